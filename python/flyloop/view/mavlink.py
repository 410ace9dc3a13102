"""MAVLink into the scene: the live stream of a running SITL or autopilot (UDP, as a ground
station listens) or a recorded telemetry log (.tlog, e.g. ``flyloop-sitl --record``).

flyloop-sitl (HEARTBEAT autopilot GENERIC) gives the truth: HIL_STATE_QUATERNION, the motor
commands (SERVO_OUTPUT_RAW), the wind (WIND_COV) and the task frame (DEBUG_FLOAT_ARRAY: reward,
termination, the target). Its ground-station link sends these only when asked: a live view
asks with SET_MESSAGE_INTERVAL when it first hears a SITL, and stops them when it quits, so a
SITL nobody watches sends nothing more. An autopilot (PX4, ArduPilot) gives its estimate:
LOCAL_POSITION_NED with ATTITUDE_QUATERNION (or ATTITUDE), drawn beside the truth."""

from __future__ import annotations

import math
import os
import select
import socket
import time
from dataclasses import dataclass, field

import numpy as np

os.environ.setdefault("MAVLINK20", "1")
from pymavlink.dialects.v20 import common as mavlink2  # noqa: E402

from .scene import Frame, Scene  # noqa: E402

EARTH_RADIUS = 6_378_137.0  # m, the SITL's flat-earth projection (protocol.md §5)
DEFAULT_HOME = (47.397742, 8.545594, 488.0)  # the SITL's default --home
# What the view asks a flyloop-sitl for, and how often (25 Hz; the SITL allows up to 50 Hz).
STREAMS = (
    mavlink2.MAVLINK_MSG_ID_HIL_STATE_QUATERNION,
    mavlink2.MAVLINK_MSG_ID_SERVO_OUTPUT_RAW,
    mavlink2.MAVLINK_MSG_ID_WIND_COV,
    mavlink2.MAVLINK_MSG_ID_DEBUG_FLOAT_ARRAY,
)
STREAM_INTERVAL_US = 40_000
# Datagrams one listener handles per poll before the others (and the watch's clock) get a turn.
BATCH_DATAGRAMS = 64
# What the view asks an autopilot for at the same rate: its estimate.
ESTIMATE_STREAMS = (
    mavlink2.MAVLINK_MSG_ID_LOCAL_POSITION_NED,
    mavlink2.MAVLINK_MSG_ID_ATTITUDE_QUATERNION,
    mavlink2.MAVLINK_MSG_ID_ATTITUDE,
)
GENERIC = mavlink2.MAV_AUTOPILOT_GENERIC
AUTOPILOTS = {mavlink2.MAV_AUTOPILOT_PX4: "PX4", mavlink2.MAV_AUTOPILOT_ARDUPILOTMEGA: "ArduPilot"}
ARRAY_LEN = 58  # DEBUG_FLOAT_ARRAY values per message (protocol.md §6)
FLEET_SYSTEM = 250  # flyloop-sitl's own lines (a fleet's, an autopilot session's): STATUSTEXT
COLLISION = "collision"  # the NAMED_VALUE_FLOAT a fleet sends for each vehicle in a collision
TEXT_CHUNK = 50  # STATUSTEXT characters per message: a longer text comes in chunks
# MAV_SEVERITY → the events log's level
LEVELS = ("CRITICAL", "CRITICAL", "CRITICAL", "ERROR", "WARN", "INFO", "INFO", "DEBUG")


def enu_to_ned(v) -> list[float]:
    x, y, z = (float(a) for a in v)
    return [y, x, -z]


@dataclass
class _Vehicle:
    """A vehicle flyloop simulates (its truth), by system id."""

    frame: Frame | None = None
    home: tuple[float, float, float] = DEFAULT_HOME
    position: list[float] = field(default_factory=lambda: [0.0, 0.0, 0.0])
    arrays: dict[int, list[float]] = field(default_factory=dict)
    arrays_time: int = -1
    truth_seen: bool = False


@dataclass
class _Autopilot:
    """An autopilot's estimate (by where it comes from and its system id)."""

    position: list[float] | None = None
    # Its local origin in the truth's frame (NED from the truth's home, m): from its
    # GPS_GLOBAL_ORIGIN; zero until it says.
    origin: list[float] = field(default_factory=lambda: [0.0, 0.0, 0.0])
    origin_known: bool = False


