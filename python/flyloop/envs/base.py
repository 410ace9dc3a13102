"""FlyloopEnv: what the envs share — the backend (a SITL of their own or one they attach to,
one datagram per step; or the core in-process), seeding, the info dict and rendering."""

from __future__ import annotations

import inspect
from collections.abc import Mapping
from typing import Any

import gymnasium as gym
import numpy as np

from ..backends import check_backend, make_backend
from ..faults import add_fault_list
from ..sitl_process import SitlProcess
from ..spaces import FastBox
from ..tasks import TaskSpec, resolve_config
from ..tasks import task_arguments as task_arguments_of

SEED_LIMIT = 2**64
KEYWORD_ONLY = inspect.Parameter.KEYWORD_ONLY


def check_seed(seed: Any) -> int:
    if isinstance(seed, (bool, np.bool_)) or not isinstance(seed, (int, np.integer)):
        raise TypeError(f"seed must be an int in [0, 2**64), got {seed!r}")
    if not 0 <= int(seed) < SEED_LIMIT:
        raise ValueError(f"seed must be in [0, 2**64), got {seed}")
    return int(seed)


def as_actions(actions: Any, shape: tuple[int, ...], what: str) -> np.ndarray:
    """`actions` as a C-contiguous float32 array of `shape` (the wire's type: float64 input
    is rounded to float32 on both backends); a single env also takes any array of the same
    size. Non-numbers raise TypeError, other shapes ValueError, both naming the shape."""
    a = np.asarray(actions)
    if a.dtype.kind not in "biuf":
        raise TypeError(f"{what} must be a float array of shape {shape}, got dtype {a.dtype}")
    a = np.ascontiguousarray(a, dtype=np.float32)
    if a.shape != shape and len(shape) == 1 and a.size == shape[0]:
        a = a.reshape(shape)
    if a.shape != shape:
        raise ValueError(f"{what} must have shape {shape}, got {a.shape}")
    return a


def spaces_of(description: Mapping[str, Any]) -> tuple[gym.spaces.Box, FastBox]:
    """The observation and action spaces the core declares (float32)."""
    observation = gym.spaces.Box(
        description["observation_low"], description["observation_high"], dtype=np.float32
    )
    action = FastBox(
        description["action_low"].astype(np.float32),
        description["action_high"].astype(np.float32),
        dtype=np.float32,
    )
    return observation, action


def env_signature(cls: type) -> inspect.Signature:
    """An env class's signature: its task arguments (keyword-only, the core's defaults), then
    the env's own keyword arguments (those of every `__init__` along the class's bases)."""
    spec = cls.SPEC
    defaults = spec.argument_defaults()
    task = [
        inspect.Parameter(a.name, KEYWORD_ONLY, default=defaults[a.name], annotation=a.annotation)
        for a in spec.arguments
    ]
    own = {}
    for base in cls.__mro__:
        if "__init__" in base.__dict__ and issubclass(base, FlyloopEnv):
            for p in inspect.signature(base.__init__, eval_str=True).parameters.values():
                if p.name != "self" and p.kind is not inspect.Parameter.VAR_KEYWORD:
                    own.setdefault(p.name, p.replace(kind=KEYWORD_ONLY))
    return inspect.Signature([*task, *own.values()])


def arguments_doc(spec: TaskSpec) -> str:
    """The docstring section listing the task arguments with the core's defaults."""
    defaults = spec.argument_defaults()
    lines = [f"    - ``{a.name}={defaults[a.name]!r}``: {a.doc}" for a in spec.arguments]
    return (
        "\n\n    ## Task arguments (from the core's parameter table)\n\n" + "\n".join(lines) + "\n"
    )


