"""The communication step size is the master's choice and changes nothing but where outputs
are read: the quadrotor's turbulence lives on its own grid (turbulence_dt), and the lander's
outputs at t are its state at t, on its period grid or not."""

import numpy as np
from fmpy import simulate_fmu
from fmu_support import HOVER

MOTORS = {f"motor_command_{i}": HOVER for i in range(4)}
WINDY = {
    "seed": 7,
    "initial_motor": HOVER,
    "initial_z": 20.0,
    "wind_speed_min": 2.0,
    "wind_speed_max": 4.0,
    **MOTORS,
}
NAMES = ["x", "y", "z", "wind_x", "wind_y", "wind_z"]


def quadrotor(fmu, h: float) -> np.ndarray:
    return simulate_fmu(
        str(fmu),
        stop_time=5.0,
        output_interval=h,
        start_values=WINDY,
        output=NAMES,
    )


def at_every(result: np.ndarray, period: float) -> np.ndarray:
    """The rows at multiples of `period` (the times n·h that land on them)."""
    ratio = result["time"] / period
    return result[np.abs(ratio - np.round(ratio)) < 1e-9]


def test_quadrotor_weather_and_path_do_not_depend_on_the_step_size(fmus):
    reference = at_every(quadrotor(fmus["Quadrotor"], 0.01), 0.02)
    assert len(reference) == 251
    for h in (0.005, 0.02):
        run = at_every(quadrotor(fmus["Quadrotor"], h), 0.02)
        assert np.array_equal(run["time"], reference["time"]), h
        for name in ("wind_x", "wind_y", "wind_z"):
            # The same samples, bit for bit.
            assert np.array_equal(run[name], reference[name]), (h, name)
        for name in ("x", "y", "z"):
            gap = float(np.max(np.abs(run[name] - reference[name])))
            assert gap < 1e-6, (h, name, gap)
    # The wind changes along the run and carries the vehicle: a real test, not still air.
    assert np.ptp(reference["wind_x"]) > 0.1
    assert np.hypot(reference["x"][-1], reference["y"][-1]) > 1.0


def test_lander_outputs_between_its_control_periods_are_the_state_there(fmus):
    g = 9.81
    result = simulate_fmu(
        str(fmus["Lander2D"]),
        stop_time=0.492,
        output_interval=0.0123,
        start_values={
            "wind_enabled": False,
            "thrust_noise_std": 0.0,
            "initial_y": 30.0,
            "motor_command_left": -1.0,
            "motor_command_right": -1.0,
        },
        output=["y", "vy"],
    )
    t = result["time"]
    assert len(t) == 41
    # Free fall: vy is exact under semi-implicit Euler; y lags by at most g·t·dt/2.
    assert np.max(np.abs(result["vy"] + g * t)) < 1e-9
    assert np.max(np.abs(result["y"] - (30.0 - 0.5 * g * t**2)) - 0.5 * g * t * 0.02) <= 1e-9
    # At t = 0.0123 the drone has moved: not the t = 0 values held until the period ends.
    assert result["vy"][1] < -0.1