class MavlinkScene:
    """Draws what MAVLink messages say: `handle(msg, source)` with a decoded pymavlink message
    and where it came from (a flyloop-sitl and a PX4 may both be system 1). The time is the
    message's simulation time (the SITL's and the autopilot's clocks are the same in every
    mode: lockstep, PX4's simulator and ArduPilot's JSON link)."""

    def __init__(self, scene: Scene) -> None:
        self.scene = scene
        self.kinds: dict[tuple, int] = {}  # (source, system id) -> MAV_AUTOPILOT of its HEARTBEAT
        self.vehicles: dict[int, _Vehicle] = {}
        self.autopilots: dict[tuple, _Autopilot] = {}
        self.truth_messages = 0
        self.estimate_messages = 0
        self._chunks: dict[tuple, list[str]] = {}  # (key, id) -> a long STATUSTEXT's chunks

    def _vehicle(self, sysid: int) -> _Vehicle:
        return self.vehicles.setdefault(sysid, _Vehicle())

    def is_autopilot(self, key: tuple) -> bool:
        return self.kinds.get(key, GENERIC) != GENERIC

    def handle(self, msg, source=None) -> None:
        handler = getattr(self, "_on_" + msg.get_type().lower(), None)
        if handler is not None:
            handler((source, msg.get_srcSystem()), msg)

    def _on_heartbeat(self, key: tuple, m) -> None:
        if m.autopilot != mavlink2.MAV_AUTOPILOT_INVALID:  # a ground station's own heartbeat
            self.kinds[key] = m.autopilot

    # ---- flyloop's truth ----

    def _on_home_position(self, key: tuple, m) -> None:
        if not self.is_autopilot(key):
            home = (m.latitude / 1e7, m.longitude / 1e7, m.altitude / 1e3)
            self._vehicle(key[1]).home = home

    def _on_hil_state_quaternion(self, key: tuple, m) -> None:
        sysid = key[1]
        v = self._vehicle(sysid)
        lat0, lon0, alt0 = v.home
        north = math.radians(m.lat / 1e7 - lat0) * EARTH_RADIUS
        east = math.radians(m.lon / 1e7 - lon0) * EARTH_RADIUS * math.cos(math.radians(lat0))
        v.position = [north, east, -(m.alt / 1e3 - alt0)]
        v.truth_seen = True
        self.scene.time(m.time_usec / 1e6)
        rates = (m.rollspeed, m.pitchspeed, m.yawspeed)
        frame = v.frame or Frame.quad_x()
        self.scene.vehicle(
            f"vehicle{sysid}", v.position, m.attitude_quaternion, frame, rates_frd=rates
        )
        self.truth_messages += 1

    def _on_servo_output_raw(self, key: tuple, m) -> None:
        raw = [getattr(m, f"servo{i}_raw") for i in range(1, 17)]
        if self.is_autopilot(key):  # its motors are the frame's first outputs
            v = self._vehicle(self._truth_of(key))
            name = f"vehicle{self._truth_of(key)}_autopilot"
            raw = raw[: len(v.frame.spins) if v.frame else 4]
        else:
            v = self._vehicle(key[1])
            if key not in self.kinds and not v.truth_seen:
                return  # from a system not yet heard of: maybe an autopilot before its HEARTBEAT
            name = f"vehicle{key[1]}_command"
            self.scene.time(m.time_usec / 1e6)
        used = [r for r in raw if r]
        if v.frame is None and used:
            v.frame = Frame.for_motors(len(used))
        # Below 1000 us (PX4's disarmed 900) is off: 0.
        self.scene.motors(name, [max(0.0, (r - 1000) / 1000) for r in used])

    def _on_wind_cov(self, key: tuple, m) -> None:
        if self.is_autopilot(key):
            return
        self.scene.time(m.time_usec / 1e6)
        position = self._vehicle(key[1]).position
        self.scene.wind(f"vehicle{key[1]}", position, [m.wind_x, m.wind_y, m.wind_z])

    def _on_hil_sensor(self, key: tuple, m) -> None:
        """The IMU sample flyloop sent an autopilot (a PX4 or ArduPilot recording)."""
        if self.is_autopilot(key):
            return
        self.scene.time(m.time_usec / 1e6)
        accel, gyro = (m.xacc, m.yacc, m.zacc), (m.xgyro, m.ygyro, m.zgyro)
        self.scene.sensors(f"vehicle{key[1]}", accel, gyro)

    def _on_debug_float_array(self, key: tuple, m) -> None:
        """The task frame: its arrays gathered (protocol.md §6), then reward, ends, target."""
        if self.is_autopilot(key):
            return
        sysid = key[1]
        v = self._vehicle(sysid)
        if m.time_usec != v.arrays_time:
            v.arrays, v.arrays_time = {}, m.time_usec
        v.arrays[m.array_id] = list(m.data)
        values = [x for k in sorted(v.arrays) for x in v.arrays[k]]
        n_obs, n_info = int(values[4]), int(values[5])
        if len(values) < 6 + n_obs + n_info:
            return  # more arrays to come
        info = values[6 + n_obs : 6 + n_obs + n_info]
        name = f"vehicle{sysid}"
        self.scene.time(m.time_usec / 1e6)
        self.scene.task(name, values[0], values[1] > 0.5, values[2] > 0.5)
        task = (
            bytes(m.name).rstrip(b"\0").decode()
            if isinstance(m.name, bytes)
            else str(m.name).rstrip("\0")
        )
        if task in ("hover", "waypoints"):
            self.scene.target(name, enu_to_ned(info[4:7]))
        elif task == "landing":
            if v.frame is None:
                v.frame = Frame.lander()
            self.scene.target(name, enu_to_ned([info[11], 0.0, info[12]]))

    # ---- events: collisions, what the fleet and the autopilots say ----

    def _on_named_value_float(self, key: tuple, m) -> None:
        """A fleet's collision: vehicle `key`'s closing speed at the contact's time."""
        if self.is_autopilot(key) or m.name.rstrip("\0") != COLLISION:
            return
        self.scene.time(m.time_boot_ms / 1e3)
        position = self._vehicle(key[1]).position
        self.scene.collision(f"vehicle{key[1]}", position, float(m.value))

    def _on_statustext(self, key: tuple, m) -> None:
        """A line from the fleet (its notices: collisions, autopilots gone, faults) or an
        autopilot (its own messages), in the events log; chunks of a long one joined."""
        text = m.text.rstrip("\0") if isinstance(m.text, str) else bytes(m.text).decode()
        if m.id:
            parts = self._chunks.setdefault((key, m.id), [])
            parts.append(text)
            if len(text) == TEXT_CHUNK:
                return  # more chunks to come
            text = "".join(self._chunks.pop((key, m.id)))
        if self.is_autopilot(key):
            name = f"vehicle{self._truth_of(key)}_autopilot"
        else:
            name = "flyloop" if key[1] == FLEET_SYSTEM else f"vehicle{key[1]}"
        self.scene.event(name, text, LEVELS[min(m.severity, len(LEVELS) - 1)])

    # ---- an autopilot's estimate ----

    def _truth_of(self, key: tuple) -> int:
        """The truth an autopilot's estimate is drawn beside: the vehicle with its system id,
        else the only one flyloop sends (PX4 instance i has system id i + 1, flyloop's
        --view stream 1)."""
        truths = [s for s, v in self.vehicles.items() if v.truth_seen]
        return truths[0] if key[1] not in truths and len(truths) == 1 else key[1]

    def _on_gps_global_origin(self, key: tuple, m) -> None:
        """The autopilot's local origin, as NED from the truth's home. One more than 1 km
        away means the two were given different homes (e.g. ArduPilot's own --home): both
        frames then start at the vehicle's start point, and the offset is taken as 0."""
        if not self.is_autopilot(key):
            return
        lat0, lon0, alt0 = self._vehicle(self._truth_of(key)).home
        north = math.radians(m.latitude / 1e7 - lat0) * EARTH_RADIUS
        east = math.radians(m.longitude / 1e7 - lon0) * EARTH_RADIUS * math.cos(math.radians(lat0))
        origin = [north, east, -(m.altitude / 1e3 - alt0)]
        autopilot = self.autopilots.setdefault(key, _Autopilot())
        autopilot.origin_known = True
        if math.hypot(*origin) < 1000.0:
            autopilot.origin = origin

    def origin_known(self, source) -> bool:
        """Whether the autopilot at `source` has told its local origin (an estimate before
        it is drawn as if its origin were home)."""
        return any(a.origin_known for (s, _), a in self.autopilots.items() if s == source)

    def _on_local_position_ned(self, key: tuple, m) -> None:
        if self.is_autopilot(key):
            a = self.autopilots.setdefault(key, _Autopilot())
            a.position = [m.x + a.origin[0], m.y + a.origin[1], m.z + a.origin[2]]

    def _on_attitude_quaternion(self, key: tuple, m) -> None:
        self._estimate(key, m.time_boot_ms / 1e3, [m.q1, m.q2, m.q3, m.q4])

    def _on_attitude(self, key: tuple, m) -> None:
        if self.kinds.get(key) == mavlink2.MAV_AUTOPILOT_ARDUPILOTMEGA:
            cr, sr = math.cos(m.roll / 2), math.sin(m.roll / 2)
            cp, sp = math.cos(m.pitch / 2), math.sin(m.pitch / 2)
            cy, sy = math.cos(m.yaw / 2), math.sin(m.yaw / 2)
            q = [
                cr * cp * cy + sr * sp * sy,
                sr * cp * cy - cr * sp * sy,
                cr * sp * cy + sr * cp * sy,
                cr * cp * sy - sr * sp * cy,
            ]
            self._estimate(key, m.time_boot_ms / 1e3, q)

    def _estimate(self, key: tuple, t_s: float, q) -> None:
        a = self.autopilots.get(key)
        if not self.is_autopilot(key) or a is None or a.position is None:
            return
        self.scene.time(t_s)
        truth = self._vehicle(self._truth_of(key))
        frame = truth.frame or Frame.quad_x()
        self.scene.vehicle(f"vehicle{self._truth_of(key)}", a.position, q, frame, estimate=True)
        self.estimate_messages += 1


