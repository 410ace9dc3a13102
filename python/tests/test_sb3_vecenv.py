"""flyloop.sb3: stable-baselines3's VecEnv over the native batch. Held against SB3's own
reference, DummyVecEnv over single envs (the same seeds give the same observations, rewards,
dones and infos bit for bit through many auto-resets), against the gymnasium native vector env
(same seeds, same episodes), through SB3's checks, wrappers and algorithms; bad input gets an
error naming it."""

from __future__ import annotations

import subprocess
import sys
import warnings

import gymnasium as gym
import numpy as np
import pytest
from stable_baselines3.common.env_checker import _check_obs, _check_unsupported_spaces
from stable_baselines3.common.vec_env import DummyVecEnv, VecEnv

import flyloop
import flyloop.sb3
from flyloop.registration import ENVS

# Short episodes and random actions: many episodes end (crash, bounds, time limit) in a few
# hundred steps, so the auto-reset is exercised often.
SHORT = {"max_steps": 60}


def random_actions(space: gym.spaces.Box, n_envs: int, steps: int, seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    low, high = space.low.astype(np.float64), space.high.astype(np.float64)
    return (low + (high - low) * rng.random((steps, n_envs, *space.shape))).astype(np.float32)


def same_infos(a: list[dict], b: list[dict], where: str) -> None:
    assert len(a) == len(b), where
    for i, (x, y) in enumerate(zip(a, b, strict=True)):
        assert sorted(x) == sorted(y), f"{where}, env {i}"
        for k in x:
            u, v = x[k], y[k]
            assert type(u) is type(v), f"{where}, env {i}, {k}"
            if isinstance(u, np.ndarray):
                assert u.dtype == v.dtype and np.array_equal(u, v), f"{where}, env {i}, {k}"
            else:
                assert u == v, f"{where}, env {i}, {k}"


@pytest.mark.parametrize(
    "env_id,unit_actions",
    [
        ("flyloop/QuadHover-v0", True),
        ("flyloop/QuadWaypoints-v0", False),
        ("flyloop/Lander2D-v1", False),
    ],
)
def test_it_equals_dummy_vec_env_bit_for_bit_through_auto_resets(env_id, unit_actions):
    n, steps = 5, 400
    ours = flyloop.sb3.make_vec_env(env_id, n, unit_actions=unit_actions, **SHORT)
    ref = flyloop.sb3.dummy_vec_env(env_id, n, unit_actions=unit_actions, **SHORT)
    assert isinstance(ref, DummyVecEnv) and len(ref.envs) == n
    try:
        assert ours.observation_space == ref.observation_space
        assert ours.action_space == ref.action_space
        assert ours.seed(17) == ref.seed(17) == [17 + i for i in range(n)]
        o1, o2 = ours.reset(), ref.reset()
        assert o1.dtype == o2.dtype == np.float32
        assert np.array_equal(o1.view(np.uint32), o2.view(np.uint32))
        same_infos(ours.reset_infos, ref.reset_infos, "reset")
        ends = 0
        for t, actions in enumerate(random_actions(ours.action_space, n, steps, 4)):
            o1, r1, d1, i1 = ours.step(actions)
            o2, r2, d2, i2 = ref.step(actions)
            where = f"step {t}"
            assert np.array_equal(o1.view(np.uint32), o2.view(np.uint32)), where
            assert r1.dtype == r2.dtype and np.array_equal(r1, r2), where
            assert d1.dtype == d2.dtype and np.array_equal(d1, d2), where
            same_infos(i1, i2, where)
            same_infos(ours.reset_infos, ref.reset_infos, where)
            ends += int(d1.sum())
        assert ends >= 3 * n, ends  # every sub-env auto-reset several times
    finally:
        ours.close()
        ref.close()


def test_terminal_observation_and_time_limit_follow_sb3s_semantics():
    n = 3
    venv = flyloop.sb3.make_vec_env("flyloop/QuadHover-v0", n, max_steps=5, use_wind=False)
    try:
        venv.seed(0)
        venv.reset()
        hover = np.full((n, 4), 0.495, np.float32)  # hovering: no crash, the time limit ends it
        for _ in range(4):
            obs, _, dones, infos = venv.step(hover)
            assert not dones.any() and all("terminal_observation" not in i for i in infos)
            assert all(i["TimeLimit.truncated"] is False for i in infos)
            last = obs
        obs, rewards, dones, infos = venv.step(hover)
        assert dones.all()
        for i, info in enumerate(infos):
            assert info["TimeLimit.truncated"] is True  # truncated, not terminated
            final = info["terminal_observation"]
            assert final.shape == (33,) and final.dtype == np.float32
            # The episode's last observation moved on from the one before; the returned one
            # is the next episode's first (the seed drawn, as a new episode starts at rest).
            assert not np.array_equal(final, last[i])
            assert not np.array_equal(obs[i], final)
            assert venv.reset_infos[i]["step_count"] == 0 and info["step_count"] == 5
        # The next step steps the new episode with its action (no ignored step as in
        # gymnasium's NEXT_STEP autoreset).
        _, _, _, infos = venv.step(hover)
        assert all(i["step_count"] == 1 for i in infos)
    finally:
        venv.close()


def test_same_seeds_give_the_gymnasium_native_vector_envs_episodes():
    """The gymnasium vector env resets an ended sub-env one step later (NEXT_STEP): the same
    episodes, each first observation one call later."""
    n, steps = 4, 300
    ours = flyloop.sb3.make_vec_env("flyloop/Lander2D-v1", n, **SHORT)
    gym_venv = gym.make_vec(
        "flyloop/Lander2D-v1",
        num_envs=n,
        vectorization_mode="vector_entry_point",
        backend="native",
        **SHORT,
    )
    try:
        ours.seed(123)
        episodes_ours: list[list[list[np.ndarray]]] = [[[o]] for o in ours.reset()]
        obs, _ = gym_venv.reset(seed=123)
        episodes_gym: list[list[list[np.ndarray]]] = [[[o]] for o in obs]
        actions = random_actions(ours.action_space, n, steps, 9)
        ended = np.zeros(n, bool)
        for a in actions:
            o, _, dones, infos = ours.step(a)
            for i in range(n):
                if dones[i]:
                    episodes_ours[i][-1].append(infos[i]["terminal_observation"])
                    episodes_ours[i].append([o[i]])
                else:
                    episodes_ours[i][-1].append(o[i])
        # The gymnasium env needs one extra call per episode end for the same env steps.
        stepped = np.zeros(n, int)
        while (stepped < steps).any():
            a = np.stack([actions[min(s, steps - 1), i] for i, s in enumerate(stepped)])
            o, _, term, trunc, _ = gym_venv.step(a)
            for i in range(n):
                if stepped[i] >= steps:
                    continue
                if ended[i]:
                    episodes_gym[i].append([o[i]])
                else:
                    episodes_gym[i][-1].append(o[i])
                    stepped[i] += 1
            ended = term | trunc
        for i in range(n):
            if len(episodes_ours[i][-1]) == 1:  # the last step ended one: only its start here
                episodes_ours[i].pop()
            assert len(episodes_ours[i]) == len(episodes_gym[i]) >= 3, i
            for e1, e2 in zip(episodes_ours[i], episodes_gym[i], strict=True):
                assert np.array_equal(np.stack(e1), np.stack(e2)), i
    finally:
        ours.close()
        gym_venv.close()


def test_sb3s_space_and_observation_checks_accept_it():
    venv = flyloop.sb3.make_vec_env("flyloop/QuadHover-v0", 4, unit_actions=True, **SHORT)
    assert isinstance(venv, VecEnv)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # SB3 warns about spaces it handles badly
        _check_unsupported_spaces(venv, venv.observation_space, venv.action_space)
    assert np.all(venv.action_space.low == -1) and np.all(venv.action_space.high == 1)
    venv.seed(0)
    for row in venv.reset():
        _check_obs(row, venv.observation_space, "reset")
    obs, *_ = venv.step(random_actions(venv.action_space, 4, 1, 0)[0])
    for row in obs:
        _check_obs(row, venv.observation_space, "step")
    assert venv.get_attr("dt") == [0.01] * 4 and venv.env_is_wrapped(gym.Wrapper) == [False] * 4

    venv.close()


# SB3's algorithms and wrappers on the VecEnv, in a fresh interpreter: torch's optimizers
# import triton, which crashes a process where pygame has opened an X11 window
# (test_render_human.py, possibly on the same pytest worker).
ALGORITHMS = """
import numpy as np, torch, gymnasium as gym, flyloop.sb3
from stable_baselines3 import PPO, SAC
from stable_baselines3.common.evaluation import evaluate_policy
from stable_baselines3.common.vec_env import VecCheckNan, VecMonitor, VecNormalize
torch.set_num_threads(1)
short = dict(max_steps=60)
venv = flyloop.sb3.make_vec_env("flyloop/QuadHover-v0", 4, unit_actions=True, **short)
wrapped = VecNormalize(VecMonitor(VecCheckNan(venv, raise_exception=True)))
model = PPO("MlpPolicy", wrapped, n_steps=64, batch_size=64, n_epochs=1, seed=0, device="cpu")
model.learn(512)
mean, _ = evaluate_policy(model, wrapped, n_eval_episodes=8, warn=False)
print("ppo", model.num_timesteps, bool(np.isfinite(mean)))
wrapped.close()
lander = flyloop.sb3.make_vec_env("flyloop/Lander2D-v1", 2, **short)
sac = SAC("MlpPolicy", lander, learning_starts=50, batch_size=32, seed=0, device="cpu")
sac.learn(200)
print("sac", sac.num_timesteps)
lander.close()
# The issue: SB3 refuses gymnasium's vector env.
gym_venv = gym.make_vec("flyloop/QuadHover-v0", num_envs=2,
                        vectorization_mode="vector_entry_point", backend="native")
try:
    PPO("MlpPolicy", gym_venv, device="cpu")
except ValueError as exc:
    print("gymnasium vector env refused:", "not a Gymnasium environment" in str(exc))
"""


def test_sb3s_algorithms_and_wrappers_run_on_it():
    done = subprocess.run(
        [sys.executable, "-c", ALGORITHMS], capture_output=True, text=True, timeout=600
    )
    assert done.returncode == 0, done.stderr[-3000:]
    assert done.stdout.splitlines() == [
        "ppo 512 True",  # VecCheckNan saw no NaN, evaluate_policy finished 8 episodes
        "sac 200",
        "gymnasium vector env refused: True",
    ], done.stdout


@pytest.mark.parametrize(
    "call,error,message",
    [
        (lambda: flyloop.sb3.make_vec_env("CartPole-v1", 2), ValueError, "not a flyloop env id"),
        (
            lambda: flyloop.sb3.make_vec_env("flyloop/QuadHover-v0", 2, backend="sitl"),
            ValueError,
            "backend must be 'native'",
        ),
        (
            lambda: flyloop.sb3.make_vec_env("flyloop/QuadHover-v0", 0),
            ValueError,
            "num_envs must be at least 1",
        ),
        (
            lambda: flyloop.sb3.make_vec_env("flyloop/QuadHover-v0", 2, render_mode="human"),
            ValueError,
            "does not render",
        ),
        (
            lambda: flyloop.sb3.make_vec_env("flyloop/QuadHover-v0", 2, max_steps=0),
            flyloop.SitlParameterError,
            r"max_steps refused by the core.*\[1, 1e8\]",
        ),
        (
            lambda: flyloop.sb3.make_vec_env("flyloop/QuadHover-v0", 2, model_params={"mass": -1}),
            flyloop.SitlParameterError,
            r"model_params\['mass'\] refused",
        ),
        (
            lambda: flyloop.sb3.make_vec_env("flyloop/QuadHover-v0", 2, wings=2),
            TypeError,
            r"unexpected arguments \['wings'\]",
        ),
        (
            lambda: flyloop.sb3.make_vec_env("flyloop/QuadHover-v0", 2, copy=False),
            ValueError,
            "copy=False",
        ),
    ],
)
def test_bad_arguments_name_the_problem(call, error, message):
    with pytest.raises(error, match=message):
        call()


def test_bad_actions_and_a_closed_env_name_the_problem():
    venv = flyloop.sb3.make_vec_env("flyloop/QuadHover-v0", 3)
    venv.reset()
    with pytest.raises(ValueError, match=r"shape \(3, 4\)"):
        venv.step(np.zeros((2, 4), np.float32))
    nan = np.zeros((3, 4), np.float32)
    nan[1, 2] = np.nan
    with pytest.raises(ValueError, match=r"actions\[1, 2\] = NaN"):
        venv.step(nan)
    with pytest.raises(AttributeError, match="rows of one batch"):
        venv.set_attr("dt", 0.02)
    venv.close()
    with pytest.raises(RuntimeError, match="closed"):
        venv.step(np.zeros((3, 4), np.float32))


def test_every_env_id_makes_one():
    for env_id in ENVS:
        venv = flyloop.sb3.make_vec_env(env_id, 2)
        assert venv.reset().shape == (2, *venv.observation_space.shape)
        venv.close()


def test_the_sitl_way_to_sb3_gives_the_same_episodes(sitl_binary):
    """The error for backend="sitl" points to dummy_vec_env(..., backend="sitl"): single envs,
    a flyloop-sitl each, the same observations as the native VecEnv."""
    n, steps = 2, 200
    ours = flyloop.sb3.make_vec_env("flyloop/QuadHover-v0", n, unit_actions=True, **SHORT)
    sitl = flyloop.sb3.dummy_vec_env(
        "flyloop/QuadHover-v0", n, unit_actions=True, backend="sitl", **SHORT
    )
    try:
        ours.seed(5), sitl.seed(5)
        assert np.array_equal(ours.reset(), sitl.reset())
        ends = 0
        for t, a in enumerate(random_actions(ours.action_space, n, steps, 2)):
            o1, _, d1, _ = ours.step(a)
            o2, _, d2, _ = sitl.step(a)
            assert np.array_equal(o1, o2) and np.array_equal(d1, d2), t
            ends += int(d1.sum())
        assert ends >= n
    finally:
        ours.close()
        sitl.close()


def test_without_stable_baselines3_the_import_says_what_to_install():
    # sys.modules[name] = None makes Python refuse that import, as if it were not installed.
    code = "import sys; sys.modules['stable_baselines3'] = None; import flyloop.sb3"
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert done.returncode == 1
    last = done.stderr.strip().splitlines()[-1]
    assert last.startswith("ModuleNotFoundError: flyloop.sb3 needs stable-baselines3"), last
    assert "pip install 'flyloop[train]'" in last
    # flyloop itself does not need it.
    code = "import sys; sys.modules['stable_baselines3'] = None; import flyloop, gymnasium"
    assert subprocess.run([sys.executable, "-c", code]).returncode == 0
