"""The SITL backend (see flyloop.backends): the task runs in a flyloop-sitl process this
backend starts (one vehicle per instance) or in a running one it attaches to (one vehicle);
every reset or step is one datagram exchange, lockstep."""

from __future__ import annotations

import math
import os
import tempfile
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from .errors import SitlError, SitlParameterError
from .faults import FAULTS_KEY
from .link import SitlLink
from .protocol import (
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
from .sitl_process import SitlProcess, find_sitl_binary
from .tasks import (
    FLAG,
    FRAME_KEY,
    INTEGER,
    RANGE_PREFIX,
    REAL,
    TaskSpec,
    parameter_error,
    to_toml,
)

_HIL_STATE_QUATERNION = mavlink2.MAVLINK_MSG_ID_HIL_STATE_QUATERNION
MAX_VEHICLES = 254  # MAVLink system ids 1..254


def frame_array_count(n_values: int) -> int:
    return max(1, math.ceil(n_values / FRAME_ARRAY_LEN))


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
    if FAULTS_KEY in config:
        raise ValueError(
            "faults need a SITL the env starts itself (or backend='native'): a running SITL "
            "takes its faults from its --config file's [[faults]] tables"
        )
    for name, value in config.items():
        if name == FRAME_KEY:
            # A running SITL flies the frame of its own --config ([frame]); a motor interface
            # sized for another frame is caught by the size check of its first frame.
            continue
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


class SitlBackend:
    """`num_envs` vehicles of a SITL this backend starts, or vehicle `vehicle` of the SITL at
    `sitl_address` (num_envs 1)."""

    name = "sitl"
    num_threads = 1
    _link: SitlLink | None = None
    _process: SitlProcess | None = None

    def __init__(
        self,
        spec: TaskSpec,
        config: Mapping[str, Any],
        core: Mapping[str, Any],
        num_envs: int,
        *,
        sitl_path: Any,
        sitl_address: Any,
        vehicle: int,
        timeout: float,
    ) -> None:
        if not 1 <= num_envs <= MAX_VEHICLES:
            raise ValueError(f"num_envs must be in [1, {MAX_VEHICLES}], got {num_envs}")
        self.spec = spec
        self._n_obs = len(core["observation_low"])
        layout = core["info"]
        self._n_info = sum(n for _, _, n in layout)
        self._n_values = FRAME_HEADER_LEN + self._n_obs + self._n_info
        self._read_info = info_reader(layout, self._n_obs)
        self._encoder = Encoder()
        # A step's HIL_ACTUATOR_CONTROLS names it by the simulation time it ends at, in µs
        # (the SITL's clock advances by this per step), so a re-sent one is not stepped twice.
        self._dt_us = max(1, round(float(core["dt"]) * 1e6))
        if sitl_address is None:
            self._ids = list(range(1, num_envs + 1))
        else:
            if not 1 <= int(vehicle) <= MAX_VEHICLES:
                raise ValueError(f"vehicle must be a system id in [1, 254], got {vehicle!r}")
            self._ids = [int(vehicle)]
        self.vehicle = self._ids[0]
        self._sink = FrameSink(self._ids, frame_array_count(self._n_values))
        if sitl_address is None:
            self._process = start_sitl(
                spec, config, sitl_path=sitl_path, vehicles=num_envs, timeout=timeout
            )
            self._link = SitlLink(self._process.address, timeout=timeout, process=self._process)
        else:
            self._link = SitlLink(_parse_address(sitl_address), timeout=timeout)
            try:
                configure_attached(self._link, self._encoder, spec, config, self.vehicle)
            except (SitlError, SitlParameterError):
                self._link.close()
                raise

    @property
    def sitl_process(self) -> SitlProcess | None:
        return self._process

    def _link_ok(self) -> SitlLink:
        if self._link is None:
            raise SitlError("this env is closed")
        return self._link

    def _frame_done(self, d: Datagram) -> bool:
        return self._sink.complete

    def _check_sizes(self, n_obs: float, n_info: float) -> None:
        if n_obs != self._n_obs or n_info != self._n_info:
            raise SitlError(
                f"the SITL's task frame holds {int(n_obs)} observation and {int(n_info)} info "
                f"values, this env expects {self._n_obs} and {self._n_info}: is it flying "
                f"task {self.spec.name!r} (and the same flyloop version)?"
            )

    # ---- one vehicle (the single env) ----

    def _frame_values(self) -> np.ndarray:
        """The task frame just received (a view: copy what outlives the next exchange)."""
        values = self._sink.values()[0]
        self._check_sizes(values[4], values[5])
        return values

    def reset_one(self, seed: int):
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

    def step_one(self, action: np.ndarray):
        values = action.tolist()
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
            sink,
        )
        values = self._frame_values()
        obs = values[FRAME_HEADER_LEN : FRAME_HEADER_LEN + self._n_obs].copy()
        info = self._read_info(values)
        reward = float(values[0])
        terminated = bool(values[1] != 0.0)
        truncated = bool(values[2] != 0.0)
        return obs, reward, terminated, truncated, info

    # ---- every vehicle (the vector env) ----

    def run(self, actions: np.ndarray, resetting: np.ndarray, seeds: np.ndarray, out) -> None:
        """One datagram: a reset command for each row in `resetting`, controls for the
        others; the replies' frames are written into `out` (an Outputs)."""
        enc, sink = self._encoder, self._sink
        n_resets = int(resetting.sum())
        if n_resets:
            sink.expect(resetting)
            steps = sink.step_ids(self._dt_us)
            rows = actions.tolist()
            parts = []
            for i, v in enumerate(self._ids):
                if resetting[i]:
                    parts.append(enc.reset(int(seeds[i]), v))
                else:
                    parts.append(enc.controls_batch((v,), (rows[i],), (steps[i],)))
            data = b"".join(parts)
        else:
            sink.expect()
            data = enc.controls_batch(self._ids, actions.tolist(), sink.step_ids(self._dt_us))

        def done(d: Datagram) -> bool:
            if not sink.complete:
                return False
            return (
                not n_resets or sum(m.get_type() == "COMMAND_ACK" for m in d.messages) >= n_resets
            )

        d = self._link_ok().exchange(data, done, "task frames of every vehicle", sink)
        values = sink.values()[:, : self._n_values]
        acks = [m for m in d.messages if m.get_type() == "COMMAND_ACK"]
        if any(m.result != MAV_RESULT_ACCEPTED for m in acks):
            texts = "; ".join(m.text for m in d.messages if m.get_type() == "STATUSTEXT")
            raise SitlError(f"the SITL refused a reset: {texts}")
        self._check_sizes(values[0, 4], values[0, 5])
        h, n_obs = FRAME_HEADER_LEN, self._n_obs
        out.obs[:] = values[:, h : h + n_obs]
        out.info[:] = values[:, h + n_obs :]
        out.rewards[:] = values[:, 0]
        np.not_equal(values[:, 1], 0.0, out=out.terminated)
        np.not_equal(values[:, 2], 0.0, out=out.truncated)
        out.rewards[resetting] = 0.0
        out.terminated[resetting] = False
        out.truncated[resetting] = False

    def close(self) -> None:
        link, self._link = self._link, None
        if link is not None:
            link.close()
        process, self._process = self._process, None
        if process is not None:
            process.stop()
