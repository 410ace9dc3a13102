"""Seeded reproducibility and the documented observation layout of hand-known states."""

from __future__ import annotations

import math

import numpy as np
import pytest

from flyloop.envs import Lander2DEnv, QuadHoverEnv, QuadWaypointsEnv

HOVER_MOTOR = 0.49523  # motor state holding 1 kg at 9.81 m/s² with T = 10 N · m²


def _text(info):
    return repr(sorted((k, np.asarray(v).tolist()) for k, v in info.items()))


def rollout(env, seed, steps, action_seed):
    rng = np.random.default_rng(action_seed)
    obs, info = env.reset(seed=seed)
    out = [(obs.tobytes(), _text(info))]
    for _ in range(steps):
        space = env.action_space
        action = rng.uniform(space.low, space.high).astype(np.float32)
        obs, r, te, tr, info = env.step(action)
        out.append((obs.tobytes(), r, te, tr, _text(info)))
        if te or tr:
            obs, info = env.reset()
            out.append((obs.tobytes(), "reset"))
    return out


@pytest.mark.parametrize("cls", [QuadHoverEnv, QuadWaypointsEnv, Lander2DEnv])
def test_same_seed_gives_bit_identical_rollouts_across_envs_and_resets(make_env, cls):
    a, b = make_env(cls, max_steps=60), make_env(cls, max_steps=60)
    first = rollout(a, 7, 150, 1)
    assert rollout(b, 7, 150, 1) == first, "a second env, same seed"
    assert rollout(a, 7, 150, 1) == first, "the same env again"
    assert any(step[-1] == "reset" for step in first), "unseeded resets were replayed too"
    assert rollout(a, 8, 150, 1) != first


def test_unseeded_first_reset_differs_between_envs(make_env):
    a, b = make_env(QuadHoverEnv), make_env(QuadHoverEnv)
    assert not np.array_equal(a.reset()[0], b.reset()[0])


def test_seeds_over_the_full_64_bit_range_are_used_whole(make_env):
    env = make_env(QuadHoverEnv)
    big = 2**64 - 1
    assert env.reset(seed=big)[0].tobytes() == env.reset(seed=big)[0].tobytes()
    assert env.reset(seed=big)[0].tobytes() != env.reset(seed=big - 2**48)[0].tobytes()
    with pytest.raises(ValueError, match="seed must be in"):
        env.reset(seed=2**64)
    with pytest.raises((TypeError, ValueError)):
        env.reset(seed=-1)


def test_hover_observation_of_a_level_start_matches_the_documented_layout(make_env):
    env = make_env(QuadHoverEnv, use_wind=False, start_attitude_range=0.0, start_height=1.5)
    obs, info = env.reset(seed=11)
    target = info["target_position"]
    np.testing.assert_array_equal(info["position"], [0.0, 0.0, 1.5])
    np.testing.assert_allclose(obs[0:3], target - [0, 0, 1.5], rtol=0, atol=1e-6)
    assert info["distance_to_target"] == pytest.approx(np.linalg.norm(target - [0, 0, 1.5]), 1e-6)
    assert info["distance_to_target"] >= 1.0, "min_target_distance"
    assert (np.abs(target[:2]) <= 1.5).all() and 0 <= target[2] <= 3
    np.testing.assert_array_equal(obs[3:6], 0.0)  # velocity
    np.testing.assert_allclose(obs[6:9], 0.0, atol=2e-3)  # hover thrust cancels gravity
    np.testing.assert_array_equal(obs[9:13], [1, 0, 0, 0])  # level, facing east
    np.testing.assert_array_equal(obs[13:16], 0.0)  # body rates
    np.testing.assert_allclose(obs[19:22], [0, 0, 1], atol=1e-7)  # body z up
    np.testing.assert_array_equal(obs[22:25], 0.0)  # no wind
    np.testing.assert_allclose(obs[25:29], HOVER_MOTOR, atol=1e-5)
    np.testing.assert_allclose(obs[29:33], HOVER_MOTOR, atol=1e-5)
    assert info["step_count"] == 0 and info["crashed"] is False


def test_waypoint_observation_adds_the_next_waypoint_and_the_checkpoint_clock(make_env):
    env = make_env(QuadWaypointsEnv, use_wind=False, start_attitude_range=0.0)
    obs, info = env.reset(seed=5)
    np.testing.assert_allclose(obs[0:3], info["current_waypoint_pos"] - [0, 0, 1.5], atol=1e-6)
    np.testing.assert_allclose(obs[33:36], info["next_waypoint_pos"] - [0, 0, 1.5], atol=1e-6)
    assert obs[36] == 0.0
    for _ in range(10):
        obs, *_ = env.step(np.full(4, HOVER_MOTOR, np.float32))
    assert obs[36] == pytest.approx(0.1, abs=1e-6)


def test_lander_observation_of_a_fixed_start_matches_the_documented_layout(make_env):
    env = make_env(Lander2DEnv, initial_pos_random_range_m=0.0, initial_angle_random_range_rad=0.0)
    obs, info = env.reset(seed=3)
    err = np.array([25.0 - 25.0, 10.5 - 40.0])
    expected = [
        0.0,  # x/25 - 1
        40 / 25 - 1,
        0.0,
        0.0,
        0.0,
        0.0,
        1.0,  # battery
        err[0] / 25,
        max(err[1] / 25, -1.0),  # clipped
        math.atan2(err[1], err[0]) / math.pi,  # straight down: -0.5
        np.hypot(*err) / 50,
    ]
    np.testing.assert_allclose(obs, np.float32(expected), atol=1e-6)
    np.testing.assert_array_equal(info["position"], [25.0, 40.0])
    np.testing.assert_allclose(info["platform_position"], [25.0, 10.5])
    assert info["distance"] == pytest.approx(29.5, abs=1e-5) and info["step"] == 0


def test_lander_spawns_around_the_given_spawn_centre(make_env):
    # spawn_x / spawn_y move the spawn square (a training curriculum starts near the pad);
    # a spawn below the platform's top plus one drone width is raised to it.
    env = make_env(Lander2DEnv, spawn_x=20.0, spawn_y=15.0, initial_pos_random_range_m=2.0)
    for seed in range(5):
        _, info = env.reset(seed=seed)
        x, y = info["position"]
        assert 18.0 <= x <= 22.0 and 13.0 <= y <= 17.0, (seed, x, y)
    env = make_env(Lander2DEnv, spawn_y=11.0, initial_pos_random_range_m=0.0)
    _, info = env.reset(seed=0)
    np.testing.assert_allclose(info["position"], [25.0, 10.5 + 1.0])


def test_full_thrust_lifts_and_zero_thrust_drops_the_lander(make_env):
    env = make_env(
        Lander2DEnv, initial_pos_random_range_m=0.0, use_wind=False, thrust_noise_std=0.0
    )
    env.reset(seed=0)
    for _ in range(25):
        obs, *_ = env.step(np.ones(2, np.float32))
    assert obs[3] > 0.0, "2 x 15 N on 1.5 kg climbs"
    env.reset(seed=0)
    for _ in range(25):
        obs, _, _, _, info = env.step(-np.ones(2, np.float32))
    assert info["velocity"][1] == pytest.approx(-9.81 * 0.5, rel=0.02), "free fall"
