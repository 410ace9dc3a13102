"""A real ArduCopter SITL flying flyloop-sitl through ArduPilot's JSON physics interface:
finding ArduPilot, starting both on ports that cannot clash, commanding ArduPilot with
pymavlink, and reading flyloop's ground-truth track.

ArduPilot comes from $FLYLOOP_ARDUPILOT: an unpacked ArduCopter SITL build (a directory with
bin/arducopter, and copter.parm beside bin/ or ArduPilot's Tools/autotest/default_params/),
an arducopter-sitl-*.tar.xz tarball, or a directory holding one. Without it the ArduPilot
tests skip with one line saying how to get it; with FLYLOOP_REQUIRE_ARDUPILOT=1 (set by
.ci/run) a missing ArduPilot fails them.
"""

from __future__ import annotations

import csv
import math
import os
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

REPO = Path(__file__).resolve().parents[2]
PARM = REPO / "sitl" / "presets" / "ardupilot_iris.parm"
HOW_TO_GET_ARDUPILOT = (
    "ArduPilot tests need an ArduCopter SITL build: in an ArduPilot checkout run "
    "`./waf configure --board sitl && ./waf copter` and set FLYLOOP_ARDUPILOT to a directory "
    "with bin/arducopter and copter.parm (Tools/autotest/default_params/copter.parm), or to a "
    "tarball of one"
)
EARTH_RADIUS = 6_378_137.0
# ArduPilot's home (its SITL default, passed explicitly): latitude, longitude (deg), altitude
# (m), heading (deg). flyloop's NED positions count from this point.
HOME = (-35.363262, 149.165237, 584.0, 0.0)
# ArduPilot's --speedup in the tests (flyloop runs unpaced: ArduPilot paces the lockstep).
SPEEDUP = 10
TAKEOFF_ALT = 5.0
# ArduCopter flight modes.
GUIDED, AUTO, LAND = 4, 3, 9


@dataclass(frozen=True)
class Build:
    """An ArduCopter SITL binary and ArduPilot's default Copter SITL parameters."""

    binary: Path
    copter_parm: Path


def ardupilot_build(unpack_into: Path) -> Build:
    """The ArduCopter build from $FLYLOOP_ARDUPILOT, unpacking a tarball."""
    given = os.environ.get("FLYLOOP_ARDUPILOT", "")
    if not given:
        if os.environ.get("FLYLOOP_REQUIRE_ARDUPILOT") == "1":
            pytest.fail(
                f"FLYLOOP_REQUIRE_ARDUPILOT=1 but FLYLOOP_ARDUPILOT is not set. "
                f"{HOW_TO_GET_ARDUPILOT}"
            )
        pytest.skip(HOW_TO_GET_ARDUPILOT)
    path = Path(given).resolve()
    if path.is_file() or not (path / "bin" / "arducopter").exists():
        tarballs = [path] if path.is_file() else sorted(path.glob("arducopter-sitl-*.tar.xz"))
        if not tarballs and (path / "ardupilot" / "bin" / "arducopter").exists():
            path = path / "ardupilot"
        elif not tarballs:
            pytest.fail(
                f"FLYLOOP_ARDUPILOT={given} holds neither bin/arducopter nor an "
                "arducopter-sitl-*.tar.xz"
            )
        else:
            with tarfile.open(tarballs[0]) as tar:
                tar.extractall(unpack_into, filter="tar")
            path = unpack_into / "ardupilot"
    for parm in (
        path / "copter.parm",
        path / "Tools" / "autotest" / "default_params" / "copter.parm",
    ):
        if parm.exists():
            return Build(path / "bin" / "arducopter", parm)
    pytest.fail(f"no copter.parm beside {path / 'bin'}")


