"""A running flyloop-sitl and a pymavlink client for it, as the system tests use them.

The client speaks MAVLink 2 (pymavlink's common dialect) over a plain UDP socket, so one
datagram can carry commands for many vehicles and each reply datagram is decoded whole.
"""

from __future__ import annotations

import math
import os
import signal
import socket
import subprocess
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path

os.environ["MAVLINK20"] = "1"  # pymavlink's mavutil would speak MAVLink 1 otherwise

from pymavlink.dialects.v20 import common as mavlink2  # noqa: E402

RESET_COMMAND = mavlink2.MAV_CMD_USER_1
LOCKSTEP = mavlink2.HIL_ACTUATOR_CONTROLS_FLAGS_LOCKSTEP
EARTH_RADIUS = 6_378_137.0
HOME = (47.397742, 8.545594, 488.0)

# Info layout of the Hover task frame (docs/protocol.md): name -> number of values.
HOVER_INFO = [
    ("distance_to_target", 1),
    ("position", 3),
    ("target_position", 3),
    ("step_count", 1),
    ("episode_time", 1),
    ("distance_progress", 1),
    ("crashed", 1),
    ("out_of_bounds", 1),
]


def seed_params(seed: int) -> list[float]:
    """The reset command's param1..4: the 64-bit seed in 16-bit pieces, low to high."""
    return [float((seed >> shift) & 0xFFFF) for shift in (0, 16, 32, 48)]


class Sitl:
    """A flyloop-sitl process on ephemeral ports; stderr goes to a file (never a full pipe)."""

    def __init__(self, binary: Path, *args: str, listen: str = "127.0.0.1:0"):
        self.log = tempfile.NamedTemporaryFile("w+", prefix="sitl-", suffix=".log", delete=False)
        self.proc = subprocess.Popen(
            [str(binary), "--listen", listen, *args],
            stdout=subprocess.PIPE,
            stderr=self.log,
            text=True,
        )
        line = self.proc.stdout.readline()
        if not line.startswith("flyloop-sitl ready "):
            self.proc.wait(timeout=5)
            raise RuntimeError(f"SITL did not start: {line!r} {self.stderr()}")
        self.ready = dict(kv.split("=", 1) for kv in line.split()[2:])
        host, port = self.ready["listen"].rsplit(":", 1)
        self.address = (host, int(port))
        gcs = self.ready["gcs"]
        self.gcs_local = None
        if gcs != "off":
            local = gcs.split("->")[0]
            self.gcs_local = ("127.0.0.1", int(local.rsplit(":", 1)[1]))

    def stderr(self) -> str:
        self.log.flush()
        return Path(self.log.name).read_text()

    def stop(self, sig: int = signal.SIGTERM) -> int:
        if self.proc.poll() is None:
            self.proc.send_signal(sig)
            try:
                self.proc.wait(timeout=5)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait()
        return self.proc.returncode

    def stats(self) -> dict[str, float]:
        """The counters the SITL logs when it stops (stop it first)."""
        for line in self.stderr().splitlines():
            if "stopped: " in line:
                text = line.split("stopped: ", 1)[1]
                return {k: float(v) for k, v in (kv.split("=") for kv in text.split())}
        raise AssertionError(f"no stats line in {self.stderr()}")


@dataclass
class Frame:
    """A decoded task frame (DEBUG_FLOAT_ARRAY values, docs/protocol.md)."""

    reward: float
    terminated: bool
    truncated: bool
    step: int
    obs: list[float]
    info: list[float]
    time_usec: int
    values: list[float] = field(repr=False)


def decode_frame(msgs: list, system_id: int) -> Frame:
    arrays = sorted(
        (m for m in msgs if m.get_type() == "DEBUG_FLOAT_ARRAY" and m.get_srcSystem() == system_id),
        key=lambda m: m.array_id,
    )
    assert arrays, f"no task frame from vehicle {system_id} in {msgs}"
    values = [v for m in arrays for v in m.data]
    n_obs, n_info = int(values[4]), int(values[5])
    return Frame(
        reward=values[0],
        terminated=values[1] == 1.0,
        truncated=values[2] == 1.0,
        step=int(values[3]),
        obs=values[6 : 6 + n_obs],
        info=values[6 + n_obs : 6 + n_obs + n_info],
        time_usec=arrays[0].time_usec,
        values=values,
    )


def hover_info(frame: Frame) -> dict[str, list[float]]:
    out, at = {}, 0
    for name, n in HOVER_INFO:
        out[name] = frame.info[at : at + n]
        at += n
    assert at == len(frame.info)
    return out


def local_ned(state) -> tuple[float, float, float]:
    """HIL_STATE_QUATERNION lat/lon/alt back to metres north, east, down of home."""
    lat0, lon0, alt0 = HOME
    north = math.radians(state.lat / 1e7 - lat0) * EARTH_RADIUS
    east = math.radians(state.lon / 1e7 - lon0) * EARTH_RADIUS * math.cos(math.radians(lat0))
    down = -(state.alt / 1000.0 - alt0)
    return north, east, down


