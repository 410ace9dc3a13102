"""FlyloopEnv: what the envs share — the backend (a SITL of their own or one they attach to,
one datagram per step; or the core in-process), seeding, the info dict and rendering."""

from __future__ import annotations

import math
import os
import tempfile
from collections.abc import Mapping, Sequence
from typing import Any

import gymnasium as gym
import numpy as np

from .. import _native
from ..errors import SitlError, SitlParameterError
from ..link import SitlLink
from ..protocol import (
    FRAME_ARRAY_LEN,
    FRAME_HEADER_LEN,
    FRAME_ID,
    MAV_RESULT_ACCEPTED,
    RESET_COMMAND,
    Datagram,
    Encoder,
    FrameSink,
    mavlink2,
)
from ..sitl_process import SitlProcess, find_sitl_binary
from ..spaces import FastBox
from ..tasks import (
    FLAG,
    INTEGER,
    RANGE_PREFIX,
    REAL,
    TaskSpec,
    parameter_error,
    resolve_config,
    to_toml,
)

SEED_LIMIT = 2**64
BACKENDS = ("sitl", "native")
_HIL_STATE_QUATERNION = mavlink2.MAVLINK_MSG_ID_HIL_STATE_QUATERNION


def frame_array_count(n_values: int) -> int:
    return max(1, math.ceil(n_values / FRAME_ARRAY_LEN))


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


def check_backend(backend: Any, sitl_path: Any, sitl_address: Any = None) -> str:
    """`backend` checked; the SITL's own arguments are refused with the native backend."""
    if backend not in BACKENDS:
        raise ValueError(f"backend must be 'sitl' or 'native', got {backend!r}")
    if backend == "native":
        for name, value in (("sitl_path", sitl_path), ("sitl_address", sitl_address)):
            if value is not None:
                raise ValueError(f"{name} applies to backend='sitl' only, got {value!r}")
    return backend


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


def info_reader(layout: Sequence[Sequence[Any]], n_obs: int):
    """A function: frame values -> the info dict (the core's info `layout`: name, kind,
    count)."""
    fields = []
    at = FRAME_HEADER_LEN + n_obs
    for name, kind, count in layout:
        fields.append((name, kind, at, at + count))
        at += count

    def read(values: np.ndarray) -> dict[str, Any]:
        row = values.tolist()
        info: dict[str, Any] = {}
        for name, kind, a, b in fields:
            if kind == REAL:
                info[name] = row[a]
            elif kind == FLAG:
                info[name] = row[a] != 0.0
            elif kind == INTEGER:
                info[name] = int(row[a])
            else:
                info[name] = np.array(row[a:b])
        return info

    return read


def start_sitl(
    spec: TaskSpec,
    config: Mapping[str, Any],
    *,
    sitl_path: Any,
    vehicles: int,
    timeout: float,
    extra_args: tuple[str, ...] = (),
) -> SitlProcess:
    """A SITL flying `spec` with `config` (written to a temporary --config file)."""
    binary = find_sitl_binary(sitl_path)
    fd, path = tempfile.mkstemp(prefix="flyloop-env-", suffix=".toml")
    try:
        with os.fdopen(fd, "w") as f:
            f.write(to_toml(config))
        args = [
            "--task",
            spec.name,
            "--gcs",
            "off",
            "--mode",
            "lockstep",
            "--vehicles",
            str(vehicles),
            "--no-state-reply",
            "--log-level",
            "warn",
            "--config",
            path,
            *extra_args,
        ]
        try:
            return SitlProcess(binary, args, start_timeout=timeout)
        except SitlError as exc:
            if exc.exit_code == 1 and "config file" in exc.stderr_tail:
                line = next(
                    (x for x in exc.stderr_tail.splitlines() if "config file" in x),
                    exc.stderr_tail,
                )
                raise parameter_error(spec, line) from None
            raise
    finally:
        os.unlink(path)


