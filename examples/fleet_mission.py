"""Flies N PX4s of one flyloop world on crossing legs at separated altitudes and prints each
vehicle's error (docs/fleet.md).

Start flyloop-sitl and the PX4s first (docs/fleet.md has the commands):

    flyloop-sitl --px4 --vehicles 4                       # PX4 i on TCP 4560 + i, 3 m apart
    PX4_SYS_AUTOSTART=10016 PX4_SIM_MODEL=none_iris px4 -d -i 0 -w /tmp/px4-0 .../etc  # i = 0..3

then `python examples/fleet_mission.py --vehicles 4`. Vehicle k stands at (3k m east, 0) and
climbs to 5 + 2k m; then it flies a leg to the mirror point across the row, 10 m north, so
every leg crosses the others above or below them; it holds there and lands. Errors are
PX4's position estimate (GLOBAL_POSITION_INT) against the target over a 2 s hold at each
end of the leg. Exit 0 when every error is within --tolerance and all land and disarm.

`--collide` sends two of them into each other instead: vehicles 0 and 1 take off to 5 m
over their start points, then vehicle 1 flies to where vehicle 0 hovers. flyloop reports
the collision as a STATUSTEXT from system 250 to its `--gcs` address (127.0.0.1:14550 by
default); this script listens there (`--gcs`), prints every line flyloop sends, and exits 0
once it has heard the collision (then both land).
"""

from __future__ import annotations

import argparse
import math
import os
import sys
import time

os.environ.setdefault("MAVLINK20", "1")
from pymavlink import mavutil  # noqa: E402

EARTH_RADIUS = 6_378_137.0
MAV = mavutil.mavlink