class FlyloopEnv(gym.Env):
    """Base of the flyloop envs (see QuadHoverEnv, QuadWaypointsEnv, Lander2DEnv)."""

    metadata = {"render_modes": ["human", "rgb_array"], "render_fps": 50}
    SPEC: TaskSpec
    # Set before __init__ can fail, so close() (and VectorEnv.__del__) always work.
    _backend = None
    _view = None

    def __init_subclass__(cls, **kwargs: Any) -> None:
        super().__init_subclass__(**kwargs)
        if "SPEC" in cls.__dict__:
            cls.__signature__ = env_signature(cls)
            cls.__doc__ = (cls.__doc__ or "") + arguments_doc(cls.SPEC)

    def __init__(
        self,
        *,
        render_mode: str | None = None,
        model_params: Mapping[str, Any] | None = None,
        sitl_path: str | None = None,
        sitl_address: Any = None,
        vehicle: int = 1,
        timeout: float = 5.0,
        backend: str = "sitl",
        **task_arguments: Any,
    ) -> None:
        spec = self.SPEC
        if render_mode is not None and render_mode not in self.metadata["render_modes"]:
            raise ValueError(
                f"render_mode must be None, 'human' or 'rgb_array', got {render_mode!r}"
            )
        if not (isinstance(timeout, (int, float)) and not isinstance(timeout, bool)) or not (
            timeout > 0
        ):
            raise ValueError(f"timeout must be a number of seconds > 0, got {timeout!r}")
        self._view = None
        self.render_mode = render_mode
        arguments = task_arguments_of(spec, task_arguments, f"{type(self).__name__}()")
        self.config = resolve_config(spec, arguments, model_params)
        check_backend(backend, sitl_path, sitl_address)
        self.core = spec.describe(self.config)
        self.dt = float(self.core["dt"])
        self.metadata = {**type(self).metadata, "render_fps": max(1, round(1.0 / self.dt))}
        self.observation_space, self.action_space = spaces_of(self.core)
        self._backend = make_backend(
            backend, spec, self.config, self.core,
            sitl_path=sitl_path, sitl_address=sitl_address, vehicle=vehicle, timeout=timeout,
        )  # fmt: skip
        self.backend = self._backend.name
        self._episode_return = 0.0
        self._last: tuple[np.ndarray, dict[str, Any], float | None] | None = None
        if render_mode is not None:
            try:
                self._view = self._make_view(render_mode)
            except BaseException:
                self.close()
                raise

    # ---- gymnasium API ----

    def reset(self, *, seed: int | None = None, options: dict[str, Any] | None = None):
        """Starts an episode. With `seed` the episode is exactly reproducible (the core's
        seed is `seed`); without, the seed is drawn from the env's generator (seeded by the
        last seeded reset). `options` is not used."""
        if seed is not None:
            seed = check_seed(seed)
        super().reset(seed=seed)
        if seed is None:
            seed = int(self.np_random.integers(0, 2**63))
        self.episode_seed = seed
        obs, info = self._backend.reset_one(seed)
        add_fault_list(info)
        self._episode_return = 0.0
        self._last = (obs, info, None)
        if self._view is not None:
            self._view.reset()
            if self.render_mode == "human":
                self.render()
        return obs, info

    def step(self, action):
        a = as_actions(action, self.action_space.shape, "action")
        obs, reward, terminated, truncated, info = self._backend.step_one(a)
        add_fault_list(info)
        if self._view is not None:
            self._episode_return += reward
            self._last = (obs, info, reward)
            if self.render_mode == "human":
                self.render()
        return obs, reward, terminated, truncated, info

    # ---- rendering ----

    def _make_view(self, render_mode: str):
        raise NotImplementedError

    def _scene(self, obs: np.ndarray, info: dict[str, Any], reward: float | None):
        raise NotImplementedError

    def render(self):
        """Draws the last step: an (H, W, 3) uint8 array in "rgb_array" mode, a window
        frame in "human" mode (done by step() and reset() already), None without a
        render_mode."""
        if self._view is None:
            if self.render_mode is None:
                gym.logger.warn(
                    "render() was called without a render_mode; make the env with "
                    'render_mode="rgb_array" or "human"'
                )
            return None
        if self._last is None:
            raise gym.error.ResetNeeded("call reset() before render()")
        obs, info, reward = self._last
        return self._view.render(self._scene(obs, info, reward))

    def close(self) -> None:
        """Closes the window (if any) and stops the SITL this env started. Safe to call
        more than once."""
        view, self._view = self._view, None
        if view is not None:
            view.close()
        if self._backend is not None:
            self._backend.close()

    @property
    def sitl_process(self) -> SitlProcess | None:
        """The SITL process this env started (None when attached to an address)."""
        return None if self._backend is None else self._backend.sitl_process
