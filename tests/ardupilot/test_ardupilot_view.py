"""docs/view.md's ArduPilot flight in the live view: flyloop-sitl --ardupilot --view sends the
truth, ArduCopter sends its own telemetry to a UDP port (--serial1 udpclient:...) where
`python -m flyloop.view` listens; ArduPilot takes off to 5 m. The view's recording must hold
both, the estimate beside the truth (height within 0.5 m once above 1 m)."""

from __future__ import annotations

import signal
import socket
import subprocess
import sys
from pathlib import Path

import numpy as np
from ardupilot_support import GUIDED, TAKEOFF_ALT, settle
from flyloop.plot import series_of

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "view"))
from flight import free_port  # noqa: E402


def test_ardupilot_takeoff_in_the_live_view_with_the_estimate_beside_the_truth(pair, tmp_path):
    truth, estimate = free_port(), free_port()
    flyloop = pair.flyloop("--view", f"127.0.0.1:{truth}")
    web, grpc = free_port(socket.SOCK_STREAM), free_port(socket.SOCK_STREAM)
    view = subprocess.Popen(
        [
            sys.executable, "-m", "flyloop.view",
            "--listen", f"127.0.0.1:{truth}", "--listen", f"127.0.0.1:{estimate}",
            "--web-port", str(web), "--grpc-port", str(grpc),
            "--save", str(tmp_path / "ap.rrd"), "--wait", "180",
        ],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
    )  # fmt: skip
    try:
        ap = pair.ardupilot(flyloop, "--serial1", f"udpclient:127.0.0.1:{estimate}")
        ap.wait_for_gps(120)
        ap.mode(GUIDED)
        ap.arm()
        ap.takeoff()
        settle(ap, 0.0, 0.0, TAKEOFF_ALT, 0.3, 60)
    finally:
        view.send_signal(signal.SIGINT)
        view.wait(timeout=20)
    assert view.returncode == 0, view.stderr.read()

    series = series_of(tmp_path / "ap.rrd")
    t_true, d_true = series["/position/vehicle1/D/truth"]
    t_est, d_est = series["/position/vehicle1/D/estimate"]
    assert len(t_true) > 100 and len(t_est) > 50, (len(t_true), len(t_est))
    # Where both were drawn (under load the view may stop with one stream behind the other).
    both = t_est <= t_true[-1]
    up = t_est[both & (-d_est > 1.0)]
    assert len(up) > 20
    gap = np.abs(np.interp(up, t_est, d_est) - np.interp(up, t_true, d_true))
    assert gap.max() < 0.5, gap.max()
    assert -d_true.min() > TAKEOFF_ALT - 0.5
