"""ArduCopter flies an AUTO mission uploaded from a script (pymavlink, the mission protocol
with MISSION_ITEM_INT): takeoff to 5 m, a waypoint 10 m north, one 10 m east of it, land
there; ArduPilot disarms by itself. Checked on flyloop's ground truth: each waypoint passed
within WPNAV_RADIUS (2 m by default: ArduPilot turns to the next waypoint there, cutting the
corner), the landing within 1 m of the last one."""

from __future__ import annotations

import math
import subprocess
import sys
import time
from pathlib import Path

from ardupilot_support import AUTO, GUIDED, TAKEOFF_ALT, check_landed, global_of, mavutil

WAYPOINTS = [(10.0, 0.0), (10.0, 10.0)]
# ArduCopter's default WPNAV_RADIUS, m.
WAYPOINT_RADIUS = 2.0


def mission_items(target: int):
    """Item 0 is home (ArduPilot overwrites it), then takeoff, waypoints, land."""
    frame = mavutil.mavlink.MAV_FRAME_GLOBAL_RELATIVE_ALT_INT
    cmd = mavutil.mavlink
    items = [(cmd.MAV_CMD_NAV_WAYPOINT, 0.0, 0.0, 0.0)]
    items.append((cmd.MAV_CMD_NAV_TAKEOFF, 0.0, 0.0, TAKEOFF_ALT))
    items += [(cmd.MAV_CMD_NAV_WAYPOINT, n, e, TAKEOFF_ALT) for n, e in WAYPOINTS]
    items.append((cmd.MAV_CMD_NAV_LAND, *WAYPOINTS[-1], 0.0))
    out = []
    for seq, (command, north, east, alt) in enumerate(items):
        lat, lon = global_of(north, east)
        out.append(
            mavutil.mavlink.MAVLink_mission_item_int_message(
                target, 1, seq, frame, command, 0, 1, 0, 0, 0, 0,
                round(lat * 1e7), round(lon * 1e7), alt, 0,
            )
        )  # fmt: skip
    return out


def upload(ap, items) -> None:
    """The mission protocol: MISSION_COUNT, then each item ArduPilot asks for, until its ACK."""
    ap.link.mav.mission_count_send(ap.target, 1, len(items), 0)
    while True:
        m = ap.wait_for(
            "a mission request or ack",
            lambda m: True,
            10,
            ["MISSION_REQUEST_INT", "MISSION_REQUEST", "MISSION_ACK"],
        )
        if m.get_type() == "MISSION_ACK":
            assert m.type == mavutil.mavlink.MAV_MISSION_ACCEPTED, m
            return
        ap.link.mav.send(items[m.seq])


def test_ardupilot_flies_an_auto_mission_uploaded_from_a_script(pair):
    flyloop = pair.flyloop()
    ap = pair.ardupilot(flyloop)
    ap.wait_for_gps(120)  # booted (its mission store too), and the EKF uses GPS
    upload(ap, mission_items(ap.target))
    ap.mode(GUIDED)
    ap.arm()
    ap.mode(AUTO)
    start = mavutil.mavlink.MAV_CMD_MISSION_START
    ap.accepted(start, lambda: ap.command(start, 0, 0), 20)
    reached = set()
    last = len(WAYPOINTS) + 1  # the last waypoint's sequence number
    while last not in reached:
        m = ap.wait_for("a waypoint reached", lambda m: True, 120, "MISSION_ITEM_REACHED")
        reached.add(m.seq)
    ap.wait_for("the disarm after landing", lambda m: not ap.armed(m), 120, "HEARTBEAT")
    time.sleep(0.5)
    flyloop.stop()
    rows = flyloop.rows()
    airborne = [r for r in rows if -r["down"] > TAKEOFF_ALT - 0.5]
    assert airborne, "never climbed to the mission altitude"
    for north, east in WAYPOINTS:
        # Height of the centre of mass above home (it stands 0.054 m up at rest).
        height = [-r["down"] + rows[0]["down"] for r in rows]
        closest = min(
            math.hypot(r["north"] - north, r["east"] - east, h - TAKEOFF_ALT)
            for r, h in zip(rows, height, strict=True)
        )
        assert closest < WAYPOINT_RADIUS, f"waypoint {north, east} missed by {closest:.2f} m"
        print(f"waypoint {north, east}: closest approach of the truth {closest:.3f} m")
    check_landed(rows, *WAYPOINTS[-1])

    # docs/ardupilot.md's plot script draws this track.
    png = flyloop.track.with_suffix(".png")
    script = Path(__file__).resolve().parents[2] / "examples" / "px4_track_plot.py"
    subprocess.run(
        [sys.executable, str(script), str(flyloop.track), str(png), "ArduPilot"], check=True
    )
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    print(f"track plot: {png}")
