"""Flying the envs: a scripted controller that reaches and holds a hover target, and the two
action wrappers moving the vehicle the way their docs say."""

from __future__ import annotations

import numpy as np
import pytest

from flyloop.envs import Lander2DEnv, QuadHoverEnv, QuadWaypointsEnv
from flyloop.wrappers import MotionPrimitiveActionWrapper, ThrustChangeController

# PX4 quad-X in body FLU (QuadHoverEnv docs): rotor i at (±a, ±a); CCW rotors 0 and 1.
ARM = 0.1 / np.sqrt(2)
YAW = 0.02  # N·m of reaction torque per N of thrust
THRUST = 10.0  # N per motor at motor state 1 (T = 10 m²)
MIX = np.array(
    [
        [1, 1, 1, 1],  # collective thrust
        [-ARM, ARM, ARM, -ARM],  # roll torque: y_i · T_i
        [-ARM, ARM, -ARM, ARM],  # pitch torque: −x_i · T_i
        [-YAW, -YAW, YAW, YAW],  # yaw torque: CCW rotors push −z
    ]
)
UNMIX = np.linalg.inv(MIX)


def rotation(q):
    w, x, y, z = q
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
        ]
    )


def hover_controller(obs, mass=1.0, gravity=9.81):
    """Cascaded PD from the observation only: position → thrust vector → attitude → torque."""
    error, velocity = obs[0:3].astype(float), obs[3:6].astype(float)
    rates = obs[13:16].astype(float)
    accel = 2.25 * error - 2.7 * velocity
    accel = np.clip(accel, [-3, -3, -5], [3, 3, 5])
    force = mass * (accel + [0, 0, gravity])
    r = rotation(obs[9:13].astype(float))
    wanted_z = r.T @ (force / np.linalg.norm(force))  # desired body z, in the body frame
    yaw = np.arctan2(r[1, 0], r[0, 0])
    attitude_error = np.array([-wanted_z[1], wanted_z[0], -yaw])
    torque = np.array([0.36, 0.36, 0.2]) * attitude_error - 0.1 * rates
    thrusts = UNMIX @ np.array([force @ r[:, 2], *torque])
    return np.sqrt(np.clip(thrusts, 0, THRUST) / THRUST).astype(np.float32)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_a_scripted_controller_reaches_and_holds_the_hover_target(make_env, seed):
    env = make_env(QuadHoverEnv, use_wind=False, max_steps=800)
    obs, info = env.reset(seed=seed)
    start = info["distance_to_target"]
    distances, rewards = [], []
    for _ in range(800):
        obs, reward, terminated, truncated, info = env.step(hover_controller(obs))
        distances.append(info["distance_to_target"])
        rewards.append(reward)
        assert not terminated
    assert truncated and info["step_count"] == 800
    distances = np.array(distances)
    assert start >= 1.0
    assert distances[300] < 0.15, "reached within 3 s"
    assert distances[400:].max() < 0.02, "held for the last 4 s"
    assert min(rewards[400:]) > 0.98, "the reward is ~1 on the target"
    assert info["distance_progress"] == pytest.approx(start - distances[-1], abs=1e-5)


def test_the_controller_holds_against_wind_too(make_env):
    env = make_env(QuadHoverEnv, wind_strength_range=(3.0, 3.0), max_steps=600)
    obs, info = env.reset(seed=4)
    for _ in range(600):
        obs, _, terminated, _, info = env.step(hover_controller(obs))
        assert not terminated
    assert np.linalg.norm(obs[22:25]) > 1.0, "the wind blows"
    assert info["distance_to_target"] < 0.6  # a PD without integral lags in a steady wind


def test_falling_out_of_the_sky_is_a_crash(make_env):
    env = make_env(QuadHoverEnv, use_wind=False)
    env.reset(seed=0)
    terminated = False
    while not terminated:
        _, _, terminated, _, info = env.step(np.zeros(4, np.float32))
        assert info["step_count"] < 200
    assert info["crashed"] and not info["out_of_bounds"]
    # The crash fires when a landing-gear foot reaches the ground, so the centre of mass is
    # then within the gear's reach of it (|(±0.07, ±0.07, −0.05)| < 0.1 m), not at z = 0.
    assert 0.0 < info["position"][2] < 0.1
    # 1.5 m of free fall takes ~0.55 s (motors spin down with a 0.08 s lag first).
    assert 55 <= info["step_count"] <= 75


