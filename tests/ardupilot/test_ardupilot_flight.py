"""The real ArduCopter flies flyloop's quadrotor through ArduPilot's JSON interface,
commanded with pymavlink: GUIDED, arm, takeoff to 5 m, hold, reposition 10 m north, hold,
LAND and ArduPilot's own disarm; ArduPilot's estimate is checked against the targets and
flyloop's ground truth against ArduPilot's estimate."""

from __future__ import annotations

import time

from ardupilot_support import (
    GUIDED,
    LAND,
    TAKEOFF_ALT,
    check_landed,
    collect,
    settle,
    truth_vs_estimate,
)

ALT = TAKEOFF_ALT


def test_ardupilot_takes_off_repositions_and_lands_on_flyloop(pair):
    flyloop = pair.flyloop()
    ap = pair.ardupilot(flyloop)
    ap.wait_for_gps(120)
    ap.mode(GUIDED)
    ap.arm()
    ap.takeoff()
    settle(ap, 0.0, 0.0, ALT, 0.25, 60)
    collect(ap, 2.0)  # the climb's overshoot dies out
    hover = collect(ap, 3.0)
    ap.goto(10.0, 0.0, ALT)
    settle(ap, 10.0, 0.0, ALT, 0.25, 60)
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
    rows = flyloop.rows()

    for hold, (north, east) in ((hover, (0.0, 0.0)), (away, (10.0, 0.0))):
        horizontal, vertical = hold.worst(north, east, ALT)
        assert vertical < 0.3, f"altitude error {vertical:.3f} m at {north, east}"
        assert horizontal < 0.5, f"position error {horizontal:.3f} m at {north, east}"
        error = truth_vs_estimate(rows, hold, 1)
        assert error < 0.5, f"truth vs estimate {error:.3f} m at {north, east}"
        print(
            f"hold at {north, east}: altitude error {vertical:.3f} m, position error "
            f"{horizontal:.3f} m, truth vs estimate {error:.3f} m"
        )
    check_landed(rows, 10.0, 0.0)
    counters = flyloop.counters()
    assert int(counters["connections"]) == 1, counters
    assert int(counters["bad_magic"]) + int(counters["bad_length"]) == 0, counters
