"""The MAVLink 2 messages the envs exchange with flyloop-sitl (docs/protocol.md).

Message ids, CRC extras and field layouts come from pymavlink's common dialect. The two
messages of every step take a short path: HIL_ACTUATOR_CONTROLS is packed with one struct
call per vehicle and DEBUG_FLOAT_ARRAY (the task frame) is read straight into numpy, both
checked with the same CRC function pymavlink uses; a test pins the bytes to pymavlink's own
`pack()`. Everything else (COMMAND_ACK, STATUSTEXT, PARAM_VALUE, ...) is decoded by
pymavlink.
"""

from __future__ import annotations

import os
import struct
from dataclasses import dataclass, field

import numpy as np

from . import _native

os.environ.setdefault("MAVLINK20", "1")  # before pymavlink is imported: MAVLink 2 framing

from pymavlink.dialects.v20 import common as mavlink2  # noqa: E402
from pymavlink.generator.mavcrc import x25crc  # noqa: E402

try:  # the C implementation pymavlink itself uses when it is installed
    from fastcrc.crc16 import mcrf4xx as _mcrf4xx
except ImportError:  # pragma: no cover - fastcrc ships with pymavlink's dependencies here
    _mcrf4xx = None

STX_V2 = 0xFD
HEADER_LEN = 10
CHECKSUM_LEN = 2
SIGNATURE_LEN = 13

CONTROLS = mavlink2.MAVLink_hil_actuator_controls_message
FRAME = mavlink2.MAVLink_debug_float_array_message
CONTROLS_ID, CONTROLS_CRC_EXTRA = CONTROLS.id, CONTROLS.crc_extra
FRAME_ID, FRAME_CRC_EXTRA = FRAME.id, FRAME.crc_extra
LOCKSTEP_FLAG = mavlink2.HIL_ACTUATOR_CONTROLS_FLAGS_LOCKSTEP
RESET_COMMAND = mavlink2.MAV_CMD_USER_1
MAV_RESULT_ACCEPTED = mavlink2.MAV_RESULT_ACCEPTED

# Task frame layout (docs/protocol.md), the SITL's own: header values, then observation,
# then info, over arrays of FRAME_ARRAY_LEN values.
FRAME_ARRAY_LEN = _native.FRAME_ARRAY_LEN
FRAME_HEADER_LEN = _native.FRAME_HEADER_LEN
_FRAME_PAYLOAD = struct.calcsize(FRAME.unpacker.format)  # 252 bytes, data at offset 20
_FRAME_DATA_OFFSET = struct.calcsize("<QH10s")
_CONTROLS = struct.Struct(CONTROLS.unpacker.format)  # <QQ16fB: time, flags, controls, mode

_ZEROS = (0.0,) * 16

# What this client sends from: a ground-control-station id, as MAVLink tools do.
CLIENT_SYSTEM_ID = 255
CLIENT_COMPONENT_ID = 190


def _crc_body(body: bytes, extra: bytes) -> int:
    if _mcrf4xx is not None:
        return _mcrf4xx(extra, _mcrf4xx(body, 0xFFFF))
    c = x25crc(body)
    c.accumulate(extra)
    return c.crc


def crc16(data: bytes, crc_extra: int) -> int:
    """MAVLink's CRC-16/MCRF4XX over `data` then the message's CRC extra byte."""
    if _mcrf4xx is not None:
        return _mcrf4xx(bytes((crc_extra,)), _mcrf4xx(data, 0xFFFF))
    c = x25crc(data)
    c.accumulate(bytes((crc_extra,)))
    return c.crc


def seed_params(seed: int) -> list[float]:
    """The reset command's param1..4: the 64-bit seed in 16-bit pieces, low to high."""
    return [float((seed >> shift) & 0xFFFF) for shift in (0, 16, 32, 48)]


