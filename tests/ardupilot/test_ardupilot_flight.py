"""The real ArduCopter flies flyloop's quadrotor through ArduPilot's JSON interface,
commanded with pymavlink: GUIDED, arm, takeoff to 5 m, hold, reposition 10 m north, hold,
LAND and ArduPilot's own disarm; ArduPilot's estimate is checked against the targets and
flyloop's ground truth against ArduPilot's estimate."""

from __future__ import annotations

from ardupilot_support import (
    TAKEOFF_ALT,
    check_landed,
    fly_mission,
    truth_vs_estimate,
)

ALT = TAKEOFF_ALT


def test_ardupilot_takes_off_repositions_and_lands_on_flyloop(pair):
    flyloop = pair.flyloop()
    ap = pair.ardupilot(flyloop)
    holds, rows = fly_mission(ap, flyloop)

    for hold, (north, east) in holds:
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
