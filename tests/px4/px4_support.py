"""A real PX4 SITL flying flyloop-sitl: finding PX4, starting both on ports that cannot clash,
commanding PX4 with pymavlink, and reading flyloop's ground-truth track.

PX4 comes from $FLYLOOP_PX4: an unpacked PX4 SITL build (a directory with bin/px4 and etc/),
a release tarball, or a directory holding one. Without it the PX4 tests skip with one line
saying how to get PX4; with FLYLOOP_REQUIRE_PX4=1 (set by .ci/run) a missing PX4 fails them.
"""

from __future__ import annotations

import csv
import math
import os
import shutil
import signal
import socket
import subprocess
import sys
import tarfile
import time
from dataclasses import dataclass
from pathlib import Path

import pytest

os.environ["MAVLINK20"] = "1"
from pymavlink import mavutil  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "sitl"))
# Re-exported: the tests import stop and fresh_dir from here.
from processes import fresh_dir, port_free, stop, stop_counters  # noqa: E402, F401

HOW_TO_GET_PX4 = (
    "PX4 tests need a PX4 SITL build: build PX4-Autopilot's px4_sitl_default (v1.14 or later) "
    "and set FLYLOOP_PX4 to its build/px4_sitl_default directory (or to a SITL tarball)"
)
EARTH_RADIUS = 6_378_137.0
# flyloop's home (the sensor defaults of the Iris preset): latitude, longitude (deg), altitude (m).
HOME = (47.397742, 8.545594, 488.0)
# Simulation seconds per wall second for flyloop and PX4 in the tests.
SPEED = 4
# PX4's main mode AUTO and its sub mode TAKEOFF (px4_custom_mode.h).
AUTO, AUTO_TAKEOFF = 4, 2
# Takeoff height above home, m (PX4's MIS_TAKEOFF_ALT).
TAKEOFF_ALT = 5.0


# PX4 gives its work queues SCHED_FIFO priorities 1-99 when it may (as root here). On a shared
# 2-core machine those threads starve everything else, and a SIGKILLed PX4's 26 runnable
# FIFO threads waited 20-60 s for a CPU before exiting while its zombie leader could not be
# reaped (the fleet mission test's teardown hang). Without CAP_SYS_NICE PX4 falls back to
# normal threads, as it runs for any non-root user.
WITHOUT_REALTIME = (
    ("setpriv", "--inh-caps=-sys_nice", "--bounding-set=-sys_nice")
    if os.geteuid() == 0 and shutil.which("setpriv")
    else ()
)


def px4_root(unpack_into: Path) -> Path:
    """The PX4 directory (with bin/px4 and etc/) from $FLYLOOP_PX4, unpacking a tarball."""
    given = os.environ.get("FLYLOOP_PX4", "")
    if not given:
        if os.environ.get("FLYLOOP_REQUIRE_PX4") == "1":
            pytest.fail(f"FLYLOOP_REQUIRE_PX4=1 but FLYLOOP_PX4 is not set. {HOW_TO_GET_PX4}")
        pytest.skip(HOW_TO_GET_PX4)
    path = Path(given).resolve()
    for candidate in (path, path / "px4"):
        if (candidate / "bin" / "px4").exists():
            return candidate
    tarballs = [path] if path.is_file() else sorted(path.glob("px4-sitl-*.tar.xz"))
    if not tarballs:
        pytest.fail(f"FLYLOOP_PX4={given} holds neither bin/px4 nor a px4-sitl-*.tar.xz")
    with tarfile.open(tarballs[0]) as tar:
        tar.extractall(unpack_into, filter="tar")
    return unpack_into / "px4"


def _stale(server: Path) -> bool:
    """Whether PX4's server socket file is left over (a killed PX4 never removes it; nothing
    listens): then it is removed, and its instance number is free again."""
    with socket.socket(socket.AF_UNIX, socket.SOCK_STREAM) as s:
        try:
            s.connect(str(server))
            return False
        except ConnectionRefusedError:
            server.unlink(missing_ok=True)
            return True
        except OSError:
            return False


