"""A second importer: libcosimpy (open-simulation-platform's libcosim) runs both FMUs
in one execution and gets the same numbers as fmpy."""

import numpy as np
from fmpy import read_model_description, simulate_fmu
from fmu_support import HOVER
from libcosimpy.CosimEnums import CosimExecutionState
from libcosimpy.CosimExecution import CosimExecution
from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
from libcosimpy.CosimObserver import CosimObserver
from libcosimpy.CosimSlave import CosimLocalSlave

NANOSECONDS = 1_000_000_000


def vrs(fmu) -> dict[str, int]:
    md = read_model_description(str(fmu))
    return {v.name: v.valueReference for v in md.modelVariables}


def test_libcosimpy_runs_both_fmus_and_agrees_with_fmpy(fmus):
    log_output_level(CosimLogLevel.ERROR)
    quad_vr, lander_vr = vrs(fmus["Quadrotor"]), vrs(fmus["Lander2D"])
    execution = CosimExecution.from_step_size(step_size=NANOSECONDS // 100)
    quad = execution.add_local_slave(CosimLocalSlave(str(fmus["Quadrotor"]), "quad"))
    lander = execution.add_local_slave(CosimLocalSlave(str(fmus["Lander2D"]), "lander"))
    assert execution.num_slaves() == 2
    observer = CosimObserver.create_last_value()
    execution.add_observer(observer)
    assert execution.integer_initial_value(quad, quad_vr["seed"], 7)
    assert execution.real_initial_value(quad, quad_vr["initial_motor"], HOVER)
    for i in range(4):
        assert execution.real_initial_value(quad, quad_vr[f"motor_command_{i}"], HOVER)
    assert execution.integer_initial_value(lander, lander_vr["seed"], 3)
    assert execution.simulate_until(target_time=3 * NANOSECONDS)
    assert execution.status().state == CosimExecutionState.STOPPED.value
    assert execution.status().current_time == 3 * NANOSECONDS

    names = ["x", "y", "z", "wind_x"]
    cosim_quad = observer.last_real_values(quad, [quad_vr[n] for n in names])
    landed, crashed = observer.last_boolean_values(
        lander, [lander_vr["landed"], lander_vr["crashed"]]
    )
    lander_y = observer.last_real_values(lander, [lander_vr["y"]])[0]

    # The same experiment through fmpy.
    inputs = np.array(
        [(0.0, *[HOVER] * 4), (3.0, *[HOVER] * 4)],
        dtype=[("time", np.float64)] + [(f"motor_command_{i}", np.float64) for i in range(4)],
    )
    result = simulate_fmu(
        str(fmus["Quadrotor"]),
        stop_time=3.0,
        output_interval=0.01,
        start_values={"seed": 7, "initial_motor": HOVER},
        input=inputs,
        output=names,
    )
    assert cosim_quad == [float(result[n][-1]) for n in names]
    assert abs(cosim_quad[0]) > 1e-3, "the seeded wind moved the vehicle"
    # The lander fell with its motors off (inputs at their start, -1) and hit something.
    assert lander_y < 40.0
    assert crashed and not landed
