"""stable-baselines3 on the native batch: a `VecEnv` whose sub-envs are the rows of one native
vector env, stepped in one call (needs stable-baselines3, the `train` extra; `import flyloop`
does not import it).

    import flyloop.sb3
    from stable_baselines3 import PPO
    venv = flyloop.sb3.make_vec_env("flyloop/QuadHover-v0", 8, unit_actions=True, max_steps=250)
    PPO("MlpPolicy", venv).learn(10_000)

A gymnasium vector env is not a stable-baselines3 VecEnv (SB3 refuses it as "not a Gymnasium
environment"), and the two disagree on autoreset: gymnasium's NEXT_STEP resets an ended
sub-env on the step after (ignoring that step's action), SB3 resets it within the step that
ended it, returns the new episode's first observation and puts the last one in
`infos[i]["terminal_observation"]`. This VecEnv does SB3's: after each step the sub-envs that
ended start their next episode at once (`FlyloopVectorEnv.reset_ended`), with the seeds the
gymnasium vector env and single envs draw. So with `venv.seed(s)` it gives the episodes of
`DummyVecEnv` over single envs seeded `s + i`, bit for bit, stepped 2-6x faster
(docs/performance.md).
"""

from __future__ import annotations

from typing import Any

import gymnasium
import numpy as np
from gymnasium.wrappers.utils import rescale_box

try:
    from stable_baselines3.common.vec_env import DummyVecEnv
    from stable_baselines3.common.vec_env.base_vec_env import VecEnv, VecEnvIndices
except ModuleNotFoundError as exc:  # an optional dependency: say which and how to get it
    raise ModuleNotFoundError(
        f"flyloop.sb3 needs stable-baselines3 ({exc}): pip install 'flyloop[train]' "
        "or pip install stable-baselines3"
    ) from exc

from .registration import ENVS
from .vector import FlyloopVectorEnv


def make_vec_env(env_id: str, n_envs: int, **kwargs: Any) -> NativeVecEnv:
    """`n_envs` sub-envs of the flyloop env `env_id` as one stable-baselines3 VecEnv over
    the native batch. `kwargs`: the env's arguments (as `gymnasium.make`'s), `num_threads`,
    and `unit_actions=True` for actions in [-1, 1] mapped linearly onto the env's bounds (as
    `gymnasium.wrappers.RescaleAction` maps them; SB3 expects such a space)."""
    return NativeVecEnv(env_id, n_envs, **kwargs)


def dummy_vec_env(
    env_id: str, n_envs: int, *, unit_actions: bool = False, **kwargs: Any
) -> DummyVecEnv:
    """The same envs as single envs in SB3's DummyVecEnv, one env object each: the reference
    `make_vec_env` equals, and the way to SB3 for the SITL backend (`backend="sitl"`: a
    flyloop-sitl process per env)."""

    def make() -> gymnasium.Env:
        env = gymnasium.make(env_id, **{"backend": "native", **kwargs})
        if unit_actions:
            unit = np.ones(env.action_space.shape, env.action_space.dtype)
            env = gymnasium.wrappers.RescaleAction(env, -unit, unit)
        return env

    return DummyVecEnv([make] * n_envs)


