"""ArduPilot's estimate against flyloop's truth over a 5-minute flight: GUIDED takeoff to 5 m,
four 10 m legs around a square with holds, LAND, ArduPilot's own disarm and 60 s on the
ground. Every GLOBAL_POSITION_INT from arming to the end is compared with flyloop's track at
the same instant (ArduPilot's clock is flyloop's physics time), in flyloop's frame (ArduPilot's
latitude, longitude and altitude above mean sea level against the home both count from; no
fitted offset): height within 0.15 m, horizontal position within 0.3 m, throughout.

With FLYLOOP_ESTIMATE_OUT=DIR the test also writes DIR/ardupilot_estimate.csv and .png (the
plot in docs/ardupilot.md, drawn by examples/estimate_plot.py); FLYLOOP_ESTIMATE_CONFIG=FILE
flies flyloop with `--config FILE`."""

from __future__ import annotations

from ardupilot_support import GUIDED, LAND, TAKEOFF_ALT, ned_of
from estimate_record import Recorder, check_flight, compare, fly_square, flyloop_args


def test_ardupilot_estimate_follows_flyloops_truth_for_5_minutes(pair):
    flyloop = pair.flyloop(*flyloop_args())
    ap = pair.ardupilot(flyloop)
    recorder = Recorder(
        ap.link,
        "GLOBAL_POSITION_INT",
        lambda m: (m.time_boot_ms, *ned_of(m.lat * 1e-7, m.lon * 1e-7, m.alt * 1e-3)),
    )
    ap.wait_for_gps(120)
    ap.mode(GUIDED)
    ap.arm()
    armed_ms = recorder.now_ms()
    ap.takeoff()
    fly_square(ap, recorder, lambda n, e: ap.goto(n, e, TAKEOFF_ALT), lambda: ap.mode(LAND))
    flyloop.stop()
    track = [r for r in flyloop.rows() if r["connection"] == 1]
    flight = compare(track, recorder.samples, armed_ms)

    check_flight(flight, "ArduPilot", TAKEOFF_ALT)
