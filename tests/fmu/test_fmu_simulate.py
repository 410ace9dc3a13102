"""fmpy.simulate_fmu with input tables: the hover command holds altitude, and a step
input gives exactly the trajectory of the core stepped directly from Rust with the same
seed — for the quadrotor, the hexacopter (the core's hexa X) and the lander."""

import numpy as np
import pytest
from fmpy import read_model_description, simulate_fmu
from fmu_support import ROTORS, hover, motors


def input_table(names: list[str], rows: list[tuple]) -> np.ndarray:
    return np.array(rows, dtype=[("time", np.float64)] + [(n, np.float64) for n in names])


@pytest.mark.parametrize("model", ROTORS)
def test_hover_command_holds_altitude(fmus, model):
    n, level = ROTORS[model], hover(model)
    result = simulate_fmu(
        str(fmus[model]),
        stop_time=5.0,
        output_interval=0.01,
        start_values={"initial_motor": level, "wind_enabled": False, "initial_z": 2.0},
        input=input_table(motors(model), [(0.0, *[level] * n), (5.0, *[level] * n)]),
        output=["x", "y", "z", "vz", "roll", "pitch", f"motor_state_{n - 1}"],
    )
    assert len(result) == 501
    assert np.max(np.abs(result["z"] - 2.0)) < 1e-9
    assert np.max(np.abs(result["vz"])) < 1e-9
    for name in ("x", "y", "roll", "pitch"):
        assert np.max(np.abs(result[name])) < 1e-12, name
    assert np.allclose(result[f"motor_state_{n - 1}"], level, atol=1e-12)
    # Without the command the same vehicle falls: the test sees the difference.
    fallen = simulate_fmu(
        str(fmus[model]),
        stop_time=0.5,
        output_interval=0.01,
        start_values={"initial_motor": level, "wind_enabled": False, "initial_z": 2.0},
        input=input_table(motors(model), [(0.0, *[0.3] * n), (0.5, *[0.3] * n)]),
        output=["z"],
    )
    assert fallen["z"][-1] < 1.9


def compare(fmu, core_trajectory, model, start_values, names, rows, stop_time, step):
    """Simulates with fmpy and with the core from Rust; returns fmpy's result and the outputs
    whose values differ from the core's in any bit."""
    md = read_model_description(str(fmu))
    outputs = [v.name for v in md.modelVariables if v.causality == "output"]
    result = simulate_fmu(
        str(fmu),
        stop_time=stop_time,
        output_interval=step,
        start_values=start_values,
        input=input_table(names, rows),
        output=outputs,
    )
    # An input change at a repeated time applies from that time on (fmpy's reading).
    changes = []
    for i, row in enumerate(rows):
        if i == 0 or rows[i - 1][0] == row[0] or rows[i - 1][1:] != row[1:]:
            changes.append({"time": row[0], "values": dict(zip(names, row[1:], strict=True))})
    core = core_trajectory(
        {
            "model": model,
            "start_values": start_values,
            "step_size": step,
            "steps": round(stop_time / step),
            "inputs": changes,
            "outputs": outputs,
        }
    )
    assert np.array_equal(result["time"], np.array(core["time"]))
    differing = []
    for name in outputs:
        fmu_values = np.asarray(result[name], dtype=np.float64)
        core_values = np.asarray(core[name], dtype=np.float64)
        assert fmu_values.shape == core_values.shape, name
        # Equal to the last bit: the same IEEE doubles (the sign of zero included).
        if not np.array_equal(fmu_values.view(np.uint64), core_values.view(np.uint64)):
            gap = float(np.max(np.abs(fmu_values - core_values)))
            differing.append(f"{name} (largest difference {gap:g})")
    return result, differing


@pytest.mark.parametrize("model", ROTORS)
def test_multirotor_step_input_matches_the_core_from_rust(fmus, core_trajectory, model):
    """Hexacopter.fmu is the core's hexa X (Quadrotor::with_frame) bit for bit, as
    Quadrotor.fmu is its quad X."""
    level = hover(model)
    high = level + 0.02
    steady = (level,) * ROTORS[model]
    # Every other motor up: the quad's 0 and 2 (one diagonal), the hexa's 0, 2 and 4.
    stepped = tuple(high if i % 2 == 0 else level for i in range(ROTORS[model]))
    rows = [(0.0, *steady), (1.0, *steady), (1.0, *stepped), (3.0, *stepped)]
    start_values = {"seed": 7, "initial_motor": level}
    result, differing = compare(
        fmus[model],
        core_trajectory,
        model,
        start_values,
        motors(model),
        rows,
        3.0,
        0.01,
    )
    assert differing == []
    # The step did something: yaw moved and the wind (seed 7) pushed the vehicle.
    assert abs(result["yaw"][-1]) > 1e-3
    assert abs(result["x"][-1]) > 1e-3


def test_lander_step_input_matches_the_core_from_rust(fmus, core_trajectory):
    names = ["motor_command_left", "motor_command_right"]
    rows = [(0.0, 0.0, 0.0), (2.0, 0.0, 0.0), (2.0, 0.3, 0.1), (4.0, 0.3, 0.1)]
    start_values = {"seed": 3, "moving_platform": True}
    result, differing = compare(
        fmus["Lander2D"],
        core_trajectory,
        "Lander2D",
        start_values,
        names,
        rows,
        4.0,
        0.02,
    )
    assert differing == []
    assert result["battery"][-1] < 100.0
    assert len(set(np.round(result["platform_x"], 6))) > 10, "the platform moves"


def test_lander_flags_leaving_the_world_and_an_empty_battery(fmus):
    # Issue 13: x = 50.8 beyond a 50 m world went unflagged; out_of_bounds is an output now.
    start = {"initial_x": 49.0, "initial_vx": 4.0, "wind_enabled": False}
    result = simulate_fmu(
        str(fmus["Lander2D"]),
        start_values=start,
        stop_time=1.0,
        output_interval=0.02,
        output=["x", "out_of_bounds", "battery_empty"],
    )
    inside = result["x"] < 50.0
    assert inside[0] and not inside[-1]
    # Flagged exactly when the centre is past world_width (50 m), never before.
    np.testing.assert_array_equal(result["out_of_bounds"], ~inside)
    assert not result["battery_empty"].any()

    drained = simulate_fmu(
        str(fmus["Lander2D"]),
        start_values={"initial_battery": 0.5, "wind_enabled": False},
        stop_time=0.5,
        output_interval=0.02,
        input=np.array(
            [(0.0, 1.0, 1.0)],
            dtype=[("time", float), ("motor_command_left", float), ("motor_command_right", float)],
        ),
        output=["battery", "battery_empty"],
    )
    # 30 N drain 0.1/(N·s): 0.5 units last 1/6 s.
    assert not drained["battery_empty"][0] and drained["battery_empty"][-1]
    np.testing.assert_array_equal(drained["battery_empty"], drained["battery"] <= 0.0)
