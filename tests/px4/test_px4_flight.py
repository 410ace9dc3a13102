"""The real PX4 autopilot flies flyloop's quadrotor: a mission with takeoff, hold, a 10 m
leg and an automatic landing, and a PX4 killed in flight and replaced by a new one.

Targets are in PX4's local frame, relative to PX4's home (where it armed), as a ground
station gives them; flyloop's truth is carried into that frame through the origin PX4 reports
(GPS_GLOBAL_ORIGIN), which PX4 took from its first GPS fixes, noise included."""

from __future__ import annotations

import subprocess
import sys
import time
from pathlib import Path

from px4_support import (
    TAKEOFF_ALT,
    check_mission,
    collect,
    fly_mission,
    launch,
    settle,
    truth_vs_estimate,
)

ALT = TAKEOFF_ALT


def test_px4_takes_off_holds_flies_10_m_and_lands_on_flyloop(pair):
    flyloop = pair.flyloop()
    px4 = pair.px4()
    frame, holds, rows = fly_mission(px4, flyloop)
    check_mission(rows, holds, frame)

    # docs/px4.md's plot script draws this track.
    png = flyloop.track.with_suffix(".png")
    script = Path(__file__).resolve().parents[2] / "examples" / "px4_track_plot.py"
    subprocess.run([sys.executable, str(script), str(flyloop.track), str(png)], check=True)
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_flyloop_survives_a_killed_px4_and_flies_the_next_one(pair):
    flyloop = pair.flyloop()
    first = pair.px4()
    _, target = launch(first)
    climbed = target[2] + ALT - 2.0  # 2 m above PX4's home
    first.wait_for("climbing past 2 m", lambda m: m.z < climbed, 60, "LOCAL_POSITION_NED")
    first.kill()  # mid-flight
    deadline = time.monotonic() + 10
    while "PX4 disconnected" not in flyloop.stderr() and time.monotonic() < deadline:
        time.sleep(0.1)
    assert "PX4 disconnected" in flyloop.stderr()
    assert flyloop.proc.poll() is None, "flyloop-sitl died with PX4"

    second = pair.px4()
    frame, target = launch(second)
    settle(second, target, 0.5, 60)
    hold = collect(second, 1.0)
    second.kill()
    flyloop.stop()
    rows = flyloop.rows()
    # The second flight started from the start state of the first: on its feet at home.
    starts = [next(r for r in rows if r["connection"] == c) for c in (1, 2)]
    assert starts[0] == {**starts[1], "connection": 1.0}, starts
    assert starts[1]["grounded"] == 1.0 and starts[1]["north"] == 0.0
    # Killed in the air.
    assert min(r["down"] for r in rows if r["connection"] == 1) < starts[0]["down"] - 1.5
    # The second PX4 flew it to the takeoff height: truth where PX4 believes it is.
    error = truth_vs_estimate(rows, hold, 2, frame)
    assert error < 0.5, f"truth vs estimate {error:.3f} m"
