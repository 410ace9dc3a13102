"""docs/view.md's recording of a PX4 flight: flyloop-sitl --px4 --record writes the .tlog of
lockstep and real time, plus what PX4 sent (HIL_ACTUATOR_CONTROLS) and the sensor samples it
got (HIL_SENSOR, HIL_GPS). PX4 takes off to 5 m; the recording must hold every step, its truth
must equal the --track CSV's, its motor commands PX4's controls, and it must replay into the
view and plot."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
from flyloop.plot import series_of
from px4_support import TAKEOFF_ALT, settle

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "view"))
from tlog import statustexts, tlog_by_type  # noqa: E402

STEP_US = 4000


def test_px4_takeoff_recorded_with_controls_sensors_and_truth(pair, tmp_path):
    tlog = tmp_path / "px4.tlog"
    flyloop = pair.flyloop("--record", str(tlog), "--track-interval-us", str(STEP_US))
    px4 = pair.px4()
    px4.heartbeat(60)
    px4.arm_and_take_off(60)
    home = px4.home()
    settle(px4, (home[0], home[1], home[2] - TAKEOFF_ALT), 0.3, 60)
    assert flyloop.stop() == 0, flyloop.stderr()
    rows = flyloop.rows()

    by_type = tlog_by_type(tlog)
    controls, servo = by_type["HIL_ACTUATOR_CONTROLS"], by_type["SERVO_OUTPUT_RAW"]
    states, sensors = by_type["HIL_STATE_QUATERNION"], by_type["HIL_SENSOR"]
    # Every step: one state, one motor command, one wind, one IMU/baro/mag sample; a GPS fix
    # every 100 ms (the sensors' default 10 Hz); one controls message per lockstep step.
    n = len(states)
    assert n == len(servo) == len(by_type["WIND_COV"]) == len(sensors) > 2000
    assert abs(len(by_type["HIL_GPS"]) - n * STEP_US / 100_000) <= 2
    assert len(controls) > 0.9 * n
    assert len(by_type["HOME_POSITION"]) == 1
    assert np.all(np.diff([t for t, _ in states]) == STEP_US)

    # The motor command is PX4's controls of the step before: 1000 + 1000 c µs, motors 1-4.
    command_at = {t + STEP_US: m.controls[:4] for t, m in controls}
    pairs = [(command_at[t], m) for t, m in servo if t in command_at]
    assert len(pairs) == len(controls)
    want = np.array([[round(1000 + 1000 * min(max(c, 0.0), 1.0)) for c in cs] for cs, _ in pairs])
    got = np.array([[m.servo1_raw, m.servo2_raw, m.servo3_raw, m.servo4_raw] for _, m in pairs])
    assert np.array_equal(want, got)
    assert got.max() > 1300, "PX4 spun the motors up"

    # flyloop's own line, as STATUSTEXT from its system 250 (the fleet's), at its time: PX4's
    # first controls, the start of lockstep.
    lines = statustexts(by_type)
    first = controls[0][0]
    said = f"PX4: first controls at t={first / 1e6:.3f} s: in lockstep"
    assert lines == [(first, 250, said)], lines

    # The truth equals the track's (1e-7 deg, mm against the CSV's 0.1 mm) at every row.
    alt = {t: m.alt / 1000 for t, m in states}
    ground = by_type["HOME_POSITION"][0][1].altitude / 1000  # the local origin (down = 0)
    gap = [abs(-(alt[int(r["time_us"])] - ground) - r["down"]) for r in rows if r["time_us"] in alt]
    assert len(gap) > 0.9 * n and max(gap) < 0.02, max(gap)
    assert max(alt.values()) - ground > TAKEOFF_ALT - 0.5
    # The IMU sample at rest: about -g on z (FRD specific force).
    assert abs(sensors[0][1].zacc + 9.81) < 0.5

    # It replays into the view (its series) and plots.
    series = series_of(tlog)
    t_d, d = series["/position/vehicle1/D/truth"]
    assert len(t_d) == n and -d.min() > TAKEOFF_ALT - 0.5
    t_m, m0 = series["/motors/vehicle1_command/m0"]
    assert len(t_m) == n and m0.max() > 0.3
    t_a, acc_z = series["/sensors/vehicle1/accel/z"]
    assert len(t_a) == n and np.array_equal(acc_z, [m.zacc for _, m in sensors])
    png = tmp_path / "px4_tlog.png"
    plot = [sys.executable, "-m", "flyloop.plot", str(tlog), "-o", str(png)]
    plotted = subprocess.run(plot, capture_output=True, text=True, timeout=120)
    assert plotted.returncode == 0 and png.stat().st_size > 20_000, plotted.stderr
