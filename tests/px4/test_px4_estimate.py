"""PX4's estimate against flyloop's truth over a 5-minute flight: takeoff to 5 m, four 10 m
legs around a square with holds, landing, the automatic disarm and 60 s on the ground. Every
LOCAL_POSITION_NED from arming to the end is compared with flyloop's track at the same instant
(PX4's clock is flyloop's simulation time), in flyloop's frame through the origin PX4 reports:
height within 0.15 m, horizontal position within 0.3 m, throughout.

With FLYLOOP_ESTIMATE_OUT=DIR the test also writes DIR/px4_estimate.csv and .png (the plot
in docs/px4.md, drawn by examples/estimate_plot.py); FLYLOOP_ESTIMATE_CONFIG=FILE flies
flyloop with `--config FILE` instead of the Iris preset (e.g. the preset with another sensor
parameter, to see its effect)."""

from __future__ import annotations

from estimate_record import Recorder, check_flight, compare, fly_square, flyloop_args
from px4_support import TAKEOFF_ALT


def test_px4_estimate_follows_flyloops_truth_for_5_minutes(pair):
    flyloop = pair.flyloop(*flyloop_args())
    # PX4's stock 10 s of GPS health before its estimator counts as ready (its SITL start-up
    # shortens it to 0.5 s): armed earlier, the estimate is still settling from the first
    # GPS fixes (one run: armed at 4 s, 0.11 m off; with 10 s, armed at 6.7 s, 0.003 m off).
    px4 = pair.px4(EKF2_REQ_GPS_H=10)
    px4.heartbeat(60)
    recorder = Recorder(px4.link, "LOCAL_POSITION_NED", lambda m: (m.time_boot_ms, m.x, m.y, m.z))

    px4.arm_when_ready(90)
    armed_ms = recorder.now_ms()
    px4.takeoff()
    frame = px4.frame()
    home = px4.home()
    fly_square(
        px4,
        recorder,
        lambda n, e: px4.goto(frame, (home[0] + n, home[1] + e, home[2] - TAKEOFF_ALT)),
        px4.land,
    )
    flyloop.stop()
    track = [r for r in flyloop.rows() if r["connection"] == 1]
    # PX4's local frame → flyloop's, through the origin PX4 reports (no fitted offset).
    samples = [(t, *frame.to_flyloop((x, y, z))) for t, x, y, z in recorder.samples]
    flight = compare(track, samples, armed_ms)

    check_flight(flight, "PX4", TAKEOFF_ALT)