class Vehicle:
    """One PX4 on its offboard link (UDP 14580 + instance; we talk first)."""

    def __init__(self, instance: int, home, east: float):
        self.instance = instance
        self.target_system = instance + 1
        self.home = home
        self.east = east
        self.link = mavutil.mavlink_connection(
            f"udpout:127.0.0.1:{14580 + instance}", source_system=245, dialect="common"
        )
        # PX4's offboard link answers only the first address that talks to it, for good: from
        # PX4's own partner port (14540 + i; instances above 9 share 14549) every run of this
        # script is that partner, so it can fly the same PX4s again. Taken (MAVSDK, another
        # script): any port, and this PX4 answers this run only if it is its first partner.
        if instance <= 9:
            try:
                self.link.port.bind(("127.0.0.1", 14540 + instance))
            except OSError:
                pass
        self.last_beat = 0.0
        self.ground_amsl = home[2]

    def recv(self, kind: str, timeout: float):
        end = time.monotonic() + timeout
        while time.monotonic() < end:
            if time.monotonic() - self.last_beat > 0.5:
                self.last_beat = time.monotonic()
                self.link.mav.heartbeat_send(MAV.MAV_TYPE_GCS, MAV.MAV_AUTOPILOT_INVALID, 0, 0, 0)
            m = self.link.recv_match(type=kind, blocking=True, timeout=0.2)
            if m is not None and m.get_srcSystem() == self.target_system:
                return m
        raise TimeoutError(
            f"vehicle {self.instance}: no {kind} from PX4 instance {self.instance} on udp "
            f"{14580 + self.instance} within {timeout:g} s (is it running? it answers only the "
            "first program that talked to that port: restart it after another one did)"
        )

    def command(self, command: int, *params: float, timeout: float = 60) -> None:
        """COMMAND_LONG, again every second until accepted."""
        p = list(params) + [0.0] * (7 - len(params))
        end = time.monotonic() + timeout
        while time.monotonic() < end:
            self.link.mav.command_long_send(self.target_system, 1, command, 0, *p)
            try:
                ack = self.recv("COMMAND_ACK", 1.0)
                if ack.command == command and ack.result == MAV.MAV_RESULT_ACCEPTED:
                    return
            except TimeoutError:
                pass
        raise TimeoutError(f"vehicle {self.instance}: command {command} not accepted")

    def global_of(self, east: float, north: float) -> tuple[float, float]:
        lat, lon, _ = self.home
        return (
            lat + math.degrees(north / EARTH_RADIUS),
            lon + math.degrees(east / (EARTH_RADIUS * math.cos(math.radians(lat)))),
        )

    def goto(self, east: float, north: float, height: float) -> None:
        """DO_REPOSITION to a point of the world (m east, north of flyloop's home, m above
        the ground PX4 armed on)."""
        lat, lon = self.global_of(east, north)
        amsl = self.ground_amsl + height
        end = time.monotonic() + 60
        while time.monotonic() < end:
            self.link.mav.command_int_send(
                self.target_system, 1, MAV.MAV_FRAME_GLOBAL, MAV.MAV_CMD_DO_REPOSITION,
                0, 0, -1, 1, 0, float("nan"), round(lat * 1e7), round(lon * 1e7), amsl,
            )  # fmt: skip
            try:
                ack = self.recv("COMMAND_ACK", 1.0)
                if ack.command == MAV.MAV_CMD_DO_REPOSITION and ack.result == 0:
                    return
            except TimeoutError:
                pass
        raise TimeoutError(f"vehicle {self.instance}: reposition not accepted")

    def error(self, east: float, north: float, height: float):
        """Horizontal and vertical distance of PX4's estimate from the target, m, and its
        speed, m/s, and PX4's time, ms."""
        m = self.recv("GLOBAL_POSITION_INT", 10)
        lat, lon = self.global_of(east, north)
        dn = math.radians(m.lat * 1e-7 - lat) * EARTH_RADIUS
        de = math.radians(m.lon * 1e-7 - lon) * EARTH_RADIUS * math.cos(math.radians(lat))
        dv = m.alt * 1e-3 - (self.ground_amsl + height)
        return math.hypot(dn, de), abs(dv), math.hypot(m.vx, m.vy, m.vz) / 100, m.time_boot_ms

    def hold(self, target, tolerance: float, timeout: float = 120, seconds: float = 2.0):
        """Waits to arrive (within the tolerance, nearly still) and 2 s more for the
        overshoot to die out, then the worst error over `seconds` of PX4 time."""
        end = time.monotonic() + timeout
        while True:
            h, v, speed, t_arrived = self.error(*target)
            if h < tolerance and v < tolerance and speed < 0.2:
                break
            if time.monotonic() > end:
                raise TimeoutError(f"vehicle {self.instance}: no arrival at {target}")
        t0 = t_arrived
        while t0 - t_arrived < 2000:
            _, _, _, t0 = self.error(*target)
        worst_h = worst_v = 0.0
        t = t0
        while t - t0 < seconds * 1000:
            h, v, _, t = self.error(*target)
            worst_h, worst_v = max(worst_h, h), max(worst_v, v)
        return worst_h, worst_v

    def armed(self) -> bool:
        return bool(self.recv("HEARTBEAT", 10).base_mode & MAV.MAV_MODE_FLAG_SAFETY_ARMED)


def fleet_lines(gcs: str):
    """flyloop's own STATUSTEXT (system 250) on its ground-station address, or None with a
    line saying why when that port is taken (a ground station listening there)."""
    try:
        return mavutil.mavlink_connection(f"udpin:{gcs}", dialect="common")
    except OSError as e:
        print(f"fleet_mission.py: cannot listen on udp {gcs} for flyloop's lines: {e}")
        return None