class NativeVecEnv(VecEnv):
    """stable-baselines3 VecEnv over one native vector env (see the module's docstring).

    Observations (N, n_obs) float32, rewards (N,) float32, dones (N,) bool (terminated or
    truncated), infos: the single env's info per sub-env, with SB3's
    `TimeLimit.truncated` and, where an episode ended, `terminal_observation`.
    """

    def __init__(self, env_id: str, n_envs: int, *, unit_actions: bool = False, **kwargs: Any):
        if env_id not in ENVS:
            raise ValueError(f"{env_id!r} is not a flyloop env id; choose one of {sorted(ENVS)}")
        backend = kwargs.pop("backend", "native")
        if backend != "native":
            raise ValueError(
                f"flyloop.sb3 steps the native batch: backend must be 'native', got {backend!r} "
                "(for the SITL: flyloop.sb3.dummy_vec_env(..., backend='sitl'), single envs)"
            )
        if not kwargs.pop("copy", True):
            raise ValueError("flyloop.sb3's VecEnv hands out its own arrays: copy=False is refused")
        if kwargs.get("render_mode") is not None:
            raise ValueError(
                "flyloop.sb3's VecEnv does not render; render a single env "
                "(gymnasium.make(..., render_mode='rgb_array'))"
            )
        venv = gymnasium.make_vec(
            env_id,
            num_envs=n_envs,
            vectorization_mode="vector_entry_point",
            backend="native",
            **kwargs,
        )
        self.venv: FlyloopVectorEnv = venv.unwrapped
        space = self.venv.single_action_space
        self._to_env = None
        if unit_actions:
            unit = np.ones(space.shape, space.dtype)
            space, _, self._to_env = rescale_box(space, -unit, unit)
        self._actions: np.ndarray | None = None
        super().__init__(self.venv.num_envs, self.venv.single_observation_space, space)

    # ---- VecEnv API ----

    def reset(self) -> np.ndarray:
        seeds = None if all(s is None for s in self._seeds) else self._seeds
        obs, _ = self.venv.reset(seed=seeds)
        self._reset_seeds()
        self._reset_options()
        self.reset_infos = self.venv.info_dicts()
        return obs

    def step_async(self, actions: np.ndarray) -> None:
        self._actions = actions

    def step_wait(self):
        if self._actions is None:
            raise RuntimeError("step_wait() without step_async(actions) first")
        actions, self._actions = self._actions, None
        if self._to_env is not None:
            actions = self._to_env(np.asarray(actions, np.float32))
        # The arrays of the step (the vector env's own: copied before its autoreset below).
        out = self.venv.step_arrays(actions)
        obs, rewards = out.obs.copy(), out.rewards.astype(np.float32)
        dones = out.terminated | out.truncated
        infos = self.venv.info_dicts()
        time_limits = (out.truncated & ~out.terminated).tolist()
        for info, time_limit in zip(infos, time_limits, strict=True):
            info["TimeLimit.truncated"] = time_limit
        if dones.any():
            for i in np.flatnonzero(dones).tolist():
                infos[i]["terminal_observation"] = obs[i].copy()
            ended, first_obs, first_infos = self.venv.reset_ended()
            for i, info in zip(ended.tolist(), first_infos, strict=True):
                self.reset_infos[i] = info
            obs[ended] = first_obs
        return obs, rewards, dones, infos

    def close(self) -> None:
        self.venv.close()

    def _indices(self, indices: VecEnvIndices) -> list[int]:
        if indices is None:
            return list(range(self.num_envs))
        return [indices] if isinstance(indices, int) else list(indices)

    def get_attr(self, attr_name: str, indices: VecEnvIndices = None) -> list[Any]:
        """The vector env's attribute, once per index: every sub-env shares it (`dt`,
        `render_mode`, the spaces, `backend`)."""
        value = getattr(self.venv, attr_name)
        return [value for _ in self._indices(indices)]

    def set_attr(self, attr_name: str, value: Any, indices: VecEnvIndices = None) -> None:
        raise AttributeError(
            f"cannot set {attr_name!r}: the sub-envs of flyloop's native VecEnv are rows of one "
            "batch and share their attributes; make a new VecEnv with other arguments"
        )

    def env_method(self, method_name: str, *args, indices: VecEnvIndices = None, **kwargs):
        raise AttributeError(
            f"no method {method_name!r} per sub-env: the sub-envs of flyloop's native VecEnv "
            "are rows of one batch, not env objects"
        )

    def env_is_wrapped(self, wrapper_class: type, indices: VecEnvIndices = None) -> list[bool]:
        return [False for _ in self._indices(indices)]
