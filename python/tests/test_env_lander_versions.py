"""Lander2D-v0 (the seed's reward) and Lander2D-v1 (the landing reward) over the real SITL:
same physics and observations, different rewards; the id fixes the reward; the physics fix
(a stopped motor gives zero thrust and drains nothing) holds in both."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest

from flyloop.envs import Lander2DEnv, Lander2DLandingEnv


def rollout(env, seed, actions):
    obs, info = env.reset(seed=seed)
    rows, infos = [], [info]
    for a in actions:
        obs, reward, terminated, truncated, info = env.step(a)
        rows.append((obs.copy(), reward, terminated, truncated))
        infos.append(info)
        if terminated or truncated:
            break
    return rows, infos


def potential(info):
    """Φ of the v1 reward (Lander2DLandingEnv's docstring), from a static pad's info."""
    d = np.hypot(*(np.asarray(info["platform_position"]) - info["position"]))
    v = np.hypot(*info["velocity"])
    return -(4 * d + 10 * v + 50 * abs(info["angle"]) + 10 * abs(info["angular_velocity"]))


def test_v0_and_v1_share_physics_and_differ_in_reward(make_env):
    rng = np.random.default_rng(7)
    actions = rng.uniform(-1, 1, (300, 2)).astype(np.float32)
    v0, _ = rollout(make_env("flyloop/Lander2D-v0"), 5, actions)
    v1, infos = rollout(make_env("flyloop/Lander2D-v1"), 5, actions)
    assert len(v0) == len(v1) > 20
    for (o0, _, t0, u0), (o1, _, t1, u1) in zip(v0, v1, strict=True):
        np.testing.assert_array_equal(o0, o1)
        assert (t0, u0) == (t1, u1)
    r0 = np.array([r for _, r, _, _ in v0])
    r1 = np.array([r for _, r, _, _ in v1])
    # The seed pays ≈ 2 per step for being within the world.
    assert r0[:-1].mean() > 1.5
    # v1: each step pays Φ(s') − Φ(s) minus the control cost (info values are float32).
    cost = 0.05 * (actions[: len(v1)] + 1).sum(axis=1) / 4
    for k in range(len(v1) - 1):
        shaping = potential(infos[k + 1]) - potential(infos[k])
        assert r1[k] == pytest.approx(shaping - cost[k], abs=2e-3), k
    # The episode ends in a failure (random actions do not land): −100 on the last step.
    last = potential(infos[-1]) - potential(infos[-2]) - cost[len(v1) - 1]
    assert r1[-1] == pytest.approx(last - 100.0, abs=2e-3)


def test_v1_time_limit_is_a_failure(make_env):
    hover = 2 * 1.5 * 9.81 / 2 / 15 - 1
    env = make_env("flyloop/Lander2D-v1", max_steps=5, use_wind=False)
    rows, infos = rollout(env, 0, [np.full(2, hover, np.float32)] * 5)
    assert len(rows) == 5 and rows[-1][3] and not rows[-1][2]
    assert infos[-1]["time_limit"]
    # −100 plus a shaping term of a few tenths (the drone barely moves in 0.1 s).
    assert -101.0 < rows[-1][1] < -99.0
    env0 = make_env("flyloop/Lander2D-v0", max_steps=5, use_wind=False)
    rows0, _ = rollout(env0, 0, [np.full(2, hover, np.float32)] * 5)
    assert 1.0 - 10.0 < rows0[-1][1] < 2.0 - 10.0  # the seed: ≈ 2 − 10


def test_the_id_fixes_the_reward_version(make_env, sitl_binary):
    assert make_env("flyloop/Lander2D-v0").unwrapped.config["reward_version"] == 0
    assert make_env("flyloop/Lander2D-v1").unwrapped.config["reward_version"] == 1
    with pytest.raises(TypeError, match="reward_version"):
        Lander2DLandingEnv(reward_version=0)
    with pytest.raises(TypeError, match="reward_version"):
        gym.make_vec("flyloop/Lander2D-v1", num_envs=2, reward_version=0)


def test_v1_vector_env_matches_the_single_env(make_env, sitl_binary):
    rng = np.random.default_rng(3)
    actions = rng.uniform(-1, 1, (50, 2)).astype(np.float32)
    single, _ = rollout(make_env(Lander2DLandingEnv), 11, actions)
    envs = gym.make_vec("flyloop/Lander2D-v1", num_envs=2)
    try:
        envs.reset(seed=11)
        for k, (obs, reward, _, _) in enumerate(single):
            o, r, *_ = envs.step(np.stack([actions[k], actions[k]]))
            np.testing.assert_array_equal(o[0], obs)
            assert np.float32(r[0]) == np.float32(reward)
    finally:
        envs.close()


@pytest.mark.parametrize("cls", [Lander2DEnv, Lander2DLandingEnv])
def test_stopped_motors_give_zero_thrust_and_drain_nothing(make_env, cls):
    env = make_env(cls, use_wind=False)  # default thrust noise on
    env.reset(seed=2)
    for _ in range(40):
        _, _, terminated, _, info = env.step(-np.ones(2, np.float32))
        np.testing.assert_array_equal(info["thrust"], [0.0, 0.0])
        assert info["battery"] == 100.0
    assert not terminated