def px4_ports_free(i: int) -> bool:
    """Whether PX4 instance i's simulator port (4560 + i), MAVLink ports (14580 + i,
    18570 + i, 14280 + i, 13030 + i) and server socket are all free right now (a stale
    server socket file is removed)."""
    server = Path(f"/tmp/px4-sock-{i}")
    if server.exists() and not _stale(server):
        return False
    udp = (14580 + i, 18570 + i, 14280 + i, 13030 + i)
    return port_free(socket.SOCK_STREAM, 4560 + i) and all(
        port_free(socket.SOCK_DGRAM, p) for p in udp
    )


def free_instance() -> int:
    """A PX4 instance number whose ports and server socket are free (px4_ports_free)."""
    for _ in range(200):
        i = 10 + int.from_bytes(os.urandom(2), "little") % 240  # MAV_SYS_ID = i + 1 ≤ 251
        if px4_ports_free(i):
            return i
    raise RuntimeError("no free PX4 instance found")


class Flyloop:
    """flyloop-sitl in PX4 mode, writing its ground-truth track."""

    def __init__(self, binary: Path, instance: int, workdir: Path, *args: str, speed=None):
        self.track = workdir / "track.csv"
        self.log = open(workdir / "flyloop.log", "w+")
        self.proc = subprocess.Popen(
            [
                str(binary),
                "--px4",
                "--px4-listen",
                f"127.0.0.1:{4560 + instance}",
                "--speed-factor",
                str(SPEED if speed is None else speed),
                "--track",
                str(self.track),
                *args,
            ],
            stdout=subprocess.PIPE,
            stderr=self.log,
            text=True,
        )
        line = self.proc.stdout.readline()
        if not line.startswith("flyloop-sitl ready "):
            stop(self.proc)
            raise RuntimeError(f"flyloop-sitl did not start: {line!r} {self.stderr()}")
        self.ready = dict(kv.split("=", 1) for kv in line.split()[2:])

    def stderr(self) -> str:
        self.log.flush()
        return Path(self.log.name).read_text()

    def rows(self) -> list[dict[str, float]]:
        with open(self.track) as f:
            # Every column a number but `faults` (the fault events, text).
            rows = csv.DictReader(f)
            return [{k: float(v) for k, v in row.items() if k != "faults"} for row in rows]

    def stop(self) -> int:
        stop(self.proc)
        return self.proc.returncode


@dataclass(frozen=True)
class Estimate:
    """PX4's position estimate at `time_ms` (PX4's clock = flyloop's simulation time):
    north, east, down in some local frame (m) and its speed (m/s)."""

    time_ms: int
    position: tuple[float, float, float]
    speed: float


@dataclass(frozen=True)
class LocalFrame:
    """PX4's local NED frame: its origin in degrees and metres above MSL. flyloop's truth is
    NED from flyloop's home (the centre of mass, m); the same point in PX4's frame is what
    PX4's estimate must match."""

    latitude: float
    longitude: float
    altitude: float

    def _scale(self) -> tuple[float, float]:
        """Metres per radian north and east around the origin (flat earth: the projection
        error is far below a millimetre over the tests' tens of metres)."""
        return EARTH_RADIUS, EARTH_RADIUS * math.cos(math.radians(self.latitude))

    def from_flyloop(self, ned: tuple[float, float, float]) -> tuple[float, float, float]:
        """flyloop's NED from its home → PX4's local NED."""
        north, east = self._scale()
        return (
            ned[0] + north * math.radians(HOME[0] - self.latitude),
            ned[1] + east * math.radians(HOME[1] - self.longitude),
            ned[2] + self.altitude - HOME[2],
        )

    def to_flyloop(self, ned: tuple[float, float, float]) -> tuple[float, float, float]:
        """A point of PX4's local NED → flyloop's NED from its home."""
        origin = self.from_flyloop((0.0, 0.0, 0.0))
        return (ned[0] - origin[0], ned[1] - origin[1], ned[2] - origin[2])

    def from_global(self, lat: float, lon: float, alt: float) -> tuple[float, float, float]:
        """Latitude, longitude (deg), altitude MSL (m) → a point of this frame."""
        north, east = self._scale()
        return (
            north * math.radians(lat - self.latitude),
            east * math.radians(lon - self.longitude),
            self.altitude - alt,
        )

    def to_global(self, ned: tuple[float, float, float]) -> tuple[float, float, float]:
        """A point of PX4's local frame → latitude, longitude (deg), altitude MSL (m)."""
        north, east = self._scale()
        return (
            self.latitude + math.degrees(ned[0] / north),
            self.longitude + math.degrees(ned[1] / east),
            self.altitude - ned[2],
        )


