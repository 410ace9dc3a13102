"""train_sb3.py's envs: the native batch as one flyloop.sb3 VecEnv (the preset's default
action interface) gives what the single envs in a DummyVecEnv gave before, bit for bit, with
info['is_success'] where an episode ended; the other action interfaces keep single envs."""

from __future__ import annotations

import numpy as np
import pytest
from flyloop.sb3 import NativeVecEnv
from sb3_training import SuccessInfos, make_base_vec_env
from stable_baselines3.common.vec_env import DummyVecEnv
from training_envs import make_success_env


def dummy(env: str, n: int) -> DummyVecEnv:
    return DummyVecEnv([lambda: make_success_env(env, backend="native")] * n)


@pytest.mark.parametrize("env", ["hover", "lander"])
def test_the_native_vecenv_gives_the_dummy_vecenvs_episodes_and_successes(env):
    n, steps = 4, 1500
    ours, ref = make_base_vec_env(env, None, n, "native"), dummy(env, n)
    assert isinstance(ours, SuccessInfos) and isinstance(ours.venv, NativeVecEnv)
    assert ours.action_space == ref.action_space
    ours.seed(3), ref.seed(3)
    assert np.array_equal(ours.reset(), ref.reset())
    rng = np.random.default_rng(0)
    ended = 0
    for t in range(steps):
        # Actions near the zero action (hover for the quadrotor), so some episodes succeed.
        a = (0.3 * rng.standard_normal((n, *ours.action_space.shape))).astype(np.float32)
        a = np.clip(a, -1, 1)
        o1, r1, d1, i1 = ours.step(a)
        o2, r2, d2, i2 = ref.step(a)
        assert np.array_equal(o1, o2) and np.array_equal(r1, r2) and np.array_equal(d1, d2), t
        for done, x, y in zip(d1, i1, i2, strict=True):
            assert ("is_success" in x) == done and x.get("is_success") == y.get("is_success"), t
            if done:
                assert np.array_equal(x["terminal_observation"], y["terminal_observation"]), t
                ended += 1
    ours.close(), ref.close()
    assert ended >= 2 * n, ended


def test_the_other_action_interfaces_keep_single_envs():
    for action in ("primitives", "rates"):
        venv = make_base_vec_env("hover", action, 2, "native")
        assert isinstance(venv, DummyVecEnv), action
        venv.close()
