"""backend="sitl" for the multi-agent envs: one world in a flyloop-sitl process this object
starts (`--task multi_hover|swap --vehicles N`, docs/protocol.md section 14), driven through
the interface of the extension's `MultiBatch` (one world), so `flyloop.multi_agent`'s env
classes run on it unchanged.

Every step is one datagram exchange: N HIL_ACTUATOR_CONTROLS in (vehicle k = agent k − 1,
addressed by the frame's system id), N task frames out. Parameters are checked by the core in
this process first (the same errors as backend="native"), then written to the SITL's
--config file. Each frame carries its agent's reward as the f64's bits, so rewards, like the
observations and the (float32) infos, are the native env's bit for bit.
"""

from __future__ import annotations

import math
import os
import tempfile
from collections.abc import Mapping
from typing import Any

import numpy as np

from . import _native
from .errors import SitlError
from .link import SitlLink
from .protocol import (
    FRAME_HEADER_LEN,
    MAV_RESULT_ACCEPTED,
    Datagram,
    Encoder,
    FrameSink,
)
from .sitl_backend import frame_array_count
from .sitl_process import SitlProcess, find_sitl_binary
from .tasks import to_toml

# MAVLink system ids 1..254: one per agent.
MAX_AGENTS = 254
# After an agent's info: active, then the reward's f64 bits in four 16-bit pieces, low first.
EXTRA_VALUES = 5
_PIECE_SHIFTS = np.array([0, 16, 32, 48], np.uint64)


def _rewards_from_pieces(pieces: np.ndarray) -> np.ndarray:
    """(N, 4) float32 16-bit pieces -> (N,) float64 with exactly those bits."""
    bits = np.bitwise_or.reduce(pieces.astype(np.uint64) << _PIECE_SHIFTS, axis=1)
    return bits.view(np.float64)


def _start(
    task: str, config: Mapping[str, Any], agents: int, sitl_path, timeout, gcs: str
) -> SitlProcess:
    fd, path = tempfile.mkstemp(prefix="flyloop-world-", suffix=".toml")
    try:
        with os.fdopen(fd, "w") as f:
            f.write(to_toml(config))
        args = [
            "--task", task, "--gcs", gcs, "--mode", "lockstep", "--vehicles", str(agents),
            "--no-state-reply", "--log-level", "warn", "--config", path,
        ]  # fmt: skip
        return SitlProcess(find_sitl_binary(sitl_path), args, start_timeout=timeout)
    finally:
        os.unlink(path)