class Px4:
    """A PX4 SITL instance in its own working directory, and a pymavlink link to it."""

    def __init__(self, root: Path, instance: int, workdir: Path, **params: float):
        """`params`: PX4 parameters to override at start, by name."""
        self.instance = instance
        workdir.mkdir(parents=True, exist_ok=True)
        env = dict(
            os.environ,
            PX4_SYS_AUTOSTART="10016",
            PX4_SIM_MODEL="none_iris",
            PX4_SIM_SPEED_FACTOR=str(SPEED),
            PX4_PARAM_COM_RC_IN_MODE="4",
            # Takeoff height relative to home: a GPS altitude sample at arming cannot offset it.
            PX4_PARAM_MIS_TAKEOFF_ALT=str(TAKEOFF_ALT),
            **{f"PX4_PARAM_{name}": str(value) for name, value in params.items()},
        )
        self.log = open(workdir / "px4.log", "w+")
        self.proc = subprocess.Popen(
            [
                *WITHOUT_REALTIME,
                str(root / "bin" / "px4"),
                "-d",
                "-i",
                str(instance),
                "-w",
                str(workdir),
                str(root / "etc"),
            ],
            cwd=workdir,
            env=env,
            stdin=subprocess.DEVNULL,
            # Its own group: stop() kills the children it starts (processes.py says why).
            start_new_session=True,
            stdout=self.log,
            stderr=subprocess.STDOUT,
        )
        # PX4's offboard link listens on 14580 + i and answers whoever talks to it (its
        # default partner port is shared by instances above 9), so the test talks first.
        self.link = mavutil.mavlink_connection(
            f"udpout:127.0.0.1:{14580 + instance}", source_system=245, dialect="common"
        )
        self.target = 1 + instance
        self.last_beat = 0.0

    def output(self) -> str:
        self.log.flush()
        return Path(self.log.name).read_text()

    def kill(self) -> None:
        # SIGKILL: PX4 ignores SIGTERM while it waits for a simulator.
        stop(self.proc, signal.SIGKILL)
        self.link.close()

    def wait_for(self, what: str, predicate, timeout: float, types=None):
        """The first message (of `types`) for which `predicate` holds, or a failure naming
        `what`."""
        end = time.monotonic() + timeout
        while time.monotonic() < end:
            if self.proc.poll() is not None:
                tail = self.output()[-3000:]
                raise AssertionError(f"PX4 exited while waiting for {what}:\n{tail}")
            if time.monotonic() - self.last_beat > 0.5:
                self.last_beat = time.monotonic()
                self.link.mav.heartbeat_send(
                    mavutil.mavlink.MAV_TYPE_GCS, mavutil.mavlink.MAV_AUTOPILOT_INVALID, 0, 0, 0
                )
            m = self.link.recv_match(type=types, blocking=True, timeout=0.2)
            if m is not None and predicate(m):
                return m
        raise AssertionError(f"timed out waiting for {what}:\n{self.output()[-3000:]}")

    def command(self, command: int, *params: float) -> None:
        p = list(params) + [0.0] * (7 - len(params))
        self.link.mav.command_long_send(self.target, 1, command, 0, *p)

    def armed(self, hb) -> bool:
        return bool(hb.base_mode & mavutil.mavlink.MAV_MODE_FLAG_SAFETY_ARMED)

    def heartbeat(self, timeout: float):
        """PX4's first heartbeat; its system id becomes the target of commands."""
        hb = self.wait_for(
            "a heartbeat",
            lambda m: m.autopilot == mavutil.mavlink.MAV_AUTOPILOT_PX4,
            timeout,
            "HEARTBEAT",
        )
        self.target = hb.get_srcSystem()
        return hb

    def accepted(self, command: int, send, timeout: float, every=1.0, taken=None) -> None:
        """Sends a command (again every `every` s) until PX4 acknowledges it as accepted, or
        shows in a heartbeat that it acted on it (`taken(heartbeat)`): a datagram can be
        lost, and PX4 refuses some commands until its estimator is ready."""

        def done(m) -> bool:
            if m.get_type() == "COMMAND_ACK":
                return m.command == command and m.result == 0
            return m.get_srcSystem() == self.target and taken(m)

        types = "COMMAND_ACK" if taken is None else ["COMMAND_ACK", "HEARTBEAT"]
        end = time.monotonic() + timeout
        while time.monotonic() < end:
            send()
            try:
                self.wait_for(f"command {command} accepted", done, every, types)
                return
            except AssertionError:
                pass
        raise AssertionError(f"PX4 did not accept command {command}:\n{self.output()[-3000:]}")

    def arm_when_ready(self, timeout: float) -> None:
        """Arms as soon as PX4 accepts (its estimator needs GPS and a few seconds)."""
        arm = mavutil.mavlink.MAV_CMD_COMPONENT_ARM_DISARM
        self.accepted(arm, lambda: self.command(arm, 1), timeout)

    def takeoff(self, timeout: float = 30) -> None:
        """Takeoff to MIS_TAKEOFF_ALT above home, here. Sent again only while PX4 has
        neither acknowledged it nor shown its takeoff mode, 5 s apart: a takeoff PX4 takes
        when it is already climbing sets a new target MIS_TAKEOFF_ALT above where it is
        (loaded, its acknowledgement later than the 1 s the command was once resent after,
        fleet test PX4s held 9.8 m and 13.9 m instead of 5 m)."""
        nan = float("nan")
        takeoff = mavutil.mavlink.MAV_CMD_NAV_TAKEOFF
        self.accepted(
            takeoff,
            lambda: self.command(takeoff, -1, 0, 0, nan, nan, nan, nan),
            timeout,
            every=5.0,
            taken=self.taking_off,
        )

    def taking_off(self, hb) -> bool:
        """Armed in AUTO.TAKEOFF (PX4's custom mode: sub mode << 24 | main mode << 16)."""
        mode = hb.custom_mode
        return self.armed(hb) and (mode >> 16) & 0xFF == AUTO and (mode >> 24) == AUTO_TAKEOFF

    def arm_and_take_off(self, timeout: float, attempts: int = 3) -> None:
        """Arms as soon as PX4 accepts and commands the takeoff, again if PX4 disarmed in
        between: PX4 disarms a vehicle still on the ground COM_DISARM_PRFLT (10 s of
        simulation) after arming, which at several times real time is a second or two of
        a loaded test process's time (a fleet test's PX4 once stayed on the ground so)."""
        for _ in range(attempts):
            self.arm_when_ready(timeout)
            self.takeoff()
            # The first heartbeat after the takeoff's acknowledgement (PX4 sends in order).
            hb = self.wait_for(
                "a heartbeat after the takeoff",
                lambda m: (
                    m.get_srcSystem() == self.target
                    and m.autopilot == mavutil.mavlink.MAV_AUTOPILOT_PX4
                ),
                30,
                "HEARTBEAT",
            )
            if self.armed(hb):
                return
        raise AssertionError(f"PX4 disarmed before its takeoff {attempts} times")

    def request(self, message_id: int, what: str, timeout: float = 30):
        """One message PX4 sends on request (MAV_CMD_REQUEST_MESSAGE, asked again every
        second: a datagram can be lost)."""
        end = time.monotonic() + timeout
        while time.monotonic() < end:
            self.command(mavutil.mavlink.MAV_CMD_REQUEST_MESSAGE, message_id)
            try:
                return self.wait_for(what, lambda m: True, 1.0, what)
            except AssertionError:
                pass
        raise AssertionError(f"PX4 did not send {what}:\n{self.output()[-3000:]}")

    def estimate(self) -> Estimate:
        """PX4's next LOCAL_POSITION_NED (its own local frame)."""
        m = self.wait_for("a position estimate", lambda m: True, 30, "LOCAL_POSITION_NED")
        return Estimate(m.time_boot_ms, (m.x, m.y, m.z), math.hypot(m.vx, m.vy, m.vz))

    def frame(self) -> LocalFrame:
        """PX4's local frame: its estimator set the origin from the GPS fixes it had when it
        started (noise included), so it is not flyloop's home, and it does not move after."""
        o = self.request(mavutil.mavlink.MAVLINK_MSG_ID_GPS_GLOBAL_ORIGIN, "GPS_GLOBAL_ORIGIN")
        return LocalFrame(o.latitude * 1e-7, o.longitude * 1e-7, o.altitude * 1e-3)

    def home(self) -> tuple[float, float, float]:
        """PX4's home (set when it armed) in its local frame, m north, east, down: takeoff
        and landing heights count from here."""
        h = self.request(mavutil.mavlink.MAVLINK_MSG_ID_HOME_POSITION, "HOME_POSITION")
        return (h.x, h.y, h.z)

    def goto(self, frame: LocalFrame, target: tuple[float, float, float]) -> None:
        """Fly to `target` (north, east, down in PX4's local frame `frame`, m): a
        DO_REPOSITION to the same point in global coordinates (COMMAND_INT keeps degE7
        exact)."""
        lat, lon, alt = frame.to_global(target)
        reposition = mavutil.mavlink.MAV_CMD_DO_REPOSITION
        self.accepted(
            reposition,
            lambda: self.link.mav.command_int_send(
                self.target,
                1,
                mavutil.mavlink.MAV_FRAME_GLOBAL,
                reposition,
                0,
                0,
                -1,
                1,
                0,
                float("nan"),
                round(lat * 1e7),
                round(lon * 1e7),
                alt,
            ),
            30,
        )

    def land(self) -> None:
        land = mavutil.mavlink.MAV_CMD_NAV_LAND
        self.accepted(land, lambda: self.command(land), 30)