class Encoder:
    """Packs MAVLink 2 frames with one running sequence number."""

    def __init__(self) -> None:
        self.sequence = 0
        self._mav = mavlink2.MAVLink(
            None, srcSystem=CLIENT_SYSTEM_ID, srcComponent=CLIENT_COMPONENT_ID
        )

    def controls(self, system_id: int, controls, step: int = 0) -> bytes:
        """HIL_ACTUATOR_CONTROLS with the LOCKSTEP flag from vehicle `system_id` (the SITL
        steps the vehicle whose id is the frame's *sender*, as PX4 sends it). `controls`: up
        to 16 float32 values (an array or a list of them); `step`: its time_usec (see
        `controls_batch`)."""
        if isinstance(controls, np.ndarray):
            controls = controls.tolist()
        return self.controls_batch((system_id,), (controls,), (step,))

    def controls_batch(self, system_ids, rows, steps=None) -> bytes:
        """One HIL_ACTUATOR_CONTROLS frame per (system id, controls row), back to back.
        `steps`: each command's time_usec, the step it names (docs/protocol.md section 3:
        the simulation time the step ends at, so a re-sent command is recognised and not
        stepped twice); None sends 0 (unnamed steps, no loss recovery).
        The hot path of every step, hence the local names."""
        pack, zeros, flag = _CONTROLS.pack, _ZEROS, LOCKSTEP_FLAG
        head = (CLIENT_COMPONENT_ID, CONTROLS_ID & 0xFF, CONTROLS_ID >> 8 & 0xFF, CONTROLS_ID >> 16)
        extra = bytes((CONTROLS_CRC_EXTRA,))
        seq = self.sequence
        out = []
        if steps is None:
            steps = (0,) * len(system_ids)
        for system_id, row, step in zip(system_ids, rows, steps, strict=True):
            payload = pack(step, flag, *row, *zeros[len(row) :], 0)
            # MAVLink 2 drops trailing zero bytes of the payload (at least one byte stays).
            payload = payload.rstrip(b"\x00") or b"\x00"
            body = bytes((len(payload), 0, 0, seq, system_id, *head)) + payload
            crc = _crc_body(body, extra)
            out.append(b"\xfd" + body + crc.to_bytes(2, "little"))
            seq = (seq + 1) & 0xFF
        self.sequence = seq
        return b"".join(out)

    def message(self, msg) -> bytes:
        """Any pymavlink message, packed by pymavlink from the client's system id."""
        self._mav.seq = self.sequence
        data = msg.pack(self._mav)
        self.sequence = (self.sequence + 1) & 0xFF
        return bytes(data)

    def reset(self, seed: int, target_system: int) -> bytes:
        """COMMAND_LONG MAV_CMD_USER_1: reset vehicle `target_system` (0 = all) with `seed`."""
        params = [*seed_params(seed), 0.0, 0.0, 0.0]
        msg = mavlink2.MAVLink_command_long_message(target_system, 1, RESET_COMMAND, 0, *params)
        return self.message(msg)

    def param_set(self, param_id: str, value: float, target_system: int) -> bytes:
        msg = mavlink2.MAVLink_param_set_message(
            target_system, 1, param_id.encode(), float(value), mavlink2.MAV_PARAM_TYPE_REAL32
        )
        return self.message(msg)

    def request_message(self, message_id: int, target: int) -> bytes:
        """MAV_CMD_REQUEST_MESSAGE: the SITL answers with that message of vehicle `target`."""
        cmd = mavlink2.MAV_CMD_REQUEST_MESSAGE
        msg = mavlink2.MAVLink_command_long_message(
            target, 1, cmd, 0, float(message_id), 0, 0, 0, 0, 0, 0
        )
        return self.message(msg)

    def set_message_interval(self, message_id: int, interval_us: float, target: int) -> bytes:
        cmd = mavlink2.MAV_CMD_SET_MESSAGE_INTERVAL
        msg = mavlink2.MAVLink_command_long_message(
            target, 1, cmd, 0, float(message_id), float(interval_us), 0, 0, 0, 0, 0
        )
        return self.message(msg)


class ProtocolError(ValueError):
    """Bytes from the SITL that are not the MAVLink 2 this client expects."""


