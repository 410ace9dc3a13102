"""The vector envs: N sub-envs of one task on one backend (flyloop.backends), stepped in one
exchange: N vehicles of ONE SITL process (backend="sitl", the default; at most 254), or N
core instances in this process (backend="native", stepped over `num_threads` threads with
the GIL released).

    envs = gymnasium.make_vec("flyloop/QuadHover-v0", num_envs=16)   # after `import flyloop`
    obs, infos = envs.reset(seed=42)          # sub-env i gets seed 42 + i
    obs, rewards, terminated, truncated, infos = envs.step(envs.action_space.sample())

Autoreset is gymnasium's NEXT_STEP mode: the step after a sub-env ends resets it (its action
is ignored) and returns its first observation with reward 0 and both flags False. Sub-env i
draws its unseeded episode seeds from its own generator, seeded with `seed + i`, exactly as a
single env reset with `seed + i` does — so the trajectories equal N single envs'. Infos hold
every key of the single env's info as an array over the sub-envs (float32 values as the task
frame carries them) with gymnasium's `_key` masks. Non-finite actions (in a sub-env not being
reset) refuse the whole step with ValueError and change nothing.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
from gymnasium.utils import seeding
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import batch_space

from .backends import Outputs, default_threads, make_backend
from .envs.base import SEED_LIMIT, as_actions, check_seed, spaces_of
from .envs.lander2d import Lander2DEnv, Lander2DLandingEnv
from .envs.quad_hover import QuadHoverEnv
from .envs.quad_waypoints import QuadWaypointsEnv
from .spaces import FastBox
from .tasks import TaskSpec, resolve_config
from .vector_infos import InfoColumns, vector_task_arguments


def _count(name: str, value: Any) -> int:
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
        raise TypeError(f"{name} must be an integer, got {value!r}")
    if value < 1:
        raise ValueError(f"{name} must be at least 1, got {value}")
    return int(value)


def _refuse_non_finite(actions: np.ndarray, resetting: np.ndarray) -> None:
    """Raises naming the first non-finite action of a sub-env that is not being reset."""
    bad = ~np.isfinite(actions) & ~resetting[:, None]
    if bad.any():
        i, j = np.argwhere(bad)[0]
        v = {"nan": "NaN"}.get(str(actions[i, j]), str(actions[i, j]))
        raise ValueError(f"actions[{i}, {j}] = {v}: actions must be finite; step refused")


class FlyloopVectorEnv(VectorEnv):
    """`num_envs` sub-envs of `SPEC` on `backend`; task arguments as the single env's.

    Observations (N, n_obs) float32, rewards (N,) float64, flags (N,) bool. render_mode must
    be None. `num_threads` (native backend) threads step the sub-envs (default: the CPUs
    available). `copy=False` returns the internal arrays themselves (overwritten by the next
    step: the fastest path for a learner that copies anyway).
    """

    metadata = {"autoreset_mode": AutoresetMode.NEXT_STEP, "render_modes": []}
    SPEC: TaskSpec
    SINGLE: type
    # Set before __init__ can fail, so close() (and VectorEnv.__del__) always work.
    _backend = None

    def __init__(
        self,
        num_envs: int = 1,
        *,
        backend: str = "sitl",
        model_params: Mapping[str, Any] | None = None,
        render_mode: str | None = None,
        sitl_path: str | None = None,
        timeout: float = 5.0,
        num_threads: int | None = None,
        copy: bool = True,
        **arguments: Any,
    ) -> None:
        spec = self.SPEC
        n = self.num_envs = _count("num_envs", num_envs)
        num_threads = _count(
            "num_threads", default_threads() if num_threads is None else num_threads
        )
        if render_mode is not None:
            raise ValueError(
                "the flyloop vector envs do not render; use a single env with render_mode"
            )
        self.config = resolve_config(spec, vector_task_arguments(spec, arguments), model_params)
        self.core = spec.describe(self.config)
        self.render_mode = None
        self.single_observation_space, self.single_action_space = spaces_of(self.core)
        self.observation_space = batch_space(self.single_observation_space, n)
        batched = batch_space(self.single_action_space, n)
        self.action_space = FastBox(batched.low, batched.high, dtype=np.float32)
        self.dt = float(self.core["dt"])
        self.metadata = {**type(self).metadata, "render_fps": max(1, round(1.0 / self.dt))}
        self._copy = bool(copy)
        layout = self.core["info"]
        self._columns = InfoColumns(layout, 0, n)
        self._out = Outputs.zeros(
            n, self.single_observation_space.shape[0], sum(k for _, _, k in layout)
        )
        self._resetting = np.zeros(n, bool)
        self._seeds = np.zeros(n, np.uint64)
        self._no_actions = np.zeros(self.action_space.shape, np.float32)
        # Generators are made when first drawn from: 100,000 of them up front would cost
        # seconds and tens of MB. `_seed_of[i]` is what generator i is seeded with.
        self._generators: list[np.random.Generator | None] = [None] * n
        self._seed_of: list[int | None] = [None] * n
        self._backend = make_backend(
            backend, spec, self.config, self.core, n,
            sitl_path=sitl_path, timeout=timeout, num_threads=num_threads,
        )  # fmt: skip
        self.backend = self._backend.name
        self.num_threads = self._backend.num_threads

    # ---- seeds ----

    def _draw(self, i: int) -> int:
        g = self._generators[i]
        if g is None:
            g = self._generators[i] = seeding.np_random(self._seed_of[i])[0]
        # The single env's `integers(0, 2**63)`: numpy's Lemire method over 2**63 values is
        # the raw 64-bit draw shifted right by one, without its per-call set-up (a fifth of
        # the cost; the vector env draws for every auto-reset).
        return int(g.bit_generator.random_raw()) >> 1

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
            # The env's own generator follows the first seed given.
            first = base if isinstance(seed, (int, np.integer)) else given[0]
            self._np_random, self._np_random_seed = seeding.np_random(first)
        self._seeds[:] = np.array(seeds, np.uint64)
        self._resetting[:] = True
        self._backend.run(self._no_actions, self._resetting, self._seeds, self._out)
        self._resetting[:] = False
        return self._give(self._out.obs), self._columns.infos(self._out.info)

    def step(self, actions):
        out = self.step_arrays(actions)
        return (
            self._give(out.obs),
            self._give(out.rewards),
            self._give(out.terminated),
            self._give(out.truncated),
            self._columns.infos(out.info),
        )

    def step_arrays(self, actions) -> Outputs:
        """`step` without building the infos: the arrays it wrote (overwritten by the next
        call), for wrappers that build their own (flyloop.sb3)."""
        a = as_actions(actions, self.action_space.shape, "actions")
        out, resetting = self._out, self._resetting
        np.logical_or(out.terminated, out.truncated, out=resetting)
        # Refused before a seed is drawn: a refused step changes nothing.
        if not np.isfinite(a).all():
            _refuse_non_finite(a, resetting)
        for i in np.flatnonzero(resetting):
            self._seeds[i] = self._draw(int(i))
        self._backend.run(a, resetting, self._seeds, out)
        return out

    def reset_ended(self) -> tuple[np.ndarray, np.ndarray, list[dict[str, Any]]]:
        """Autoreset within the step, for APIs that want it (flyloop.sb3): every sub-env the
        last step ended starts its next episode now, with the seed the next step would have
        drawn, so the next step steps it with its action. Returns the indices of those
        sub-envs, their first observations and their info dicts. Native backend only."""
        if not hasattr(self._backend, "reset_rows"):
            raise ValueError("reset_ended needs backend='native'")
        out = self._out
        ended = out.terminated | out.truncated
        rows = np.flatnonzero(ended)
        for i in rows:
            self._seeds[i] = self._draw(int(i))
        self._backend.reset_rows(ended, self._seeds, out)
        return rows, out.obs[rows], self._columns.dicts(out.info[rows])

    def info_dicts(self) -> list[dict[str, Any]]:
        """The last step's or reset's info as one dict per sub-env."""
        return self._columns.dicts(self._out.info)

    def _give(self, array: np.ndarray) -> np.ndarray:
        return array.copy() if self._copy else array

    def close_extras(self, **kwargs: Any) -> None:
        if self._backend is not None:
            self._backend.close()

    @property
    def sitl_process(self):
        """The SITL process all sub-envs fly in (None with backend="native")."""
        return None if self._backend is None else self._backend.sitl_process


class QuadHoverVectorEnv(FlyloopVectorEnv):
    """`num_envs` QuadHover sub-envs (arguments as QuadHoverEnv)."""

    SPEC = QuadHoverEnv.SPEC
    SINGLE = QuadHoverEnv


class QuadWaypointsVectorEnv(FlyloopVectorEnv):
    """`num_envs` QuadWaypoints sub-envs (arguments as QuadWaypointsEnv)."""

    SPEC = QuadWaypointsEnv.SPEC
    SINGLE = QuadWaypointsEnv


class Lander2DVectorEnv(FlyloopVectorEnv):
    """`num_envs` Lander2D sub-envs (arguments as Lander2DEnv)."""

    SPEC = Lander2DEnv.SPEC
    SINGLE = Lander2DEnv


class Lander2DLandingVectorEnv(FlyloopVectorEnv):
    """`num_envs` Lander2D-v1 sub-envs, the landing reward (arguments as Lander2DLandingEnv)."""

    SPEC = Lander2DLandingEnv.SPEC
    SINGLE = Lander2DLandingEnv


# The ids' vector entry points (flyloop.registration).
quad_hover_vector = QuadHoverVectorEnv
quad_waypoints_vector = QuadWaypointsVectorEnv
lander2d_vector = Lander2DVectorEnv
lander2d_landing_vector = Lander2DLandingVectorEnv
