"""The real PX4 autopilot flies flyloop's quadrotor: a mission with takeoff, hold, a 10 m
leg and an automatic landing, and a PX4 killed in flight and replaced by a new one."""

from __future__ import annotations

import math
import subprocess
import sys
import time
from pathlib import Path

from px4_support import TAKEOFF_ALT, collect, settle, truth_vs_estimate

ALT = TAKEOFF_ALT


def launch(px4):
    """Waits for PX4, arms it as soon as it is ready and commands the takeoff."""
    px4.heartbeat(60)
    px4.arm_when_ready(60)
    px4.takeoff()
    return px4


def test_px4_takes_off_holds_flies_10_m_and_lands_on_flyloop(pair):
    flyloop = pair.flyloop()
    px4 = launch(pair.px4())
    settle(px4, (0.0, 0.0, -ALT), 0.15, 60)
    collect(px4, 2.0)  # let the climb's overshoot die out
    hover = collect(px4, 3.0)
    px4.reposition(10.0, 0.0)
    settle(px4, (10.0, 0.0, -ALT), 0.15, 60)
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
    rows = flyloop.rows()

    # PX4's own estimate against the targets.
    for hold, target in ((hover, (0.0, 0.0, -ALT)), (away, (10.0, 0.0, -ALT))):
        horizontal, vertical = hold.worst(target)
        assert vertical < 0.3, f"altitude error {vertical:.3f} m at {target}"
        assert horizontal < 0.5, f"position error {horizontal:.3f} m at {target}"
        # flyloop's ground truth against PX4's estimate, at the same instants.
        assert truth_vs_estimate(rows, hold, 1) < 0.5
    # At rest, level, on the ground, motors off.
    last = rows[-1]
    assert last["grounded"] == 1.0
    assert abs(last["roll"]) < 0.02 and abs(last["pitch"]) < 0.02, last
    assert abs(last["down"]) < 0.05
    assert math.hypot(last["north"] - 10.0, last["east"]) < 1.0, last

    # The README's plot script draws this track.
    png = flyloop.track.with_suffix(".png")
    script = Path(__file__).resolve().parents[2] / "examples" / "px4_track_plot.py"
    subprocess.run([sys.executable, str(script), str(flyloop.track), str(png)], check=True)
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_flyloop_survives_a_killed_px4_and_flies_the_next_one(pair):
    flyloop = pair.flyloop()
    first = launch(pair.px4())
    first.wait_for("climbing past 1.5 m", lambda m: m.z < -1.5, 60, "LOCAL_POSITION_NED")
    first.kill()  # mid-flight
    deadline = time.monotonic() + 10
    while "PX4 disconnected" not in flyloop.stderr() and time.monotonic() < deadline:
        time.sleep(0.1)
    assert "PX4 disconnected" in flyloop.stderr()
    assert flyloop.proc.poll() is None, "flyloop-sitl died with PX4"

    second = launch(pair.px4())
    settle(second, (0.0, 0.0, -ALT), 0.5, 60)
    second.kill()
    flyloop.stop()
    rows = flyloop.rows()
    # The second flight started from the start state, on the ground at home.
    restart = next(r for r in rows if r["connection"] == 2)
    assert restart["down"] == 0.0 and restart["north"] == 0.0 and restart["grounded"] == 1.0
    assert min(r["down"] for r in rows if r["connection"] == 1) < -1.5
    assert min(r["down"] for r in rows if r["connection"] == 2) < -ALT + 0.5