@dataclass
class Datagram:
    """What one datagram from the SITL holds: task-frame arrays by (system id, array id),
    and every other message decoded by pymavlink."""

    arrays: dict[tuple[int, int], np.ndarray] = field(default_factory=dict)
    times: dict[int, int] = field(default_factory=dict)
    names: dict[int, str] = field(default_factory=dict)
    messages: list = field(default_factory=list)


_FLOATS_PER_PAYLOAD = _FRAME_PAYLOAD // 4  # 63: 5 floats' worth of header, then 58 values
_HEADER_FLOATS = _FRAME_DATA_OFFSET // 4


class FrameSink:
    """Where the step path puts task frames: one row per vehicle, the payloads of its
    arrays side by side in one buffer, read as float32 in one numpy view. Frames of other
    vehicles, or array ids beyond `n_arrays`, are ignored."""

    def __init__(self, system_ids, n_arrays: int) -> None:
        self.rows = {sid: i for i, sid in enumerate(system_ids)}
        self.n_rows = len(self.rows)
        self.n_arrays = n_arrays
        self.raw = bytearray(self.n_rows * n_arrays * _FRAME_PAYLOAD)
        self.have = bytearray(self.n_rows * n_arrays)
        self.count = 0
        self._no_slots = bytes(len(self.have))
        floats = np.frombuffer(self.raw, "<f4").reshape(self.n_rows, n_arrays, _FLOATS_PER_PAYLOAD)
        self._data = floats[:, :, _HEADER_FLOATS:]
        # Which frames belong to the exchange under way (a late duplicate of an earlier
        # reply must not be taken for it): per row, the simulation time (µs) of the last
        # frame taken, -1 before the first; a step's frame is later than that, a reset's
        # frame is at that time or later and has episode step 0. See `expect`.
        self.last_time = [-1] * self.n_rows
        self.resetting = bytearray(self.n_rows)
        self.stale = 0
        # time_usec of each row's first array (payload bytes 0-7), read in place.
        self._times = np.ndarray((self.n_rows,), "<u8", self.raw, 0, (n_arrays * _FRAME_PAYLOAD,))

    def clear(self) -> None:
        self.have[:] = self._no_slots
        self.count = 0

    def expect(self, resetting=None) -> None:
        """Before an exchange: rows in `resetting` (a bool per row, or None for none)
        expect a reset's frame, the others a step's."""
        if resetting is None:
            self.resetting[:] = bytes(self.n_rows)
        else:
            self.resetting[:] = bytes(bool(r) for r in resetting)

    def accepts(self, row: int, time_usec: int, first_array: bool, step_zero: bool) -> bool:
        last = self.last_time[row]
        if self.resetting[row]:
            return time_usec >= last and (step_zero or not first_array)
        return time_usec > last

    def commit(self) -> None:
        """After a complete exchange: the frames' times become the rows' last times."""
        self.last_time = self._times.tolist()

    def step_ids(self, dt_us: int) -> list[int]:
        """The time_usec that names each row's next step: its last frame's time + dt_us."""
        return [max(t, 0) + dt_us for t in self.last_time]

    @property
    def complete(self) -> bool:
        return self.count == len(self.have)

    def values(self) -> np.ndarray:
        """(vehicles, n_arrays · 58) float32; a view of the buffer the next datagram reuses
        (a copy when a frame spans several arrays)."""
        return self._data.reshape(self.n_rows, self.n_arrays * FRAME_ARRAY_LEN)


def _frame_bounds(data: bytes, at: int, end: int) -> tuple[int, int, int]:
    """The MAVLink 2 frame starting at byte `at`: its payload length, where its payload
    stops and where the frame (checksum and signature included) ends."""
    if data[at] != STX_V2:
        raise ProtocolError(f"byte {at} of a datagram is {data[at]:#x}, not MAVLink 2")
    if at + HEADER_LEN + CHECKSUM_LEN > end:
        raise ProtocolError("a datagram ends inside a MAVLink header")
    plen = data[at + 1]
    signed = data[at + 2] & 0x01
    stop = at + HEADER_LEN + plen
    total = stop + CHECKSUM_LEN + (SIGNATURE_LEN if signed else 0)
    if total > end:
        raise ProtocolError("a datagram ends inside a MAVLink frame")
    return plen, stop, total


