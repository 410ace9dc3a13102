"""The vector env: N vehicles of one SITL equal N single envs with the same seeds,
autoreset included (gymnasium's NEXT_STEP mode)."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.vector import AutoresetMode

import flyloop  # noqa: F401
from flyloop import SitlError
from flyloop.envs import Lander2DEnv, QuadHoverEnv, QuadWaypointsEnv
from flyloop.vector import Lander2DVectorEnv, QuadHoverVectorEnv, QuadWaypointsVectorEnv

CASES = [
    (QuadHoverVectorEnv, QuadHoverEnv, {"max_steps": 40}),
    (QuadWaypointsVectorEnv, QuadWaypointsEnv, {"max_steps": 30, "max_num_waypoints": 3}),
    (Lander2DVectorEnv, Lander2DEnv, {"max_steps": 35, "moving_platform": True}),
]


@pytest.fixture
def closing():
    made = []

    def keep(env):
        made.append(env)
        return env

    yield keep
    for env in made:
        env.close()


def single_rollouts(cls, kwargs, seeds, actions, closing):
    """What N single envs do with NEXT_STEP autoreset done by hand."""
    out = []
    for i, seed in enumerate(seeds):
        env = closing(cls(**kwargs))
        obs, info = env.reset(seed=seed)
        rows = [(obs, 0.0, False, False, info)]
        done = False
        for t in range(len(actions)):
            if done:
                obs, info = env.reset()
                rows.append((obs, 0.0, False, False, info))
                done = False
            else:
                obs, r, te, tr, info = env.step(actions[t][i])
                rows.append((obs, r, te, tr, info))
                done = te or tr
        out.append(rows)
    return out


@pytest.mark.parametrize("vec_cls, cls, kwargs", CASES)
def test_vector_trajectories_equal_single_envs_with_the_same_seeds(
    sitl_binary, closing, vec_cls, cls, kwargs
):
    n, steps = 4, 90
    venv = closing(vec_cls(num_envs=n, **kwargs))
    assert venv.metadata["autoreset_mode"] == AutoresetMode.NEXT_STEP
    rng = np.random.default_rng(3)
    actions = [
        rng.uniform(venv.action_space.low, venv.action_space.high).astype(np.float32)
        for _ in range(steps)
    ]
    singles = single_rollouts(cls, kwargs, [100 + i for i in range(n)], actions, closing)

    obs, infos = venv.reset(seed=100)
    got = [(obs, np.zeros(n), np.zeros(n, bool), np.zeros(n, bool), infos)]
    for t in range(steps):
        got.append(venv.step(actions[t]))
    resets = 0
    for t, (obs, rewards, terminated, truncated, infos) in enumerate(got):
        assert obs.shape == venv.observation_space.shape and obs.dtype == np.float32
        assert venv.observation_space.contains(obs)
        for i in range(n):
            s_obs, s_r, s_te, s_tr, s_info = singles[i][t]
            np.testing.assert_array_equal(obs[i], s_obs, err_msg=f"t={t} env {i}")
            assert rewards[i] == s_r and terminated[i] == s_te and truncated[i] == s_tr
            for key, value in s_info.items():
                np.testing.assert_array_equal(infos[key][i], value, err_msg=key)
                assert infos[f"_{key}"][i]
            resets += (
                t > 0
                and s_r == 0.0
                and not s_te
                and not s_tr
                and (s_info.get("step_count", s_info.get("step")) == 0)
            )
    assert resets >= n, "every sub-env was auto-reset at least once"


def test_make_vec_uses_the_one_sitl_vector_env(sitl_binary, closing):
    envs = closing(gym.make_vec("flyloop/QuadHover-v0", num_envs=16, use_wind=False))
    assert isinstance(envs.unwrapped, QuadHoverVectorEnv)
    obs, infos = envs.reset(seed=0)
    assert obs.shape == (16, 33) and infos["position"].shape == (16, 3)
    assert infos["crashed"].dtype == bool and infos["step_count"].dtype == np.int64
    np.testing.assert_array_equal(infos["position"][:, 2], 1.5)
    obs, rewards, terminated, truncated, infos = envs.step(np.full((16, 4), 0.5, np.float32))
    assert rewards.shape == (16,) and rewards.dtype == np.float64
    assert (infos["step_count"] == 1).all()
    pid = envs.unwrapped.sitl_process.pid
    envs.close()
    with pytest.raises(FileNotFoundError):
        open(f"/proc/{pid}/stat").read()


def test_seed_lists_and_bad_input(sitl_binary, closing):
    venv = closing(Lander2DVectorEnv(num_envs=3))
    a, _ = venv.reset(seed=[5, 5, 9])
    np.testing.assert_array_equal(a[0], a[1])
    assert not np.array_equal(a[0], a[2])
    with pytest.raises(ValueError, match="3 envs"):
        venv.reset(seed=[1, 2])
    with pytest.raises(ValueError, match="shape"):
        venv.step(np.zeros((2, 2), np.float32))
    with pytest.raises(ValueError, match="finite"):
        venv.step(np.full((3, 2), np.nan, np.float32))
    with pytest.raises(ValueError, match="num_envs"):
        Lander2DVectorEnv(num_envs=0)
    with pytest.raises(ValueError, match="do not render"):
        Lander2DVectorEnv(num_envs=2, render_mode="rgb_array")


def test_a_dead_vector_sitl_raises(sitl_binary, closing):
    import os
    import signal

    venv = closing(QuadHoverVectorEnv(num_envs=8))
    venv.reset(seed=0)
    os.kill(venv.sitl_process.pid, signal.SIGKILL)
    with pytest.raises(SitlError, match="killed by signal 9"):
        for _ in range(3):
            venv.step(np.full((8, 4), 0.5, np.float32))
