"""The communication step size is the master's choice and changes nothing but where outputs
are read: the quadrotor integrates on its fixed physics grid (max_substep, 5 ms) and samples
its turbulence on its own grid (turbulence_dt), so every step size on the grid gives the same
bits at the shared times, on the ground too; so does the lander on its fixed physics grid
(physics_step), and its outputs at t are its state at t, on the grid or not."""

import numpy as np
import pytest
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
            # The same physics grid: the same bits.
            assert np.array_equal(run[name], reference[name]), (h, name)
    # The wind changes along the run and carries the vehicle: a real test, not still air.
    assert np.ptp(reference["wind_x"]) > 0.1
    assert np.hypot(reference["x"][-1], reference["y"][-1]) > 1.0


@pytest.mark.parametrize("fmu", ["Quadrotor", "Quadrotor-fmi3", "Hexacopter"])
def test_a_windy_drop_to_the_ground_is_the_same_at_every_step_size_on_the_grid(fmus, fmu):
    """Dropped from 20 m with the motors off and wind on (seed 11): through the impact and
    the bounces, h = 0.005, 0.01 and 0.02 s give the same positions at every 0.02 s."""
    start = {
        "seed": 11,
        "initial_z": 20.0,
        "initial_motor": 0.0,
        "wind_speed_min": 2.0,
        "wind_speed_max": 4.0,
    }
    if fmu.endswith("fmi3"):
        start["motor_command"] = [0.0] * 4
    else:
        start.update({f"motor_command_{i}": 0.0 for i in range(4)})

    def run(h: float) -> np.ndarray:
        result = simulate_fmu(
            str(fmus[fmu]), stop_time=4.0, output_interval=h, start_values=start, output=NAMES
        )
        return at_every(result, 0.02)

    reference = run(0.02)
    assert len(reference) == 201
    z = reference["z"]
    assert z.min() < 0.1 and z[-1] < 3.0, "it reached the ground (and bounces on its gear)"
    assert np.hypot(reference["x"][-1], reference["y"][-1]) > 0.1, "the wind pushed it"
    for h in (0.005, 0.01):
        run_h = run(h)
        for name in ("x", "y", "z"):
            assert np.array_equal(run_h[name], reference[name]), (h, name)


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


LANDER_NAMES = ["x", "y", "vx", "vy", "angle", "thrust_left", "battery", "crashed", "on_ground"]


def lander_every_20ms(fmu, h: float, command: float) -> np.ndarray:
    """Lander2D on a 5 ms physics grid (wind and thrust noise on, seed 11), 20 m above the
    ground, both motors held at `command`, stepped at h; the outputs every 0.02 s."""
    start = {
        "seed": 11,
        "physics_step": 0.005,
        "initial_y": 30.0,
        "motor_command_left": command,
        "motor_command_right": command,
    }
    result = simulate_fmu(
        str(fmu), stop_time=4.0, output_interval=h, start_values=start, output=LANDER_NAMES
    )
    return at_every(result, 0.02)


@pytest.mark.parametrize("fmu", ["Lander2D", "Lander2D-fmi3"])
def test_a_windy_lander_drop_is_the_same_at_every_step_size_on_the_grid(fmus, fmu):
    """Motors off: the wind carries it past the pad's edge and it falls the 20 m onto the
    ground (a crash at ~20 m/s, 2 s in); h = 0.005, 0.01 and 0.02 s give the same outputs at
    every 0.02 s, through the impact and lying on the ground."""
    reference = lander_every_20ms(fmus[fmu], 0.02, -1.0)
    assert len(reference) == 201
    hit = int(np.argmax(reference["y"] < 10.11))
    assert 95 <= hit <= 105, hit
    assert reference["vy"][hit - 1] < -19.0
    assert reference["crashed"][-1] and reference["on_ground"][-1]
    assert abs(reference["x"][-1] - 25.0) > 3.0, "the wind pushed it"
    for h in (0.005, 0.01):
        run = lander_every_20ms(fmus[fmu], h, -1.0)
        for name in LANDER_NAMES:
            assert np.array_equal(run[name], reference[name]), (h, name)


@pytest.mark.parametrize("fmu", ["Lander2D", "Lander2D-fmi3"])
def test_lander_thrust_noise_and_battery_are_on_the_grid_not_on_the_step(fmus, fmu):
    """Motors near hover: the thrust noise is drawn and the battery drained once per 5 ms
    grid step whatever h is, so the noisy thrust and the charge agree bit for bit too."""
    reference = lander_every_20ms(fmus[fmu], 0.02, -0.02)
    thrust = reference["thrust_left"]
    assert np.std(thrust) > 0.3 and abs(np.mean(thrust[1:]) - 7.35) < 0.2
    assert 93.5 < reference["battery"][-1] < 94.5
    for h in (0.005, 0.01):
        run = lander_every_20ms(fmus[fmu], h, -0.02)
        for name in LANDER_NAMES:
            assert np.array_equal(run[name], reference[name]), (h, name)
