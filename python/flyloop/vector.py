"""Vector envs: N vehicles of ONE SITL process, all stepped by one datagram exchange
(backend="sitl", the default), or N core instances in this process (backend="native", see
flyloop.native_vector).

    envs = gymnasium.make_vec("flyloop/QuadHover-v0", num_envs=16)   # after `import flyloop`
    obs, infos = envs.reset(seed=42)          # vehicle i gets seed 42 + i
    obs, rewards, terminated, truncated, infos = envs.step(envs.action_space.sample())

Autoreset is gymnasium's NEXT_STEP mode: the step after a sub-env ends resets it (its action
is ignored) and returns its first observation with reward 0 and both flags False. Sub-env i
draws its unseeded episode seeds from its own generator, seeded with `seed + i`, exactly as a
single env reset with `seed + i` does — so the trajectories equal N single envs'.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
from gymnasium.utils import seeding
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import batch_space

from .envs.base import (
    as_actions,
    check_backend,
    check_seed,
    frame_array_count,
    spaces_of,
    start_sitl,
)
from .envs.lander2d import Lander2DEnv, Lander2DLandingEnv
from .envs.quad_hover import QuadHoverEnv
from .envs.quad_waypoints import QuadWaypointsEnv
from .errors import SitlError
from .link import SitlLink
from .native_vector import NativeVectorEnv
from .protocol import (
    FRAME_HEADER_LEN,
    MAV_RESULT_ACCEPTED,
    Datagram,
    Encoder,
    FrameSink,
)
from .sitl_process import SitlProcess
from .spaces import FastBox
from .tasks import TaskSpec, resolve_config
from .vector_infos import InfoColumns, task_arguments

MAX_VEHICLES = 254


class FlyloopVectorEnv(VectorEnv):
    """`num_envs` vehicles of one SITL flying `spec`; arguments as the single env's.

    Observations (N, n_obs) float32, rewards (N,) float64, flags (N,) bool. Infos: every key
    of the single env's info as an array over the N envs (vectors as (N, k)), with gymnasium's
    `_key` masks (all True: every sub-env reports every key). render_mode must be None.
    """

    metadata = {"autoreset_mode": AutoresetMode.NEXT_STEP, "render_modes": []}
    SPEC: TaskSpec
    SINGLE: type
    # Set before __init__ can fail, so close() (and VectorEnv.__del__) always work.
    _link: SitlLink | None = None
    _process: SitlProcess | None = None

    def __init__(
        self,
        num_envs: int = 1,
        *,
        model_params: Mapping[str, Any] | None = None,
        render_mode: str | None = None,
        sitl_path: str | None = None,
        timeout: float = 5.0,
        **arguments: Any,
    ) -> None:
        spec = self.SPEC
        if isinstance(num_envs, bool) or not isinstance(num_envs, (int, np.integer)):
            raise TypeError(f"num_envs must be an integer, got {num_envs!r}")
        if not 1 <= num_envs <= MAX_VEHICLES:
            raise ValueError(f"num_envs must be in [1, {MAX_VEHICLES}], got {num_envs}")
        if render_mode is not None:
            raise ValueError(
                "the flyloop vector envs do not render; use a single env with render_mode"
            )
        self._link: SitlLink | None = None
        self._process = None
        self.config = resolve_config(
            spec, task_arguments(spec, self.SINGLE, arguments), model_params
        )
        self.core = spec.describe(self.config)
        self.num_envs = int(num_envs)
        self.render_mode = None
        self.backend = "sitl"
        self.single_observation_space, self.single_action_space = spaces_of(self.core)
        self.observation_space = batch_space(self.single_observation_space, self.num_envs)
        batched = batch_space(self.single_action_space, self.num_envs)
        self.action_space = FastBox(batched.low, batched.high, dtype=np.float32)
        self.dt = float(self.core["dt"])
        self.metadata = {**type(self).metadata, "render_fps": max(1, round(1.0 / self.dt))}

        self._n_obs = self.single_observation_space.shape[0]
        layout = self.core["info"]
        self._n_values = FRAME_HEADER_LEN + self._n_obs + sum(n for _, _, n in layout)
        self._n_arrays = frame_array_count(self._n_values)
        self._columns = InfoColumns(layout, FRAME_HEADER_LEN + self._n_obs, self.num_envs)
        self._encoder = Encoder()
        self._generators: list[np.random.Generator] = [
            seeding.np_random()[0] for _ in range(self.num_envs)
        ]
        self._autoreset = np.zeros(self.num_envs, bool)
        self._values = np.zeros((self.num_envs, self._n_values), np.float32)
        self._ids = list(range(1, self.num_envs + 1))
        self._sink = FrameSink(self._ids, self._n_arrays)
        self._dt_us = max(1, round(self.dt * 1e6))  # names each step (see FlyloopEnv)

        self._process = start_sitl(
            spec, self.config, sitl_path=sitl_path, vehicles=self.num_envs, timeout=timeout
        )
        self._link = SitlLink(self._process.address, timeout=timeout, process=self._process)

    # ---- exchange ----

    def _collect_done(self, acks: int):
        sink = self._sink

        def done(d: Datagram) -> bool:
            if not sink.complete:
                return False
            return not acks or sum(m.get_type() == "COMMAND_ACK" for m in d.messages) >= acks

        return done

    def _exchange(self, data: bytes, acks: int, what: str) -> Datagram:
        return self._link_ok().exchange(data, self._collect_done(acks), what, self._sink)

    def _fill(self, d: Datagram) -> None:
        values = self._values
        values[:] = self._sink.values()[:, : self._n_values]
        acks = [m for m in d.messages if m.get_type() == "COMMAND_ACK"]
        if any(m.result != MAV_RESULT_ACCEPTED for m in acks):
            texts = "; ".join(m.text for m in d.messages if m.get_type() == "STATUSTEXT")
            raise SitlError(f"the SITL refused a reset: {texts}")
        n_obs, n_info = values[0, 4], values[0, 5]
        if n_obs != self._n_obs or n_obs + n_info + FRAME_HEADER_LEN != self._n_values:
            raise SitlError(
                f"the SITL's task frame holds {int(n_obs)} observation and {int(n_info)} info "
                f"values; this vector env expects {self._n_obs} and "
                f"{self._n_values - FRAME_HEADER_LEN - self._n_obs}"
            )

    def _infos(self) -> dict[str, Any]:
        return self._columns.infos(self._values)

    def _link_ok(self) -> SitlLink:
        if self._link is None:
            raise SitlError("this vector env is closed")
        return self._link

    # ---- gymnasium API ----

    def reset(
        self,
        *,
        seed: int | Sequence[int] | None = None,
        options: dict[str, Any] | None = None,
    ):
        """Resets every sub-env. `seed` int: sub-env i gets seed + i; a list: one seed per
        sub-env (None entries draw from that sub-env's generator); None: all draw."""
        if seed is None:
            seeds: list[int | None] = [None] * self.num_envs
        elif isinstance(seed, (int, np.integer)) and not isinstance(seed, bool):
            seeds = [check_seed(seed) + i for i in range(self.num_envs)]
        else:
            seeds = list(seed)
            if len(seeds) != self.num_envs:
                raise ValueError(f"seed list has {len(seeds)} entries for {self.num_envs} envs")
        if seed is not None:
            self._np_random, self._np_random_seed = seeding.np_random(
                seeds[0] if seeds[0] is not None else None
            )
        data = b""
        for i, s in enumerate(seeds):
            data += self._encoder.reset(self._episode_seed(i, s), self._ids[i])
        self._sink.expect([True] * self.num_envs)
        d = self._exchange(data, self.num_envs, "replies to the reset commands")
        self._fill(d)
        self._autoreset[:] = False
        obs = self._values[:, FRAME_HEADER_LEN : FRAME_HEADER_LEN + self._n_obs].copy()
        return obs, self._infos()

    def _episode_seed(self, i: int, seed: int | None) -> int:
        """As the single env: an explicit seed seeds sub-env i's generator; otherwise the
        episode seed is drawn from it."""
        if seed is not None:
            seed = check_seed(seed)
            self._generators[i] = seeding.np_random(seed)[0]
            return seed
        return int(self._generators[i].integers(0, 2**63))

    def step(self, actions):
        a = as_actions(actions, self.action_space.shape, "actions")
        if not np.isfinite(a).all():
            raise ValueError("actions must be finite; step refused")
        resetting = self._autoreset.copy()
        enc = self._encoder
        steps = self._sink.step_ids(self._dt_us)
        if resetting.any():
            self._sink.expect(resetting)
            parts = []
            rows = a.tolist()
            for i, v in enumerate(self._ids):
                if resetting[i]:
                    parts.append(enc.reset(self._episode_seed(i, None), v))
                else:
                    parts.append(enc.controls_batch((v,), (rows[i],), (steps[i],)))
            data = b"".join(parts)
        else:
            self._sink.expect()
            data = enc.controls_batch(self._ids, a.tolist(), steps)
        d = self._exchange(data, int(resetting.sum()), "task frames after a step")
        self._fill(d)
        values = self._values
        obs = values[:, FRAME_HEADER_LEN : FRAME_HEADER_LEN + self._n_obs].copy()
        rewards = values[:, 0].astype(np.float64)
        terminated = values[:, 1] != 0.0
        truncated = values[:, 2] != 0.0
        if resetting.any():
            rewards[resetting] = 0.0
            terminated[resetting] = False
            truncated[resetting] = False
        self._autoreset = terminated | truncated
        return obs, rewards, terminated, truncated, self._infos()

    def close_extras(self, **kwargs: Any) -> None:
        link, self._link = self._link, None
        if link is not None:
            link.close()
        process, self._process = self._process, None
        if process is not None:
            process.stop()

    @property
    def sitl_process(self):
        """The SITL process all sub-envs fly in."""
        return self._process


class QuadHoverVectorEnv(FlyloopVectorEnv):
    """`num_envs` QuadHover vehicles in one SITL (arguments as QuadHoverEnv)."""

    SPEC = QuadHoverEnv.SPEC
    SINGLE = QuadHoverEnv


class QuadWaypointsVectorEnv(FlyloopVectorEnv):
    """`num_envs` QuadWaypoints vehicles in one SITL (arguments as QuadWaypointsEnv)."""

    SPEC = QuadWaypointsEnv.SPEC
    SINGLE = QuadWaypointsEnv


class Lander2DVectorEnv(FlyloopVectorEnv):
    """`num_envs` Lander2D vehicles in one SITL (arguments as Lander2DEnv)."""

    SPEC = Lander2DEnv.SPEC
    SINGLE = Lander2DEnv


class Lander2DLandingVectorEnv(FlyloopVectorEnv):
    """`num_envs` Lander2D-v1 vehicles (landing reward) in one SITL (arguments as
    Lander2DLandingEnv)."""

    SPEC = Lander2DLandingEnv.SPEC
    SINGLE = Lander2DLandingEnv


def _vector_entry(sitl_class: type[FlyloopVectorEnv]):
    """The vector entry point of an env id: `backend="sitl"` (default) or `"native"`."""

    def make(num_envs: int = 1, *, backend: str = "sitl", **kwargs: Any) -> VectorEnv:
        if check_backend(backend, kwargs.get("sitl_path")) == "native":
            return NativeVectorEnv(sitl_class.SPEC, sitl_class.SINGLE, num_envs, **kwargs)
        return sitl_class(num_envs, **kwargs)

    make.__name__ = make.__qualname__ = f"make_{sitl_class.SPEC.name}_vector"
    make.__doc__ = f"{sitl_class.__doc__} With backend='native': NativeVectorEnv."
    return make


quad_hover_vector = _vector_entry(QuadHoverVectorEnv)
quad_waypoints_vector = _vector_entry(QuadWaypointsVectorEnv)
lander2d_vector = _vector_entry(Lander2DVectorEnv)
lander2d_landing_vector = _vector_entry(Lander2DLandingVectorEnv)
