"""docs/view.md's recording of an ArduPilot flight: flyloop-sitl --ardupilot --record writes
the .tlog of every mode: per frame the truth, the motor outputs ArduCopter sent
(SERVO_OUTPUT_RAW), the wind and the IMU sample of the JSON line (HIL_SENSOR). ArduCopter
takes off to 5 m; the recording must hold every step, its truth must equal the --track CSV's,
and it must replay into the view and plot."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
from ardupilot_support import GUIDED, TAKEOFF_ALT, settle
from flyloop.plot import series_of

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "view"))
from tlog import statustexts, tlog_by_type  # noqa: E402


def test_ardupilot_takeoff_recorded_with_outputs_imu_and_truth(pair, tmp_path):
    tlog = tmp_path / "ap.tlog"
    flyloop = pair.flyloop("--record", str(tlog), "--track-interval-us", "1")
    ap = pair.ardupilot(flyloop)
    ap.wait_for_gps(120)
    ap.mode(GUIDED)
    ap.arm()
    ap.takeoff()
    settle(ap, 0.0, 0.0, TAKEOFF_ALT, 0.3, 60)
    assert flyloop.stop() == 0, flyloop.stderr()
    rows = flyloop.rows()

    by_type = tlog_by_type(tlog)
    states, servo, imu = (
        by_type["HIL_STATE_QUATERNION"],
        by_type["SERVO_OUTPUT_RAW"],
        by_type["HIL_SENSOR"],
    )
    # Every frame ArduCopter stepped: one state, its motor outputs, the wind, the IMU sample.
    n = len(states)
    assert n == len(servo) == len(by_type["WIND_COV"]) == len(imu) > 5000
    assert len(by_type["HOME_POSITION"]) == 1
    assert [t for t, _ in states] == [int(r["time_us"]) for r in rows]
    # Its motor outputs (PWM µs, ArduCopter's 1000-2000 range), spun up to fly.
    pwm = np.array([[m.servo1_raw, m.servo2_raw, m.servo3_raw, m.servo4_raw] for _, m in servo])
    assert pwm.min() >= 1000 and pwm.max() > 1300
    assert all(m.servo5_raw == 0 for _, m in servo)
    # The IMU sample: about -g on z at rest (FRD specific force); accel and gyro flagged.
    assert abs(imu[0][1].zacc + 9.81) < 0.5 and imu[0][1].fields_updated == 0x3F

    # flyloop's own line, as STATUSTEXT from its system 250 (the fleet's): ArduPilot connected.
    lines = statustexts(by_type)
    assert [(s, text) for _, s, text in lines] == [(250, "ArduPilot: connection 1: in lockstep")]
    assert lines[0][0] <= states[0][0]

    # The truth equals the track's (mm against the CSV's 0.1 mm) at every step.
    ground = by_type["HOME_POSITION"][0][1].altitude / 1000
    down = np.array([-(m.alt / 1000 - ground) for _, m in states])
    assert np.abs(down - np.array([r["down"] for r in rows])).max() < 0.002
    assert -down.min() > TAKEOFF_ALT - 0.5

    # It replays into the view (its series) and plots.
    series = series_of(tlog)
    t_d, d = series["/position/vehicle1/D/truth"]
    assert len(t_d) == n and -d.min() > TAKEOFF_ALT - 0.5
    png = tmp_path / "ap_tlog.png"
    plot = [sys.executable, "-m", "flyloop.plot", str(tlog), "-o", str(png)]
    plotted = subprocess.run(plot, capture_output=True, text=True, timeout=120)
    assert plotted.returncode == 0 and png.stat().st_size > 20_000, plotted.stderr
