"""A second importer: libcosimpy (open-simulation-platform's libcosim) runs the three FMUs
in one execution and gets the same numbers as fmpy."""

import numpy as np
from fmpy import read_model_description, simulate_fmu
from fmu_support import HOVER, hover, motors
from libcosimpy.CosimEnums import CosimExecutionState
from libcosimpy.CosimExecution import CosimExecution
from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
from libcosimpy.CosimObserver import CosimObserver
from libcosimpy.CosimSlave import CosimLocalSlave

NANOSECONDS = 1_000_000_000


def vrs(fmu) -> dict[str, int]:
    md = read_model_description(str(fmu))
    return {v.name: v.valueReference for v in md.modelVariables}


def fmpy_last(fmu, model: str, level: float, names: list[str]) -> list[float]:
    """The last values of `names` after 3 s at seed 7 with every motor at `level`, by fmpy."""
    inputs = np.array(
        [(0.0, *[level] * len(motors(model))), (3.0, *[level] * len(motors(model)))],
        dtype=[("time", np.float64)] + [(m, np.float64) for m in motors(model)],
    )
    result = simulate_fmu(
        str(fmu),
        stop_time=3.0,
        output_interval=0.01,
        start_values={"seed": 7, "initial_motor": level},
        input=inputs,
        output=names,
    )
    return [float(result[n][-1]) for n in names]


def test_libcosimpy_runs_the_fmus_and_agrees_with_fmpy(fmus):
    log_output_level(CosimLogLevel.ERROR)
    quad_vr, lander_vr = vrs(fmus["Quadrotor"]), vrs(fmus["Lander2D"])
    hexa_vr = vrs(fmus["Hexacopter"])
    execution = CosimExecution.from_step_size(step_size=NANOSECONDS // 100)
    quad = execution.add_local_slave(CosimLocalSlave(str(fmus["Quadrotor"]), "quad"))
    lander = execution.add_local_slave(CosimLocalSlave(str(fmus["Lander2D"]), "lander"))
    hexa = execution.add_local_slave(CosimLocalSlave(str(fmus["Hexacopter"]), "hexa"))
    assert execution.num_slaves() == 3
    observer = CosimObserver.create_last_value()
    execution.add_observer(observer)
    assert execution.integer_initial_value(quad, quad_vr["seed"], 7)
    assert execution.real_initial_value(quad, quad_vr["initial_motor"], HOVER)
    for i in range(4):
        assert execution.real_initial_value(quad, quad_vr[f"motor_command_{i}"], HOVER)
    assert execution.integer_initial_value(hexa, hexa_vr["seed"], 7)
    hexa_hover = hover("Hexacopter")
    assert execution.real_initial_value(hexa, hexa_vr["initial_motor"], hexa_hover)
    for name in motors("Hexacopter"):
        assert execution.real_initial_value(hexa, hexa_vr[name], hexa_hover)
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
    cosim_hexa = observer.last_real_values(hexa, [hexa_vr[n] for n in names])

    # The same experiments through fmpy.
    assert cosim_quad == fmpy_last(fmus["Quadrotor"], "Quadrotor", HOVER, names)
    assert abs(cosim_quad[0]) > 1e-3, "the seeded wind moved the vehicle"
    assert cosim_hexa == fmpy_last(fmus["Hexacopter"], "Hexacopter", hexa_hover, names)
    assert abs(cosim_hexa[0]) > 1e-3
    # The lander fell with its motors off (inputs at their start, -1) and hit something.
    assert lander_y < 40.0
    assert crashed and not landed