def ardupilot_ports_free(i: int) -> bool:
    """Whether ArduPilot instance i's ports are free right now: TCP 5760/5762/5763 + 10i (its
    serial ports), UDP 5501 + 10i (RC input) and 9002 + 10i (its default physics port)."""
    tcp = all(port_free(socket.SOCK_STREAM, p + 10 * i) for p in (5760, 5762, 5763))
    return tcp and all(port_free(socket.SOCK_DGRAM, p + 10 * i) for p in (5501, 9002))


def free_instance() -> int:
    """An ArduPilot instance number (3..150, never 0: a developer's own SITL uses it) whose
    ports are free right now (ardupilot_ports_free)."""
    for _ in range(200):
        i = 3 + int.from_bytes(os.urandom(2), "little") % 148
        if ardupilot_ports_free(i):
            return i
    raise RuntimeError("no free ArduPilot instance found")


class Flyloop:
    """flyloop-sitl in ArduPilot mode on a free UDP port, writing its ground-truth track."""

    def __init__(self, binary: Path, workdir: Path, *args: str, speed: float = 0):
        self.track = workdir / "track.csv"
        self.log = open(workdir / "flyloop.log", "w+")
        self.proc = subprocess.Popen(
            [
                str(binary),
                "--ardupilot",
                "--ardupilot-listen",
                "127.0.0.1:0",
                "--speed-factor",
                str(speed),
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
        self.port = int(self.ready["ardupilot"].rsplit(":", 1)[1])

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

    def counters(self) -> dict[str, str]:
        """The counters of the line flyloop logs when it stops."""
        return stop_counters(self.stderr())

    def wait_for_log(self, text: str, timeout: float) -> None:
        end = time.monotonic() + timeout
        while text not in self.stderr() and time.monotonic() < end:
            time.sleep(0.1)
        assert text in self.stderr(), self.stderr()[-3000:]


def ned_of(lat: float, lon: float, alt: float) -> tuple[float, float, float]:
    """Latitude, longitude (deg), altitude MSL (m) → north, east, down from HOME, m (flat
    earth, as ArduPilot turns flyloop's NED into a position)."""
    return (
        EARTH_RADIUS * math.radians(lat - HOME[0]),
        EARTH_RADIUS * math.cos(math.radians(HOME[0])) * math.radians(lon - HOME[1]),
        HOME[2] - alt,
    )


def global_of(north: float, east: float) -> tuple[float, float]:
    """North, east from HOME (m) → latitude, longitude (deg)."""
    return (
        HOME[0] + math.degrees(north / EARTH_RADIUS),
        HOME[1] + math.degrees(east / (EARTH_RADIUS * math.cos(math.radians(HOME[0])))),
    )


@dataclass(frozen=True)
class Estimate:
    """ArduPilot's GLOBAL_POSITION_INT at `time_ms` (its clock = flyloop's physics time):
    NED from HOME (m), height above ArduPilot's home (m), speed (m/s)."""

    time_ms: int
    position: tuple[float, float, float]
    relative_alt: float
    speed: float


class ArduPilot:
    """An ArduCopter SITL instance in its own working directory, flying flyloop (servo
    packets to flyloop's port), and a pymavlink link to its TCP port 5760 + 10i."""

    def __init__(
        self,
        build: Build,
        instance: int,
        flyloop_port: int,
        workdir: Path,
        *extra,
        parm: Path = PARM,
    ):
        """`parm`: flyloop's parameter file on top of copter.parm (the Iris's by default)."""
        self.instance = instance
        workdir.mkdir(parents=True, exist_ok=True)
        self.log = open(workdir / "arducopter.log", "w+")
        home = ",".join(str(v) for v in HOME)
        self.proc = subprocess.Popen(
            [
                str(build.binary),
                "--model",
                "JSON:127.0.0.1",
                "--defaults",
                f"{build.copter_parm},{parm}",
                "--home",
                home,
                "--speedup",
                str(SPEEDUP),
                "-w",
                "-I",
                str(instance),
                # After -I: the port flyloop listens on (ArduPilot's default 9002 + 10i).
                "--sim-port-out",
                str(flyloop_port),
                *extra,
            ],
            cwd=workdir,
            stdin=subprocess.DEVNULL,
            # Its own group: stop() kills the children it starts (processes.py says why).
            start_new_session=True,
            stdout=self.log,
            stderr=subprocess.STDOUT,
        )
        self.tcp_port = 5760 + 10 * instance
        self.link = None
        self.target = 1
        # ArduPilot's STATUSTEXT lines (prearm failures, mode changes), for failure messages.
        self.texts: list[str] = []

    def output(self) -> str:
        self.log.flush()
        return Path(self.log.name).read_text()

    def connect(self, timeout: float = 30) -> None:
        """Connects to SERIAL0 (ArduPilot blocks until a client is there) and asks for its
        telemetry streams."""
        end = time.monotonic() + timeout
        while True:
            try:
                self.link = mavutil.mavlink_connection(
                    f"tcp:127.0.0.1:{self.tcp_port}",
                    source_system=245,
                    dialect="ardupilotmega",
                    retries=0,
                )
                break
            except OSError as e:
                if time.monotonic() > end or self.proc.poll() is not None:
                    raise AssertionError(f"no TCP {self.tcp_port}:\n{self.output()[-3000:]}") from e
                time.sleep(0.2)
        hb = self.wait_for(
            "a heartbeat",
            lambda m: m.autopilot == mavutil.mavlink.MAV_AUTOPILOT_ARDUPILOTMEGA,
            60,
            "HEARTBEAT",
        )
        self.target = hb.get_srcSystem()
        # Telemetry at 10 Hz of ArduPilot's clock (positions, status, heartbeat as usual).
        self.link.mav.request_data_stream_send(
            self.target, 1, mavutil.mavlink.MAV_DATA_STREAM_ALL, 10, 1
        )

    def kill(self) -> None:
        stop(self.proc, signal.SIGKILL)
        if self.link is not None:
            self.link.close()

    def stop(self) -> None:
        stop(self.proc)
        if self.link is not None:
            self.link.close()

    def wait_for(self, what: str, predicate, timeout: float, types=None):
        """The first message (of `types`) for which `predicate` holds, or a failure naming
        `what`."""
        end = time.monotonic() + timeout
        while time.monotonic() < end:
            if self.proc.poll() is not None:
                raise AssertionError(f"ArduPilot exited waiting for {what}:\n{self.report()}")
            m = self.link.recv_match(blocking=True, timeout=0.2)
            if m is None:
                continue
            if m.get_type() == "STATUSTEXT":
                self.texts.append(m.text)
            wanted = types is None or m.get_type() in ([types] if isinstance(types, str) else types)
            if wanted and predicate(m):
                return m
        raise AssertionError(f"timed out waiting for {what}:\n{self.report()}")

    def report(self) -> str:
        """ArduPilot's last status texts and console lines."""
        texts = "\n".join(self.texts[-30:])
        return f"STATUSTEXT:\n{texts}\nconsole:\n{self.output()[-2000:]}"

    def command(self, command: int, *params: float) -> None:
        p = list(params) + [0.0] * (7 - len(params))
        self.link.mav.command_long_send(self.target, 1, command, 0, *p)

    def accepted(self, command: int, send, timeout: float) -> None:
        """Sends a command (again every second) until ArduPilot accepts it (it refuses to
        arm until its estimator uses GPS)."""
        end = time.monotonic() + timeout
        last = None
        while time.monotonic() < end:
            send()
            try:
                ack = self.wait_for(
                    f"command {command} acknowledged",
                    lambda m: m.command == command,
                    1.0,
                    "COMMAND_ACK",
                )
                last = ack.result
                if ack.result == mavutil.mavlink.MAV_RESULT_ACCEPTED:
                    return
                time.sleep(0.5)
            except AssertionError:
                pass
        raise AssertionError(
            f"ArduPilot did not accept command {command} (last result {last}):\n{self.report()}"
        )

    def mode(self, mode: int, timeout: float = 30) -> None:
        """Sets a flight mode and waits for the heartbeat to show it."""
        end = time.monotonic() + timeout
        while time.monotonic() < end:
            self.link.mav.set_mode_send(
                self.target, mavutil.mavlink.MAV_MODE_FLAG_CUSTOM_MODE_ENABLED, mode
            )
            try:
                self.wait_for(f"mode {mode}", lambda m: m.custom_mode == mode, 1.0, "HEARTBEAT")
                return
            except AssertionError:
                pass
        raise AssertionError(f"ArduPilot did not switch to mode {mode}")

    def armed(self, hb) -> bool:
        return bool(hb.base_mode & mavutil.mavlink.MAV_MODE_FLAG_SAFETY_ARMED)

    def wait_for_gps(self, timeout: float) -> None:
        """Waits until EKF3 uses GPS on both IMUs: before that ArduPilot's mode and arming
        checks may pass, but a takeoff is refused (and the mode may fall back)."""
        for imu in (0, 1):
            text = f"EKF3 IMU{imu} is using GPS"
            if not any(text in t for t in self.texts):
                self.wait_for(text, lambda m, text=text: text in m.text, timeout, "STATUSTEXT")

    def arm(self, timeout: float = 30) -> None:
        arm = mavutil.mavlink.MAV_CMD_COMPONENT_ARM_DISARM
        self.accepted(arm, lambda: self.command(arm, 1), timeout)

    def takeoff(self, alt: float = TAKEOFF_ALT) -> None:
        takeoff = mavutil.mavlink.MAV_CMD_NAV_TAKEOFF
        self.accepted(takeoff, lambda: self.command(takeoff, 0, 0, 0, 0, 0, 0, alt), 20)

    def goto(self, north: float, east: float, alt: float) -> None:
        """DO_REPOSITION to `north`, `east` of HOME (m), `alt` above ArduPilot's home."""
        lat, lon = global_of(north, east)
        reposition = mavutil.mavlink.MAV_CMD_DO_REPOSITION
        self.accepted(
            reposition,
            lambda: self.link.mav.command_int_send(
                self.target,
                1,
                mavutil.mavlink.MAV_FRAME_GLOBAL_RELATIVE_ALT_INT,
                reposition,
                0,
                0,
                -1,
                mavutil.mavlink.MAV_DO_REPOSITION_FLAGS_CHANGE_MODE,
                0,
                0,
                round(lat * 1e7),
                round(lon * 1e7),
                alt,
            ),
            30,
        )

    def estimate(self) -> Estimate:
        m = self.wait_for("a global position", lambda m: True, 30, "GLOBAL_POSITION_INT")
        return Estimate(
            m.time_boot_ms,
            ned_of(m.lat * 1e-7, m.lon * 1e-7, m.alt * 1e-3),
            m.relative_alt * 1e-3,
            math.hypot(m.vx, m.vy, m.vz) / 100,
        )


@dataclass
class Hold:
    """ArduPilot's estimates over a hold."""

    samples: list[Estimate]

    def worst(self, north: float, east: float, alt: float) -> tuple[float, float]:
        """Largest horizontal distance from (north, east) and height error from `alt` above
        ArduPilot's home."""
        h = max(math.hypot(s.position[0] - north, s.position[1] - east) for s in self.samples)
        v = max(abs(s.relative_alt - alt) for s in self.samples)
        return h, v


def fly_mission(ap, flyloop):
    """GUIDED, arm, takeoff to TAKEOFF_ALT, hold, 10 m north, hold, LAND and ArduPilot's own
    disarm, then flyloop stopped; returns the holds (each with its north, east) and flyloop's
    track."""
    ap.wait_for_gps(120)
    ap.mode(GUIDED)
    ap.arm()
    ap.takeoff()
    settle(ap, 0.0, 0.0, TAKEOFF_ALT, 0.25, 60)
    collect(ap, 2.0)  # the climb's overshoot dies out
    hover = collect(ap, 3.0)
    ap.goto(10.0, 0.0, TAKEOFF_ALT)
    settle(ap, 10.0, 0.0, TAKEOFF_ALT, 0.25, 60)
    collect(ap, 2.0)
    away = collect(ap, 3.0)
    ap.mode(LAND)
    ap.wait_for(
        "the automatic disarm after landing",
        lambda m: m.get_srcSystem() == ap.target and not ap.armed(m),
        90,
        "HEARTBEAT",
    )
    time.sleep(0.5)  # a little rest on the ground in the track
    flyloop.stop()
    return [(hover, (0.0, 0.0)), (away, (10.0, 0.0))], flyloop.rows()


def collect(source, seconds: float) -> Hold:
    """`source`'s estimates over `seconds` of ArduPilot's clock."""
    first = source.estimate()
    samples = [first]
    while samples[-1].time_ms - first.time_ms < seconds * 1000:
        samples.append(source.estimate())
    return Hold(samples)


def settle(source, north: float, east: float, alt: float, tolerance: float, timeout: float):
    """Waits until `source`'s estimate is within `tolerance` of the target and nearly still."""
    end = time.monotonic() + timeout
    e = None
    while time.monotonic() < end:
        e = source.estimate()
        off = math.hypot(e.position[0] - north, e.position[1] - east, e.relative_alt - alt)
        if off < tolerance and e.speed < 0.2:
            return
    raise AssertionError(f"no arrival at {(north, east, alt)} within {timeout} s: last {e}")


def truth_vs_estimate_parts(
    rows: list[dict[str, float]], hold: Hold, connection: int
) -> tuple[float, float, float]:
    """Largest distance (3-D, horizontal, vertical) between ArduPilot's estimate and flyloop's
    ground truth at the same time (ArduPilot's clock is flyloop's physics time; the truth
    interpolated between rows)."""
    rows = [r for r in rows if r["connection"] == connection]
    times = [r["time_us"] / 1000 for r in rows]
    compared = [s for s in hold.samples if times[0] <= s.time_ms <= times[-1]]
    assert len(compared) > len(hold.samples) / 2, f"the track ends at {times[-1]} ms"
    worst = [0.0, 0.0, 0.0]
    for s in compared:
        i = next(k for k in range(1, len(times)) if times[k] >= s.time_ms)
        a, b = rows[i - 1], rows[i]
        w = (s.time_ms - times[i - 1]) / (times[i] - times[i - 1])
        truth = tuple(a[k] + w * (b[k] - a[k]) for k in ("north", "east", "down"))
        d = [truth[k] - s.position[k] for k in range(3)]
        parts = (math.hypot(*d), math.hypot(d[0], d[1]), abs(d[2]))
        worst = [max(x, y) for x, y in zip(worst, parts, strict=True)]
    return worst[0], worst[1], worst[2]


def truth_vs_estimate(rows: list[dict[str, float]], hold: Hold, connection: int) -> float:
    """Largest 3-D distance between ArduPilot's estimate and flyloop's truth (see
    truth_vs_estimate_parts)."""
    return truth_vs_estimate_parts(rows, hold, connection)[0]


def check_landed(rows: list[dict[str, float]], north: float, east: float) -> None:
    """At the end: at rest level on its feet where it started from, motors off, below the
    last target (< 1 m)."""
    first, last = rows[0], rows[-1]
    assert last["grounded"] == 1.0 and max(last[f"m{i}"] for i in range(4)) < 0.01, last
    assert abs(last["roll"]) < 0.02 and abs(last["pitch"]) < 0.02, last
    assert abs(last["down"] - first["down"]) < 0.005, (first, last)
    assert math.hypot(last["north"] - north, last["east"] - east) < 1.0, last