def collide(fleet, gcs: str, timeout: float = 60) -> int:
    """Vehicles 0 and 1 up to 5 m, then 1 sent to 0's point; exit code 0 once flyloop said
    `collision ...`."""
    listener = fleet_lines(gcs)
    if listener is None:
        return 1
    a, b = fleet[0], fleet[1]
    for v in (a, b):
        v.recv("HEARTBEAT", 120)
        v.command(MAV.MAV_CMD_COMPONENT_ARM_DISARM, 1, timeout=120)
        v.ground_amsl = v.recv("GLOBAL_POSITION_INT", 10).alt * 1e-3
        nan = float("nan")
        v.command(MAV.MAV_CMD_NAV_TAKEOFF, -1, 0, 0, nan, nan, nan, nan)
    for v in (a, b):
        v.goto(v.east, 0.0, 5.0)
    for v in (a, b):
        v.hold((v.east, 0.0, 5.0), 0.3)
    print(f"vehicle 1 flies to vehicle 0 ({a.east:.1f} m east, 5 m up)")
    b.goto(a.east, 0.0, 5.0)
    heard = False
    chunks: dict[int, str] = {}  # a line longer than 50 bytes comes in chunks with one id
    end = time.monotonic() + timeout
    while time.monotonic() < end and not heard:
        m = listener.recv_match(type="STATUSTEXT", blocking=True, timeout=0.5)
        if m is None or m.get_srcSystem() != 250:
            continue
        text = chunks.pop(m.id, "") + m.text
        if m.id != 0 and len(m.text) == 50:
            chunks[m.id] = text
            continue
        print(f"flyloop: {text}")
        heard = text.startswith("collision ")
    if not heard:
        print(f"no collision reported on udp {gcs} within {timeout:.0f} s")
    for v in (a, b):
        v.command(MAV.MAV_CMD_NAV_LAND)
    listener.close()
    return 0 if heard else 1


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--vehicles", type=int, default=4, help="number of PX4s (default 4)")
    p.add_argument("--first-instance", type=int, default=0, help="PX4 instance of vehicle 0")
    p.add_argument("--spacing", type=float, default=3.0, help="flyloop's --spacing, m")
    p.add_argument("--home", default="47.397742,8.545594,488", help="flyloop's --home")
    p.add_argument("--tolerance", type=float, default=0.3, help="largest error allowed, m")
    p.add_argument("--leg", type=float, default=10.0, help="northward length of a leg, m")
    p.add_argument(
        "--collide", action="store_true", help="send vehicle 1 into vehicle 0 instead (2 or more)"
    )
    p.add_argument(
        "--gcs", default="127.0.0.1:14550", help="flyloop's --gcs, where --collide listens"
    )
    a = p.parse_args(argv)
    if a.vehicles < 1:
        p.error("--vehicles must be at least 1")
    if a.collide and a.vehicles < 2:
        p.error("--collide needs --vehicles 2 or more")
    home = tuple(float(x) for x in a.home.split(","))
    n = a.vehicles
    fleet = [Vehicle(a.first_instance + k, home, a.spacing * k) for k in range(n)]
    if a.collide:
        return collide(fleet, a.gcs)
    heights = [5.0 + 2.0 * k for k in range(n)]
    for v in fleet:
        v.recv("HEARTBEAT", 120)
        v.command(MAV.MAV_CMD_COMPONENT_ARM_DISARM, 1, timeout=120)
        v.ground_amsl = v.recv("GLOBAL_POSITION_INT", 10).alt * 1e-3
        nan = float("nan")
        v.command(MAV.MAV_CMD_NAV_TAKEOFF, -1, 0, 0, nan, nan, nan, nan)
    starts = [(v.east, 0.0, z) for v, z in zip(fleet, heights, strict=False)]
    ends = [(fleet[n - 1 - k].east, a.leg, z) for k, z in enumerate(heights)]
    for v, s in zip(fleet, starts, strict=False):
        v.goto(*s)
    errors = [[v.hold(s, a.tolerance)] for v, s in zip(fleet, starts, strict=False)]
    for v, e in zip(fleet, ends, strict=False):
        v.goto(*e)
    for k, (v, e) in enumerate(zip(fleet, ends, strict=False)):
        errors[k].append(v.hold(e, a.tolerance))
    for v in fleet:
        v.command(MAV.MAV_CMD_NAV_LAND)
    landed = []
    for v in fleet:
        end = time.monotonic() + 120
        while v.armed() and time.monotonic() < end:
            pass
        landed.append(not v.armed())
    ok = True
    for k, (v, e) in enumerate(zip(fleet, errors, strict=False)):
        worst = max(max(h, z) for h, z in e)
        good = worst <= a.tolerance and landed[k]
        ok &= good
        legs = "  ".join(f"horizontal {h:.3f} m vertical {z:.3f} m" for h, z in e)
        print(
            f"vehicle {k} (PX4 instance {v.instance}, sysid {v.target_system}, "
            f"{heights[k]:.0f} m): start {legs.split('  ')[0]}; end {legs.split('  ')[1]}; "
            f"{'landed and disarmed' if landed[k] else 'NOT disarmed'}"
        )
    return 0 if ok else 1


if __name__ == "__main__":
    try:
        sys.exit(main())
    except TimeoutError as e:
        sys.exit(f"fleet_mission.py: {e}")