@dataclass
class Hold:
    """PX4's local position estimate over a hold, and flyloop's truth at the same times."""

    estimate: list[tuple[int, float, float, float]]  # time_boot_ms, north, east, down

    def worst(self, target: tuple[float, float, float]) -> tuple[float, float]:
        """Largest horizontal and vertical distance of the estimate from `target`."""
        h = max(math.hypot(n - target[0], e - target[1]) for _, n, e, _ in self.estimate)
        v = max(abs(d - target[2]) for _, _, _, d in self.estimate)
        return h, v


def collect(source, seconds: float) -> Hold:
    """`source`'s estimates (its `estimate()`) over `seconds` of PX4 time."""
    first = source.estimate()
    samples = [first]
    while samples[-1].time_ms - first.time_ms < seconds * 1000:
        samples.append(source.estimate())
    return Hold([(e.time_ms, *e.position) for e in samples])


def settle(source, target: tuple[float, float, float], tolerance: float, timeout: float) -> None:
    """Waits until `source`'s estimate is within `tolerance` of `target` and nearly still."""
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        e = source.estimate()
        if math.dist(e.position, target) < tolerance and e.speed < 0.2:
            return
    raise AssertionError(f"no arrival at {target} within {timeout} s: last estimate {e}")


def truth_vs_estimate(
    rows: list[dict[str, float]], hold: Hold, connection: int, frame: LocalFrame
) -> float:
    """Largest distance between PX4's estimate and flyloop's ground truth at the same time, in
    PX4's local frame (PX4's clock is flyloop's simulation time; the truth is interpolated
    between rows; estimates after the last row, written before PX4 went away, are left out)."""
    rows = [r for r in rows if r["connection"] == connection]
    times = [r["time_us"] / 1000 for r in rows]
    compared = [s for s in hold.estimate if s[0] <= times[-1]]
    assert len(compared) > len(hold.estimate) / 2, f"the track ends at {times[-1]} ms"
    worst = 0.0
    for t, n, e, d in compared:
        i = next(k for k in range(1, len(times)) if times[k] >= t)
        a, b = rows[i - 1], rows[i]
        w = (t - times[i - 1]) / (times[i] - times[i - 1])
        truth = frame.from_flyloop(
            tuple(a[k] + w * (b[k] - a[k]) for k in ("north", "east", "down"))
        )
        worst = max(worst, math.dist(truth, (n, e, d)))
    return worst