def configure_attached(link: SitlLink, encoder: Encoder, spec: TaskSpec, config, vehicle: int):
    """Checks that an attached SITL's vehicle flies `spec`'s task, sets `config` over the
    parameter protocol (values travel as float32; they apply at the next reset) and turns
    HIL_STATE_QUATERNION off in its replies to this client."""
    frame = link.exchange(
        encoder.request_message(FRAME_ID, vehicle),
        lambda d: vehicle in d.names,
        f"task frame of vehicle {vehicle}",
    )
    flies = frame.names[vehicle]
    if flies != spec.name:
        raise SitlError(
            f"the SITL at {link.address[0]}:{link.address[1]} flies task {flies!r} on vehicle "
            f"{vehicle}; {spec.env_id} needs a SITL started with --task {spec.name}"
        )
    link.exchange(
        encoder.set_message_interval(_HIL_STATE_QUATERNION, -1, vehicle),
        lambda d: any(m.get_type() == "COMMAND_ACK" for m in d.messages),
        "COMMAND_ACK to SET_MESSAGE_INTERVAL",
    )
    ids = spec.param_ids
    if any(name.startswith(RANGE_PREFIX) for name in config):
        raise ValueError(
            "randomize needs a SITL the env starts itself (or backend='native'): a running "
            "SITL takes its randomisation ranges from its --config file's [randomize] table"
        )
    for name, value in config.items():
        param_id = ids[name]
        sent = float(value)
        d = link.exchange(
            encoder.param_set(param_id, sent, vehicle),
            lambda d, p=param_id: any(
                m.get_type() == "PARAM_VALUE" and m.param_id == p for m in d.messages
            ),
            f"PARAM_VALUE for {param_id}",
        )
        texts = [m.text for m in d.messages if m.get_type() == "STATUSTEXT"]
        if any(m.get_type() == "PARAM_ERROR" for m in d.messages):
            raise parameter_error(spec, f"`{name}`: " + " ".join(texts))