def level_env(make_env, cls=QuadHoverEnv, **kwargs):
    return make_env(cls, use_wind=False, start_attitude_range=0.0, **kwargs)


@pytest.mark.parametrize(
    "primitive, rate_index, drift_index, drift_sign",
    [
        (1, 0, 1, +1),  # roll > 0: right side up, body rate x < 0, drifts to +y (left)
        (2, 1, 0, -1),  # pitch > 0: nose up, body rate y < 0 (FLU), drifts to −x (back)
        (3, 2, None, 0),  # yaw > 0: clockwise from above, body rate z < 0
    ],
)
def test_each_motion_primitive_turns_the_vehicle_the_documented_way(
    make_env, primitive, rate_index, drift_index, drift_sign
):
    env = MotionPrimitiveActionWrapper(level_env(make_env), scale=0.5)
    obs, info = env.reset(seed=0)
    hover = float(obs[25])
    for sign in (+1, -1):
        obs, info = env.reset(seed=0)
        action = np.array([hover, 0, 0, 0], np.float32)
        action[primitive] = 0.1 * sign
        for _ in range(15):
            obs, *_ = env.step(action)
        rates = obs[13:16]
        assert np.sign(rates[rate_index]) == -sign, rates
        others = [i for i in range(3) if i != rate_index]
        assert np.abs(rates[others]).max() < 0.05 * abs(rates[rate_index])
        if drift_index is not None:
            level = np.zeros(4, np.float32)
            level[0] = hover
            for _ in range(30):
                obs, _, _, _, info = env.step(level)
            assert np.sign(info["position"][drift_index]) == drift_sign * sign


def test_motion_primitives_are_clipped_and_mixed_per_motor(make_env):
    env = MotionPrimitiveActionWrapper(level_env(make_env), scale=0.5)
    np.testing.assert_allclose(env.action([0.5, 0.2, 0.0, 0.0]), [0.6, 0.4, 0.4, 0.6])
    np.testing.assert_allclose(env.action([0.5, 0.0, 0.2, 0.0]), [0.6, 0.4, 0.6, 0.4])
    np.testing.assert_allclose(env.action([0.5, 0.0, 0.0, 0.2]), [0.6, 0.6, 0.4, 0.4])
    np.testing.assert_allclose(env.action([7.0, -9.0, 0.0, 0.0]), [0.5, 1.0, 1.0, 0.5])
    np.testing.assert_allclose(env.action([-1.0, 0.0, 0.0, 0.0]), 0.0)
    assert env.action_space.low.tolist() == [0, -1, -1, -1]


def test_thrust_change_controller_integrates_a_clipped_rate(make_env):
    env = ThrustChangeController(level_env(make_env, dt=0.02))
    obs, _ = env.reset(seed=0)
    hover = obs[29:33].copy()
    np.testing.assert_allclose(env.command, hover)
    obs, *_ = env.step(np.array([1.0, -1.0, 0.0, 5.0], np.float32))
    want = np.clip(hover + 0.02 * np.array([1.0, -1.0, 0.0, 1.0]), 0, 1)
    np.testing.assert_allclose(obs[29:33], want, atol=1e-6)
    for _ in range(60):  # 1.2 s at full rate: saturates at 1
        obs, *_ = env.step(np.ones(4, np.float32))
    np.testing.assert_array_equal(obs[29:33], 1.0)
    obs, _ = env.reset(seed=0)
    np.testing.assert_allclose(env.command, hover)
    assert env.action_space.low.tolist() == [-1] * 4


def test_the_wrappers_refuse_the_lander(make_env):
    lander = make_env(Lander2DEnv)
    for wrapper in (ThrustChangeController, MotionPrimitiveActionWrapper):
        with pytest.raises(TypeError, match="quadrotor env"):
            wrapper(lander)


def test_thrust_change_controller_wraps_the_waypoint_task(make_env):
    env = ThrustChangeController(level_env(make_env, QuadWaypointsEnv))
    obs, _ = env.reset(seed=1)
    obs, *_ = env.step(np.zeros(4, np.float32))
    np.testing.assert_allclose(obs[29:33], obs[25:29], atol=1e-3)  # hover held