class SitlMultiBatch:
    """One world of the multi-agent task `task` ("multi_hover", "swap") with `config` (the
    extension's parameter dict) in a SITL of its own; the methods are `MultiBatch`'s. `gcs`:
    the SITL's ground-station target (`--gcs`; "off" by default), where each agent streams
    its telemetry as MAVLink system i + 1."""

    num_worlds = 1
    num_threads = 1
    _link: SitlLink | None = None
    _process: SitlProcess | None = None

    def __init__(
        self,
        task: str,
        config: Mapping[str, Any],
        *,
        sitl_path: Any = None,
        timeout: float = 5.0,
        gcs: str = "off",
    ) -> None:
        agents = config.get("num_agents", 4)
        if not 1 <= agents <= MAX_AGENTS:
            raise ValueError(
                f"num_agents must be in [1, {MAX_AGENTS}] with backend='sitl' (one MAVLink "
                f"system id per agent), got {agents}"
            )
        # The core in this process checks every parameter (the native backend's errors) and
        # gives the spaces; the SITL flies the same config.
        core = _native.MultiBatch(task, dict(config), 1, 1)
        self._describe = core.describe()
        self.num_agents = core.num_agents
        self.observation_size = core.observation_size
        self.action_size = core.action_size
        self.info_size = core.info_size
        self._n_values = FRAME_HEADER_LEN + self.observation_size + self.info_size + EXTRA_VALUES
        layout = self._describe["info_layout"]
        offsets, at = {}, 0
        for name, size, _ in layout:
            offsets[name] = (at, at + size)
            at += size
        self._position = offsets["position"]
        self._target = offsets["target_position"]
        self._ids = list(range(1, self.num_agents + 1))
        self._sink = FrameSink(self._ids, frame_array_count(self._n_values))
        self._encoder = Encoder()
        self._dt_us = max(1, round(float(self._describe["dt"]) * 1e6))
        self._info = np.zeros((self.num_agents, self.info_size), np.float32)
        self._process = _start(task, config, self.num_agents, sitl_path, timeout, gcs)
        self._link = SitlLink(self._process.address, timeout=timeout, process=self._process)

    @property
    def sitl_process(self) -> SitlProcess | None:
        return self._process

    def describe(self) -> dict[str, Any]:
        return self._describe

    def _link_ok(self) -> SitlLink:
        if self._link is None:
            raise SitlError("this env is closed; make a new one to go on")
        return self._link

    def positions(self, w: int):
        """Agent positions and targets (ENU, m) as the last frames' info carries them
        (float32): two flat (N·3,) arrays."""
        if w != 0:
            raise ValueError(f"world {w} out of range: 1 world")
        (p0, p1), (t0, t1) = self._position, self._target
        return self._info[:, p0:p1].astype(np.float64).ravel(), self._info[:, t0:t1].astype(
            np.float64
        ).ravel()

    def _exchange(self, data: bytes, resetting: bool, what: str) -> Datagram:
        sink = self._sink
        sink.expect([resetting] * self.num_agents if resetting else None)

        def done(d: Datagram) -> bool:
            # A refusal (STATUSTEXT) ends the wait as well: it is raised below, not waited out.
            if any(m.get_type() == "STATUSTEXT" for m in d.messages):
                return True
            return sink.complete and (
                not resetting or any(m.get_type() == "COMMAND_ACK" for m in d.messages)
            )

        d = self._link_ok().exchange(data, done, what, sink)
        texts = "; ".join(m.text for m in d.messages if m.get_type() == "STATUSTEXT")
        acks = [m for m in d.messages if m.get_type() == "COMMAND_ACK"]
        if any(m.result != MAV_RESULT_ACCEPTED for m in acks) or not sink.complete:
            raise SitlError(f"the SITL refused the {'reset' if resetting else 'step'}: {texts}")
        return d

    def step(self, actions, reset, seeds, obs, info, rewards, terminated, truncated, active):
        """`MultiBatch.step` for the one world: a reset with `seeds[0]` if `reset[0]`, else
        one step with `actions` (N, 4)."""
        n = self.num_agents
        if actions.shape != (n, self.action_size):
            want = (n, self.action_size)
            raise ValueError(f"actions must have shape {want}, got {actions.shape}")
        if bool(reset[0]):
            data = self._encoder.reset(int(seeds[0]), 0)
            self._exchange(data, True, "reply to the world's reset")
        else:
            rows = actions.tolist()
            for r, row in enumerate(rows):
                if not math.isfinite(sum(row)):
                    j = next(j for j, a in enumerate(row) if not math.isfinite(a))
                    # Written as the extension writes it (Rust's NaN, inf, -inf).
                    shown = "NaN" if math.isnan(row[j]) else f"{row[j]:g}"
                    raise ValueError(
                        f"actions[{r}, {j}] = {shown} (world 0, agent {r}): actions must be "
                        "finite; step refused"
                    )
            steps = self._sink.step_ids(self._dt_us)
            data = self._encoder.controls_batch(self._ids, rows, steps)
            self._exchange(data, False, "task frames of every vehicle")
        values = self._sink.values()[:, : self._n_values]
        n_obs, n_info = self.observation_size, self.info_size
        if values[0, 4] != n_obs or values[0, 5] != n_info:
            raise SitlError(
                f"the SITL's task frame holds {int(values[0, 4])} observation and "
                f"{int(values[0, 5])} info values, this env expects {n_obs} and {n_info}: is it "
                "the same flyloop version?"
            )
        h = FRAME_HEADER_LEN
        obs[:] = values[:, h : h + n_obs]
        info[:] = values[:, h + n_obs : h + n_obs + n_info]
        self._info[:] = info
        extra = values[:, h + n_obs + n_info :]
        np.not_equal(extra[:, 0], 0.0, out=active)
        rewards[:] = _rewards_from_pieces(extra[:, 1:5])
        np.not_equal(values[:, 1], 0.0, out=terminated)
        np.not_equal(values[:, 2], 0.0, out=truncated)

    def close(self) -> None:
        link, self._link = self._link, None
        if link is not None:
            link.close()
        process, self._process = self._process, None
        if process is not None:
            process.stop()
