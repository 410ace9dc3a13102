"""An ArduPilot killed mid-flight: flyloop logs the silence, keeps running, and a new
ArduPilot (frame count from 0) gets the vehicle back in its start state and flies it."""

from __future__ import annotations

from ardupilot_support import GUIDED, TAKEOFF_ALT, collect, settle, truth_vs_estimate


def launch(ap) -> None:
    ap.wait_for_gps(120)
    ap.mode(GUIDED)
    ap.arm()
    ap.takeoff()


def test_flyloop_survives_a_killed_ardupilot_and_flies_the_next_one(pair):
    flyloop = pair.flyloop()
    first = pair.ardupilot(flyloop)
    launch(first)
    first.wait_for("climbing past 2 m", lambda m: m.relative_alt > 2000, 60, "GLOBAL_POSITION_INT")
    first.kill()  # mid-flight
    flyloop.wait_for_log("no servo packet from ArduPilot", 10)
    assert flyloop.proc.poll() is None, "flyloop-sitl died with ArduPilot"

    second = pair.ardupilot(flyloop)
    launch(second)
    settle(second, 0.0, 0.0, TAKEOFF_ALT, 0.5, 60)
    hold = collect(second, 1.0)
    flyloop.wait_for_log("ArduPilot restarted", 1)
    second.kill()
    flyloop.stop()
    rows = flyloop.rows()
    # The second flight started from the start state of the first: on its feet at home.
    starts = [next(r for r in rows if r["connection"] == c) for c in (1, 2)]
    assert starts[0] == {**starts[1], "connection": 1.0}, starts
    assert starts[1]["grounded"] == 1.0 and starts[1]["north"] == 0.0
    # Killed in the air.
    assert min(r["down"] for r in rows if r["connection"] == 1) < starts[0]["down"] - 1.5
    # The second ArduPilot flew it to the takeoff height: truth where ArduPilot believes it is.
    error = truth_vs_estimate(rows, hold, 2)
    assert error < 0.5, f"truth vs estimate {error:.3f} m"
    assert int(flyloop.counters()["connections"]) == 2