def check_mission(rows, holds, frame: LocalFrame) -> None:
    """The checks of a flown mission, on flyloop's track `rows` (first connection) and PX4's
    estimates `holds` (a Hold and its target in `frame`, each): PX4's estimate against the
    targets (altitude < 0.3 m, position < 0.5 m), flyloop's truth against PX4's estimate at
    the same instants (< 0.5 m), and at the end: at rest level on its feet (the centre of
    mass at the start height), motors off, below the last target (< 1 m)."""
    for hold, target in holds:
        horizontal, vertical = hold.worst(target)
        assert vertical < 0.3, f"altitude error {vertical:.3f} m at {target}"
        assert horizontal < 0.5, f"position error {horizontal:.3f} m at {target}"
        error = truth_vs_estimate(rows, hold, 1, frame)
        assert error < 0.5, f"truth vs estimate {error:.3f} m at {target}"
    first, last = rows[0], rows[-1]
    motors = [v for k, v in last.items() if k[0] == "m" and k[1:].isdigit()]
    assert last["grounded"] == 1.0 and max(motors) < 0.01, last
    assert abs(last["roll"]) < 0.01 and abs(last["pitch"]) < 0.01, last
    assert abs(last["down"] - first["down"]) < 0.002, (first, last)
    north, east, _ = frame.from_flyloop((last["north"], last["east"], last["down"]))
    target = holds[-1][1]
    assert math.hypot(north - target[0], east - target[1]) < 1.0, (target, last)