class Decoder:
    """Splits datagrams into MAVLink 2 frames and decodes them."""

    def __init__(self) -> None:
        self._mav = mavlink2.MAVLink(None)
        self._zeros = bytes(_FRAME_PAYLOAD)

    def decode(self, data: bytes, out: Datagram, sink: FrameSink | None = None) -> Datagram:
        """Task frames go to `sink` when given (the step path), else to `out.arrays`; every
        other message to `out.messages`."""
        at, end = 0, len(data)
        view = memoryview(data)
        while at < end:
            plen, stop, total = _frame_bounds(data, at, end)
            msg_id = data[at + 7] | (data[at + 8] << 8) | (data[at + 9] << 16)
            if msg_id == FRAME_ID:
                crc = data[stop] | (data[stop + 1] << 8)
                if crc16(view[at + 1 : stop], FRAME_CRC_EXTRA) != crc:
                    raise ProtocolError("a task frame fails its CRC")
                if sink is not None:
                    self._to_sink(sink, data, view, at, plen)
                else:
                    self._to_arrays(out, data, at, plen)
            else:
                try:
                    out.messages.append(self._mav.decode(bytearray(data[at:total])))
                except Exception as exc:  # pymavlink raises its own MAVError / struct.error
                    raise ProtocolError(f"message {msg_id} does not decode: {exc}") from exc
            at = total
        return out

    def _to_sink(self, sink: FrameSink, data: bytes, view: memoryview, at: int, plen: int) -> None:
        """The step path: the task frame at `at` into its vehicle's row of `sink`, unless it
        is another vehicle's, beyond the sink's arrays, or stale (see FrameSink.accepts).
        `view` is the datagram's memoryview, made once per datagram by `decode`."""
        row = sink.rows.get(data[at + 5])
        # array_id (payload bytes 8-9) is never 0, so MAVLink 2 never truncates it.
        k = (data[at + 18] | (data[at + 19] << 8)) - 1 if plen >= 10 else -1
        if row is None or not 0 <= k < sink.n_arrays:
            return
        start = at + HEADER_LEN
        t = int.from_bytes(data[start : start + 8], "little")
        # The episode step, value 3 (payload bytes 32-35; absent when truncated).
        zero = plen < 36 or not any(data[start + 32 : start + 36])
        if not sink.accepts(row, t, k == 0, zero):
            sink.stale += 1
            return
        slot = row * sink.n_arrays + k
        off = slot * _FRAME_PAYLOAD
        sink.raw[off : off + plen] = view[start : start + plen]
        if plen < _FRAME_PAYLOAD:
            # MAVLink 2 cut the payload's trailing zeros.
            sink.raw[off + plen : off + _FRAME_PAYLOAD] = self._zeros[plen:]
        if not sink.have[slot]:
            sink.have[slot] = 1
            sink.count += 1

    def _to_arrays(self, out: Datagram, data: bytes, at: int, plen: int) -> None:
        """The task frame at `at` into `out.arrays` (and, for a frame's first array, the
        vehicle's time and task name into `out.times` and `out.names`)."""
        payload = data[at + HEADER_LEN : at + HEADER_LEN + plen]
        if plen < _FRAME_PAYLOAD:
            payload = payload + self._zeros[plen:]
        system_id = data[at + 5]
        array_id = payload[8] | (payload[9] << 8)
        values = np.frombuffer(payload, "<f4", FRAME_ARRAY_LEN, _FRAME_DATA_OFFSET)
        out.arrays[(system_id, array_id)] = values
        if array_id == 1:
            out.times[system_id] = int.from_bytes(payload[:8], "little")
            out.names[system_id] = payload[10:20].split(b"\0", 1)[0].decode(errors="replace")
