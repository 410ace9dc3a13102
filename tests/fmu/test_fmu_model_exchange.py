"""Quadrotor.fmu and Hexacopter.fmu as Model Exchange with fmpy's solvers: the importer
integrates the core's own right-hand side, so its path is the core's path (CVode), converges
to it at first order (explicit Euler), matches Co-Simulation, and sees the same turbulence
samples as Co-Simulation at any communication step."""

import numpy as np
import pytest
from fmpy import read_model_description, simulate_fmu
from fmu_support import HOVER, ROTORS, hover, motors

# Wind off, no ground contact in 5 s: a climbing, rolling, drifting flight.
CALM = {
    "wind_enabled": False,
    "initial_z": 10.0,
    "initial_roll": 0.2,
    "initial_vx": 0.5,
    "initial_wx": 0.5,
    "initial_motor": HOVER,
    **{f"motor_command_{i}": 0.52 for i in range(4)},
}
POSITION = ["x", "y", "z"]


def calm(model: str) -> dict:
    """CALM for `model`: its own hover state, every one of its motors at 0.52."""
    return {**CALM, "initial_motor": hover(model), **dict.fromkeys(motors(model), 0.52)}


def model_exchange(fmu, stop: float, start_values: dict, solver="CVode", **options):
    return simulate_fmu(
        str(fmu),
        fmi_type="ModelExchange",
        solver=solver,
        stop_time=stop,
        start_values=start_values,
        output=POSITION + ["qw", "motor_state_0", "wind_x", "wind_y", "wind_z"],
        **options,
    )


def core_path(
    core_trajectory, start_values: dict, h: float, steps: int, model: str = "Quadrotor"
) -> dict:
    """The core stepped directly from Rust with RK4 substeps of at most 1 ms (error ~1e-12)."""
    inputs = {k: v for k, v in start_values.items() if k.startswith("motor_command_")}
    params = {k: v for k, v in start_values.items() if k not in inputs}
    return core_trajectory(
        {
            "model": model,
            "start_values": {**params, "max_substep": 0.001},
            "step_size": h,
            "steps": steps,
            "inputs": [{"time": 0.0, "values": inputs}],
            "outputs": POSITION,
        }
    )


def on_grid(result, h: float):
    """The rows at multiples of h, one per time (an event may repeat a time)."""
    ratio = result["time"] / h
    rows = result[np.abs(ratio - np.round(ratio)) < 1e-9]
    _, first = np.unique(np.round(rows["time"] / h), return_index=True)
    return rows[first]


def gap(a, b, names=POSITION) -> float:
    return max(float(np.max(np.abs(np.asarray(a[n]) - np.asarray(b[n])))) for n in names)


@pytest.mark.parametrize("model", ROTORS)
def test_the_model_description_offers_both_interfaces(fmus, model):
    md = read_model_description(str(fmus[model]))
    assert md.modelExchange is not None and md.coSimulation is not None
    states = 13 + ROTORS[model] + 8  # rigid body, one per motor, the bristles
    assert md.numberOfEventIndicators == 4 and md.numberOfContinuousStates == states
    derivatives = [u.variable for u in md.derivatives]
    assert [d.name for d in derivatives[:3]] == ["der(x)", "der(y)", "der(z)"]
    assert [d.derivative.name for d in derivatives[-2:]] == ["gear_stretch_3_x", "gear_stretch_3_y"]
    lander = read_model_description(str(fmus["Lander2D"]))
    assert lander.modelExchange is None


@pytest.mark.parametrize("model", ROTORS)
def test_cvode_matches_the_core_and_co_simulation_to_a_micrometre(fmus, core_trajectory, model):
    start = calm(model)
    me = on_grid(
        model_exchange(fmus[model], 5.0, start, relative_tolerance=1e-10, output_interval=0.01),
        0.01,
    )
    core = core_path(core_trajectory, start, 0.01, 500, model)
    assert len(me) == 501 and np.allclose(me["time"], core["time"], atol=1e-12)
    assert gap(me, core) < 1e-6, gap(me, core)
    cs = simulate_fmu(
        str(fmus[model]),
        stop_time=5.0,
        output_interval=0.01,
        start_values=start,
        output=POSITION,
    )
    assert gap(me, cs) < 1e-6, gap(me, cs)
    # A real flight: it climbs, drifts and its attitude moves.
    assert me["z"][-1] - 10.0 > 1.0 and abs(me["x"][-1]) > 1.0 and np.ptp(me["qw"]) > 1e-3


def test_a_second_solver_euler_converges_to_the_core_at_first_order(fmus, core_trajectory):
    core = core_path(core_trajectory, CALM, 0.01, 100)
    errors = []
    for h in (1e-3, 5e-4):
        # fmpy's Euler takes one step per output interval.
        euler = model_exchange(
            fmus["Quadrotor"], 1.0, CALM, solver="Euler", step_size=h, output_interval=h
        )
        errors.append(gap(on_grid(euler, 0.01), core))
    # Halving the step halves the error: the same right-hand side, integrated at order 1.
    assert errors[0] < 1e-2 and 1.8 < errors[0] / errors[1] < 2.2, errors


def test_model_exchange_sees_the_co_simulation_turbulence_samples(fmus):
    windy = {
        "seed": 7,
        "initial_motor": HOVER,
        "initial_z": 20.0,
        "wind_speed_min": 2.0,
        "wind_speed_max": 4.0,
        **{f"motor_command_{i}": HOVER for i in range(4)},
    }
    me = model_exchange(
        fmus["Quadrotor"], 2.0, windy, relative_tolerance=1e-10, output_interval=0.005
    )
    # Midway between samples (t = 0.005 + k 0.01) the wind is unambiguous.
    mid = np.abs((me["time"] - 0.005) / 0.01 - np.round((me["time"] - 0.005) / 0.01)) < 1e-9
    me = me[mid]
    assert len(me) == 200
    for h in (0.005,):
        cs = simulate_fmu(
            str(fmus["Quadrotor"]),
            stop_time=2.0,
            output_interval=h,
            start_values=windy,
            output=POSITION + ["wind_x", "wind_y", "wind_z"],
        )
        ratio = (cs["time"] - 0.005) / 0.01
        cs = cs[np.abs(ratio - np.round(ratio)) < 1e-9]
        assert np.allclose(cs["time"], me["time"], atol=1e-12)
        for name in ("wind_x", "wind_y", "wind_z"):
            assert np.array_equal(cs[name], me[name]), name
        assert gap(me, cs) < 1e-6, gap(me, cs)
    assert np.ptp(me["wind_x"]) > 0.1