class FlyloopEnv(gym.Env):
    """Base of the flyloop envs (see QuadHoverEnv, QuadWaypointsEnv, Lander2DEnv)."""

    metadata = {"render_modes": ["human", "rgb_array"], "render_fps": 50}
    SPEC: TaskSpec
    # Set before __init__ can fail, so close() (and VectorEnv.__del__) always work.
    _link: SitlLink | None = None
    _process: SitlProcess | None = None
    _native = None
    _view = None

    def __init__(
        self,
        *,
        arguments: Mapping[str, Any],
        model_params: Mapping[str, Any] | None,
        render_mode: str | None,
        sitl_path: Any,
        sitl_address: Any,
        vehicle: int,
        timeout: float,
        backend: str = "sitl",
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
        self._link: SitlLink | None = None
        self._process: SitlProcess | None = None
        self._view = None
        self.render_mode = render_mode
        self.config = resolve_config(spec, arguments, model_params)
        self.backend = check_backend(backend, sitl_path, sitl_address)
        self.core = spec.describe(self.config)
        self.dt = float(self.core["dt"])
        self.metadata = {**type(self).metadata, "render_fps": max(1, round(1.0 / self.dt))}
        self.observation_space, self.action_space = spaces_of(self.core)
        self._native = None
        if self.backend == "native":
            self._native = _native.Batch(spec.name, self.config, 1, 1)
        else:
            self._start_sitl(sitl_path, sitl_address, vehicle, timeout)
        self._episode_return = 0.0
        self._last: tuple[np.ndarray, dict[str, Any], float | None] | None = None
        if render_mode is not None:
            try:
                self._view = self._make_view(render_mode)
            except BaseException:
                self.close()
                raise

    def _start_sitl(self, sitl_path: Any, sitl_address: Any, vehicle: int, timeout: float) -> None:
        spec = self.SPEC
        self._n_obs = self.observation_space.shape[0]
        layout = self.core["info"]
        self._n_values = FRAME_HEADER_LEN + self._n_obs + sum(n for _, _, n in layout)
        self._n_arrays = frame_array_count(self._n_values)
        self._read_info = info_reader(layout, self._n_obs)
        self._encoder = Encoder()

        self.vehicle = 1 if sitl_address is None else int(vehicle)
        self._sink = FrameSink([self.vehicle], self._n_arrays)
        # A step's HIL_ACTUATOR_CONTROLS names it by the simulation time it ends at, in µs
        # (the SITL's clock advances by this per step), so a re-sent one is not stepped twice.
        self._dt_us = max(1, round(self.dt * 1e6))
        if sitl_address is None:
            self._process = start_sitl(
                spec, self.config, sitl_path=sitl_path, vehicles=1, timeout=timeout
            )
            self._link = SitlLink(self._process.address, timeout=timeout, process=self._process)
        else:
            if not 1 <= self.vehicle <= 254:
                raise ValueError(f"vehicle must be a system id in [1, 254], got {vehicle!r}")
            self._link = SitlLink(_parse_address(sitl_address), timeout=timeout)
            try:
                configure_attached(self._link, self._encoder, spec, self.config, self.vehicle)
            except (SitlError, SitlParameterError):
                self._link.close()
                raise

    # ---- SITL exchange ----

    def _frame_done(self, d: Datagram) -> bool:
        return self._sink.complete

    def _frame_values(self) -> np.ndarray:
        """The task frame just received (a view: copy what outlives the next exchange)."""
        values = self._sink.values()[0]
        if values[4] != self._n_obs or values[5] != self._n_values - FRAME_HEADER_LEN - self._n_obs:
            raise SitlError(
                f"the SITL's task frame holds {int(values[4])} observation and "
                f"{int(values[5])} info values, this env expects {self._n_obs} and "
                f"{self._n_values - FRAME_HEADER_LEN - self._n_obs}: is it flying task "
                f"{self.SPEC.name!r} (and the same flyloop version)?"
            )
        return values

    def _link_ok(self) -> SitlLink:
        if self._link is None:
            raise SitlError("this env is closed")
        return self._link

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
        if self.backend == "native":
            obs, info = self._native_ok().reset_one(seed)
        else:
            obs, info = self._sitl_reset(seed)
        self._episode_return = 0.0
        self._last = (obs, info, None)
        if self._view is not None:
            self._view.reset()
            if self.render_mode == "human":
                self.render()
        return obs, info

    def _sitl_reset(self, seed: int):
        link = self._link_ok()
        self._sink.expect((True,))
        d = link.exchange(
            self._encoder.reset(seed, self.vehicle),
            lambda d: (
                self._frame_done(d) and any(m.get_type() == "COMMAND_ACK" for m in d.messages)
            ),
            "reply to the reset command",
            self._sink,
        )
        ack = next(m for m in d.messages if m.get_type() == "COMMAND_ACK")
        if ack.command != RESET_COMMAND or ack.result != MAV_RESULT_ACCEPTED:
            texts = "; ".join(m.text for m in d.messages if m.get_type() == "STATUSTEXT")
            raise SitlError(f"the SITL refused the reset (result {ack.result}): {texts}")
        values = self._frame_values()
        obs = values[FRAME_HEADER_LEN : FRAME_HEADER_LEN + self._n_obs].copy()
        return obs, self._read_info(values)

    def step(self, action):
        a = as_actions(action, self.action_space.shape, "action")
        if self.backend == "native":
            # The core refuses NaN / ±inf with ValueError and changes nothing, like the SITL.
            obs, reward, terminated, truncated, info = self._native_ok().step_one(a)
        else:
            obs, reward, terminated, truncated, info = self._sitl_step(a, action)
        if self._view is not None:
            self._episode_return += reward
            self._last = (obs, info, reward)
            if self.render_mode == "human":
                self.render()
        return obs, reward, terminated, truncated, info

    def _sitl_step(self, a: np.ndarray, action: Any):
        values = a.tolist()
        # NaN and ±inf survive a sum of float32 values (whose sum cannot overflow a double).
        if not math.isfinite(sum(values)):
            raise ValueError(f"action must be finite, got {action!r}")
        link = self._link_ok()
        sink = self._sink
        sink.expect()
        link.exchange(
            self._encoder.controls(self.vehicle, values, max(sink.last_time[0], 0) + self._dt_us),
            self._frame_done,
            "task frame after a step",
            self._sink,
        )
        values = self._frame_values()
        obs = values[FRAME_HEADER_LEN : FRAME_HEADER_LEN + self._n_obs].copy()
        info = self._read_info(values)
        reward = float(values[0])
        terminated = bool(values[1] != 0.0)
        truncated = bool(values[2] != 0.0)
        return obs, reward, terminated, truncated, info

    def _native_ok(self):
        if self._native is None or self._native.closed:
            raise RuntimeError("this env is closed; make a new one to go on")
        return self._native

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
        native, self._native = self._native, None
        if native is not None:
            native.close()
        link, self._link = self._link, None
        if link is not None:
            link.close()
        process, self._process = self._process, None
        if process is not None:
            process.stop()

    @property
    def sitl_process(self) -> SitlProcess | None:
        """The SITL process this env started (None when attached to an address)."""
        return self._process


def _parse_address(address: Any) -> tuple[str, int]:
    if isinstance(address, str):
        host, sep, port = address.rpartition(":")
        if not sep or not port.isdigit():
            raise ValueError(f"sitl_address must be 'host:port' or (host, port), got {address!r}")
        return host.strip("[]"), int(port)
    try:
        host, port = address
        return str(host), int(port)
    except (TypeError, ValueError):
        raise ValueError(
            f"sitl_address must be 'host:port' or (host, port), got {address!r}"
        ) from None