class Client:
    """A controller peer: one UDP socket, MAVLink 2 frames packed by pymavlink."""

    def __init__(self, address: tuple[str, int], timeout: float = 5.0):
        self.address = address
        self.sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self.sock.bind(("127.0.0.1", 0))
        self.sock.settimeout(timeout)
        self.mav = mavlink2.MAVLink(None, srcSystem=255, srcComponent=190)

    def close(self) -> None:
        self.sock.close()

    def pack(self, msg, system_id: int = 255) -> bytes:
        self.mav.srcSystem = system_id
        return msg.pack(self.mav)

    def send_raw(self, data: bytes) -> None:
        self.sock.sendto(data, self.address)

    def receive(self) -> tuple[bytes, list]:
        data, _ = self.sock.recvfrom(65536)
        parser = mavlink2.MAVLink(None)
        return data, parser.parse_buffer(data) or []

    def exchange(self, data: bytes) -> list:
        self.send_raw(data)
        return self.receive()[1]

    def controls(self, controls, system_id: int = 1, time_usec: int = 0) -> bytes:
        padded = list(controls) + [0.0] * (16 - len(controls))
        msg = self.mav.hil_actuator_controls_encode(time_usec, padded, 0, LOCKSTEP)
        return self.pack(msg, system_id)

    def step(self, controls, system_id: int = 1) -> list:
        return self.exchange(self.controls(controls, system_id))

    def command(self, command: int, params, target: int = 1) -> bytes:
        p = list(params) + [0.0] * (7 - len(params))
        return self.pack(self.mav.command_long_encode(target, 1, command, 0, *p))

    def reset(self, seed: int, target: int = 1) -> list:
        return self.exchange(self.command(RESET_COMMAND, [*seed_params(seed), 0.0], target))

    def set_interval(self, message_id: int, interval_us: float, target: int = 1) -> list:
        cmd = mavlink2.MAV_CMD_SET_MESSAGE_INTERVAL
        return self.exchange(self.command(cmd, [message_id, interval_us], target))

    def param_set(self, param_id: str, value: float, target: int = 1) -> list:
        msg = self.mav.param_set_encode(
            target, 1, param_id.encode(), value, mavlink2.MAV_PARAM_TYPE_REAL32
        )
        return self.exchange(self.pack(msg))

    def param_read(self, param_id: str, target: int = 1) -> list:
        msg = self.mav.param_request_read_encode(target, 1, param_id.encode(), -1)
        return self.exchange(self.pack(msg))

    def drain(self, seconds: float) -> list:
        """Every message received within `seconds`."""
        end = time.monotonic() + seconds
        out = []
        while (left := end - time.monotonic()) > 0:
            self.sock.settimeout(left)
            try:
                out.extend(self.receive()[1])
            except TimeoutError:
                break
        self.sock.settimeout(5.0)
        return out


def of_type(msgs: list, name: str) -> list:
    return [m for m in msgs if m.get_type() == name]


def statustexts(msgs: list) -> list[str]:
    """STATUSTEXT texts with MAVLink 2 chunks (same sender and non-zero id) joined."""
    out: list[str] = []
    chunks: dict[tuple[int, int], list[str]] = {}
    for m in of_type(msgs, "STATUSTEXT"):
        if m.id == 0:
            out.append(m.text)
            continue
        key = (m.get_srcSystem(), m.id)
        if key not in chunks:
            chunks[key] = []
            out.append(key)
        chunks[key].append(m.text)
    return ["".join(chunks[t]) if isinstance(t, tuple) else t for t in out]


def free_udp_port() -> int:
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


class GroundStation:
    """A pymavlink ground station listening like QGroundControl does (udpin)."""

    def __init__(self):
        self.sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self.sock.bind(("127.0.0.1", 0))
        self.port = self.sock.getsockname()[1]
        self.mav = mavlink2.MAVLink(None, srcSystem=255, srcComponent=190)
        self.parser = mavlink2.MAVLink(None)
        self.sitl_address = None

    def listen(self, seconds: float) -> list:
        out = []
        end = time.monotonic() + seconds
        while (left := end - time.monotonic()) > 0:
            self.sock.settimeout(left)
            try:
                data, self.sitl_address = self.sock.recvfrom(65536)
            except TimeoutError:
                break
            out.extend(self.parser.parse_buffer(data) or [])
        return out

    def command(self, command: int, params, target: int = 1) -> None:
        p = list(params) + [0.0] * (7 - len(params))
        msg = self.mav.command_long_encode(target, 1, command, 0, *p)
        self.sock.sendto(msg.pack(self.mav), self.sitl_address)

    def send(self, msg) -> None:
        """Sends a pymavlink message (e.g. PARAM_SET) to the SITL, once it has been heard."""
        self.sock.sendto(msg.pack(self.mav), self.sitl_address)