def _decode(parser, data: bytes) -> list:
    try:
        return parser.parse_buffer(data) or []
    except mavlink2.MAVError:
        return []


class Listener:
    """A UDP socket where MAVLink arrives (a ground station's port, e.g. the SITL's --gcs
    target 127.0.0.1:14550). Asks every flyloop-sitl it hears for the view's streams, and
    stops them again at close()."""

    def __init__(self, address: tuple[str, int], view: MavlinkScene) -> None:
        self.address, self.view = address, view
        self.sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        try:
            self.sock.bind(address)
        except OSError as e:
            self.sock.close()
            raise OSError(
                f"cannot listen for MAVLink on udp {address[0]}:{address[1]}: {e.strerror}"
            ) from None
        self.sock.setblocking(False)
        # Room for bursts while the view draws (an autopilot at 4x real time sends ~1,000
        # messages/s): the kernel's default (~208 KiB) would drop them.
        self.sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4 << 20)
        self.peers: dict[tuple, object] = {}  # address -> its parser
        self.asked: set[tuple] = set()
        self.autopilots: list[tuple] = []
        # (system, component) of each autopilot heard at an address: commands' targets
        self.systems: dict[tuple, set[tuple]] = {}
        self.last_beat = 0.0
        self.mav = mavlink2.MAVLink(None, srcSystem=255, srcComponent=190)
        self.datagrams = 0

    def connect(self, autopilot: tuple[str, int]) -> None:
        """Talks first to an autopilot's MAVLink port (PX4's ground-station port 18570 + i
        answers whoever talks to it): a ground station's HEARTBEAT every second."""
        self.autopilots.append(autopilot)

    def fileno(self) -> int:
        return self.sock.fileno()

    def poll(self, most: int = BATCH_DATAGRAMS) -> int:
        """Handles the datagrams waiting, at most `most` of them; returns how many messages.
        Bounded: a view slower than its stream (a loaded machine) would otherwise never
        leave this loop, nor hear Ctrl-C's end of the watch."""
        n = 0
        self._beat()
        for _ in range(most):
            try:
                data, peer = self.sock.recvfrom(65536)
            except (BlockingIOError, InterruptedError):
                return n
            self.datagrams += 1
            parser = self.peers.setdefault(peer, mavlink2.MAVLink(None))
            for msg in _decode(parser, data):
                n += 1
                self.view.handle(msg, peer)
                if msg.get_type() == "HEARTBEAT" and msg.autopilot in AUTOPILOTS:
                    self.systems.setdefault(peer, set()).add(
                        (msg.get_srcSystem(), msg.get_srcComponent())
                    )
                if msg.get_type() == "HEARTBEAT" and peer not in self.asked:
                    if msg.autopilot == GENERIC:
                        self._ask(peer, STREAM_INTERVAL_US)
                    elif msg.autopilot in AUTOPILOTS:
                        self._greet(peer)
        return n

    def _commands(self, peer: tuple, commands: list[tuple]) -> None:
        """COMMAND_LONGs (command, param1, param2) to every system at `peer`, one datagram:
        addressed to each autopilot heard there (PX4 ignores a broadcast
        SET_MESSAGE_INTERVAL), broadcast to a flyloop-sitl."""
        out = b""
        for system, component in sorted(self.systems.get(peer, {(0, 0)})):
            for command, p1, p2 in commands:
                msg = self.mav.command_long_encode(
                    system, component, command, 0, p1, p2, 0, 0, 0, 0, 0
                )
                out += msg.pack(self.mav)
        self.sock.sendto(out, peer)

    def _ask(self, peer: tuple, interval_us: float) -> None:
        """A flyloop-sitl: SET_MESSAGE_INTERVAL of the view's streams, and its home."""
        self.asked.add(peer)
        interval = mavlink2.MAV_CMD_SET_MESSAGE_INTERVAL
        commands = [(interval, m, interval_us) for m in STREAMS]
        home = mavlink2.MAVLINK_MSG_ID_HOME_POSITION
        self._commands(peer, [*commands, (mavlink2.MAV_CMD_REQUEST_MESSAGE, home, 0)])

    def _greet(self, peer: tuple) -> None:
        """An autopilot: its estimate at 25 Hz, its local origin (the estimate's frame), and
        a ground station's heartbeat from now on (some send only to a ground station they
        hear)."""
        self.asked.add(peer)
        if peer not in self.autopilots:
            self.autopilots.append(peer)
        origin = mavlink2.MAVLINK_MSG_ID_GPS_GLOBAL_ORIGIN
        self._rates(peer, STREAM_INTERVAL_US, [(mavlink2.MAV_CMD_REQUEST_MESSAGE, origin, 0)])

    def _rates(self, peer: tuple, interval_us: float, more: list[tuple] = ()) -> None:
        """The autopilot's estimate every `interval_us` (0: its default rates again)."""
        interval = mavlink2.MAV_CMD_SET_MESSAGE_INTERVAL
        self._commands(peer, [(interval, m, interval_us) for m in ESTIMATE_STREAMS] + list(more))

    def _beat(self) -> None:
        now = time.monotonic()
        if self.autopilots and now - self.last_beat >= 1.0:
            self.last_beat = now
            gcs, invalid = mavlink2.MAV_TYPE_GCS, mavlink2.MAV_AUTOPILOT_INVALID
            hb = self.mav.heartbeat_encode(gcs, invalid, 0, 0, 0).pack(self.mav)
            origin = mavlink2.MAVLINK_MSG_ID_GPS_GLOBAL_ORIGIN
            for peer in self.autopilots:
                self.sock.sendto(hb, peer)
                # An autopilot sets its origin at its first GPS fusion, after the view
                # greeted it: ask again each second until it has answered.
                if not self.view.origin_known(peer):
                    self._commands(peer, [(mavlink2.MAV_CMD_REQUEST_MESSAGE, origin, 0)])

    def close(self) -> None:
        for peer in self.asked:
            try:
                if peer in self.autopilots:
                    self._rates(peer, 0)
                else:  # streams off again: a SITL nobody watches sends nothing more
                    self._ask(peer, -1)
            except OSError:
                pass
        self.sock.close()


