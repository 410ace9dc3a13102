"""The native vector env: N core task instances in this process, stepped in one call.

    envs = gymnasium.make_vec("flyloop/QuadHover-v0", num_envs=1024,
                              vectorization_mode="vector_entry_point", backend="native")
    obs, infos = envs.reset(seed=42)          # sub-env i gets seed 42 + i
    obs, rewards, terminated, truncated, infos = envs.step(actions)   # actions (1024, 4)

The extension (`flyloop._native.Batch`) steps every sub-env with the GIL released, split
over `num_threads` threads (default: the CPUs this process may use), writing observations,
rewards, flags and info values straight into arrays allocated once here. Each sub-env only
touches its own rows, so results do not depend on the thread count.

Semantics are the SITL vector env's (flyloop.vector): NEXT_STEP autoreset (the step after a
sub-env ends resets it, ignores its action and returns its first observation with reward 0
and both flags False); sub-env i draws unseeded episode seeds from its own generator seeded
with `seed + i`, as a single env reset with `seed + i` does; infos hold every key of the
single env's info as an array over the sub-envs (float32 values as the SITL frame carries
them) with gymnasium's `_key` masks. Non-finite actions refuse the whole step with
ValueError and change nothing.
"""

from __future__ import annotations

import os
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
from gymnasium.utils import seeding
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import batch_space

from . import _native
from .envs.base import SEED_LIMIT, as_actions, check_seed, spaces_of
from .spaces import FastBox
from .tasks import TaskSpec, resolve_config
from .vector_infos import InfoColumns, task_arguments


def default_threads() -> int:
    """The CPUs this process may run on."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # not Linux
        return os.cpu_count() or 1


class NativeVectorEnv(VectorEnv):
    """`num_envs` sub-envs of `spec` stepped in-process; task arguments as the single env's
    (`single` is its class, for the argument defaults). `num_threads` threads step them
    (default: the CPUs available). `copy=False` returns the internal arrays themselves
    (overwritten by the next step: the fastest path for a learner that copies anyway)."""

    metadata = {"autoreset_mode": AutoresetMode.NEXT_STEP, "render_modes": []}
    _batch = None

    def __init__(
        self,
        spec: TaskSpec,
        single: type,
        num_envs: int = 1,
        *,
        model_params: Mapping[str, Any] | None = None,
        render_mode: str | None = None,
        num_threads: int | None = None,
        copy: bool = True,
        **arguments: Any,
    ) -> None:
        if isinstance(num_envs, bool) or not isinstance(num_envs, (int, np.integer)):
            raise TypeError(f"num_envs must be an integer, got {num_envs!r}")
        if num_envs < 1:
            raise ValueError(f"num_envs must be at least 1, got {num_envs}")
        if num_threads is None:
            num_threads = default_threads()
        if isinstance(num_threads, bool) or not isinstance(num_threads, (int, np.integer)):
            raise TypeError(f"num_threads must be an integer, got {num_threads!r}")
        if num_threads < 1:
            raise ValueError(f"num_threads must be at least 1, got {num_threads}")
        if render_mode is not None:
            raise ValueError(
                "the flyloop vector envs do not render; use a single env with render_mode"
            )
        self.spec_task = spec
        self.config = resolve_config(spec, task_arguments(spec, single, arguments), model_params)
        self.core = spec.describe(self.config)
        self.num_envs = n = int(num_envs)
        self.render_mode = None
        self.backend = "native"
        self.single_observation_space, self.single_action_space = spaces_of(self.core)
        self.observation_space = batch_space(self.single_observation_space, n)
        batched = batch_space(self.single_action_space, n)
        self.action_space = FastBox(batched.low, batched.high, dtype=np.float32)
        self.dt = float(self.core["dt"])
        self.metadata = {**type(self).metadata, "render_fps": max(1, round(1.0 / self.dt))}
        self._copy = bool(copy)

        self._batch = _native.Batch(spec.name, self.config, n, int(num_threads))
        self.num_threads = self._batch.num_threads
        self._columns = InfoColumns(self.core["info"], 0, n)
        self._obs = np.zeros((n, self._batch.observation_size), np.float32)
        self._info = np.zeros((n, self._batch.info_size), np.float32)
        self._rewards = np.zeros(n, np.float64)
        self._terminated = np.zeros(n, bool)
        self._truncated = np.zeros(n, bool)
        self._resetting = np.zeros(n, bool)
        self._seeds = np.zeros(n, np.uint64)
        self._no_actions = np.zeros(self.action_space.shape, np.float32)
        # Generators are made when first drawn from: 100,000 of them up front would cost
        # seconds and tens of MB. `_seed_of[i]` is what generator i is seeded with.
        self._generators: list[np.random.Generator | None] = [None] * n
        self._seed_of: list[int | None] = [None] * n

    # ---- seeds ----

    def _draw(self, i: int) -> int:
        g = self._generators[i]
        if g is None:
            g = self._generators[i] = seeding.np_random(self._seed_of[i])[0]
        return int(g.integers(0, 2**63))

    def _seed_env(self, i: int, seed: int) -> int:
        self._seed_of[i] = seed
        self._generators[i] = None
        return seed

    # ---- gymnasium API ----

    def reset(
        self,
        *,
        seed: int | Sequence[int | None] | None = None,
        options: dict[str, Any] | None = None,
    ):
        """Resets every sub-env. `seed` int: sub-env i gets seed + i; a list: one seed per
        sub-env (None entries draw from that sub-env's generator); None: all draw."""
        n = self.num_envs
        if seed is None:
            seeds = [self._draw(i) for i in range(n)]
        elif isinstance(seed, (int, np.integer)) and not isinstance(seed, bool):
            base = check_seed(seed)
            if base + n > SEED_LIMIT:
                raise ValueError(f"seed + num_envs - 1 must be below 2**64, got seed {seed}")
            seeds = [self._seed_env(i, base + i) for i in range(n)]
        else:
            given = list(seed)
            if len(given) != n:
                raise ValueError(f"seed list has {len(given)} entries for {n} envs")
            seeds = [
                self._draw(i) if s is None else self._seed_env(i, check_seed(s))
                for i, s in enumerate(given)
            ]
        if seed is not None:
            # As the SITL vector env: the env's own generator follows the first seed given.
            first = base if isinstance(seed, (int, np.integer)) else given[0]
            self._np_random, self._np_random_seed = seeding.np_random(first)
        self._seeds[:] = np.array(seeds, np.uint64)
        self._resetting[:] = True
        self._run(self._no_actions)
        self._resetting[:] = False
        return self._out(self._obs), self._columns.infos(self._info)

    def step(self, actions):
        a = as_actions(actions, self.action_space.shape, "actions")
        resetting = self._resetting
        np.logical_or(self._terminated, self._truncated, out=resetting)
        for i in np.flatnonzero(resetting):
            self._seeds[i] = self._draw(int(i))
        self._run(a)
        return (
            self._out(self._obs),
            self._out(self._rewards),
            self._out(self._terminated),
            self._out(self._truncated),
            self._columns.infos(self._info),
        )

    def _run(self, actions: np.ndarray) -> None:
        batch = self._batch
        if batch is None or batch.closed:
            raise RuntimeError("this vector env is closed; make a new one to go on")
        batch.step(
            actions,
            self._resetting,
            self._seeds,
            self._obs,
            self._info,
            self._rewards,
            self._terminated,
            self._truncated,
        )

    def _out(self, array: np.ndarray) -> np.ndarray:
        return array.copy() if self._copy else array

    def close_extras(self, **kwargs: Any) -> None:
        batch, self._batch = self._batch, None
        if batch is not None:
            batch.close()