def launch(px4):
    """Waits for PX4, arms it as soon as it is ready and commands the takeoff; returns PX4's
    local frame and the takeoff target in it."""
    px4.heartbeat(60)
    px4.arm_and_take_off(60)
    frame = px4.frame()
    home = px4.home()
    return frame, (home[0], home[1], home[2] - TAKEOFF_ALT)


def offset(point, north=0.0, east=0.0):
    return (point[0] + north, point[1] + east, point[2])


def fly_mission(px4, flyloop):
    """Takeoff to TAKEOFF_ALT, hold, 10 m north, hold, land and PX4's own disarm, then
    flyloop stopped; returns PX4's local frame, the two holds with their targets, and
    flyloop's track."""
    frame, hover_target = launch(px4)
    settle(px4, hover_target, 0.25, 60)
    collect(px4, 2.0)  # let the climb's overshoot die out
    hover = collect(px4, 3.0)
    away_target = offset(hover_target, north=10.0)
    px4.goto(frame, away_target)
    settle(px4, away_target, 0.25, 60)
    collect(px4, 2.0)
    away = collect(px4, 3.0)
    px4.land()
    px4.wait_for(
        "the automatic disarm after landing",
        lambda m: m.get_srcSystem() == px4.target and not px4.armed(m),
        90,
        "HEARTBEAT",
    )
    time.sleep(0.5)  # a little rest on the ground in the track
    flyloop.stop()
    return frame, [(hover, hover_target), (away, away_target)], flyloop.rows()


def autopilot_params(sitl_binary: Path, preset: Path, autopilot: str) -> dict[str, str]:
    """The parameters `flyloop-sitl --print-autopilot-params` gives for `preset`'s frame."""
    out = subprocess.run(
        [str(sitl_binary), "--config", str(preset), "--print-autopilot-params", autopilot],
        check=True,
        capture_output=True,
        text=True,
    ).stdout
    lines = [line.split() for line in out.splitlines() if line and not line.startswith("#")]
    return {name: value for name, value in lines}