def read_tlog(path: str, view: MavlinkScene) -> int:
    """Replays a telemetry log (8-byte big-endian µs time, then a MAVLink 2 frame; the format
    of `flyloop-sitl --record`, MAVProxy and QGroundControl) into `view`; returns the number
    of messages. Raises ValueError for a file that holds no MAVLink."""
    parser = mavlink2.MAVLink(None)
    parser.robust_parsing = True
    data = np.fromfile(path, dtype=np.uint8).tobytes()
    n, at = 0, 0
    while at + 8 < len(data):
        at += 8  # the time stamp: the messages carry their own simulation time
        if data[at] != 0xFD or at + 12 > len(data):
            break
        end = at + 12 + data[at + 1] + (13 if data[at + 2] & 1 else 0)
        for msg in _decode(parser, data[at:end]):
            if msg.get_type() != "BAD_DATA":
                view.handle(msg)
                n += 1
        at = end
    if n == 0:
        raise ValueError(f"{path}: no MAVLink 2 telemetry-log frame in it (not a .tlog?)")
    return n


def poll(listeners: list[Listener], timeout: float = 0.2) -> int:
    """Waits up to `timeout` for datagrams on any listener, then handles every one waiting
    (and sends the heartbeats due); returns how many messages."""
    select.select(listeners, [], [], timeout)
    return sum(listener.poll() for listener in listeners)
