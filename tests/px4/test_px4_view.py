"""docs/view.md's PX4 flight in the live view: flyloop-sitl --px4 --view sends the truth,
`python -m flyloop.view` talks to PX4's ground-station port for its estimate; PX4 takes off.
The view's recording must hold both, the estimate beside the truth (within 0.3 m once
airborne), and the browser must draw the vehicle."""

from __future__ import annotations

import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
from flyloop.plot import series_of, series_of_ulg
from flyloop.view.screenshot import Browser, hub_pixels
from px4_support import TAKEOFF_ALT, settle

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "view"))
from flight import free_port, rise  # noqa: E402


def airborne(times, t_true, d_true):
    """Those of `times` within the truth's span at which the truth is above 1 m. By the truth,
    not the estimate: PX4's estimate dips to 1.2 m up for a moment as it starts (its log holds
    it from 0.9 s), which once counted as airborne, 0.95-1.17 m from the truth."""
    inside = times[(times >= t_true[0]) & (times <= t_true[-1])]
    return inside[-np.interp(inside, t_true, d_true) > 1.0]


def test_px4_takeoff_in_the_live_view_with_the_estimate_beside_the_truth(pair, tmp_path):
    truth_port = free_port()
    # At real time, as docs/view.md watches it. At 4x, PX4 took most of a loaded machine's
    # CPU and the viewer, starved, drew the flight ever further behind (93 s, and 147 s when
    # opened after PX4 started), never showing the climb.
    flyloop = pair.flyloop("--view", f"127.0.0.1:{truth_port}", speed=1)
    web, grpc = free_port(socket.SOCK_STREAM), free_port(socket.SOCK_STREAM)
    view = subprocess.Popen(
        [
            sys.executable, "-m", "flyloop.view",
            "--listen", f"127.0.0.1:{truth_port}",
            "--connect", f"127.0.0.1:{18570 + pair.number}",
            "--web-port", str(web), "--grpc-port", str(grpc),
            "--save", str(tmp_path / "px4.rrd"), "--wait", "240",
        ],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
    )  # fmt: skip
    try:
        url = view.stdout.readline().split("open ", 1)[1].strip()
        browser = Browser()
        try:
            # The page loaded before PX4 starts: it then takes the flight in as it comes.
            # Opened once PX4 was up, on a loaded machine it first had a minute of stream to
            # take in a chunk at a time, and it drew the vehicle 147 s behind, still on the
            # ground when the test looked for the climb (docs/view.md, "How far behind").
            browser.open(url)
            assert browser.wait_for_world(timeout=120), "the viewer did not load"
            px4 = pair.px4()
            px4.heartbeat(60)
            # The vehicle on the ground first, then the takeoff (as docs/view.md says to
            # watch): a page that takes in the flight faster than it is screenshotted would
            # otherwise first be seen with the vehicle already up.
            ground, n_ground = browser.wait_for_vehicle(30, timeout=90)
            px4.arm_and_take_off(60)
            frame = px4.frame()
            home = px4.home()
            settle(px4, (home[0], home[1], home[2] - TAKEOFF_ALT), 0.3, 60)
            risen, air = rise(browser, hub_pixels(ground)[:, 0], 40, timeout=90)
            (tmp_path / "px4.png").write_bytes(air)
        finally:
            browser.close()
        # The view's recording is what it drew: on a loaded machine its stream runs seconds
        # behind the flight, so it is given time to draw the rest of the climb.
        time.sleep(10)
    finally:
        view.send_signal(signal.SIGINT)
        view.wait(timeout=20)
        flyloop.stop()
    assert view.returncode == 0, view.stderr.read()
    del frame

    series = series_of(tmp_path / "px4.rrd")
    t_true, d_true = series["/position/vehicle1/D/truth"]
    t_est, d_est = series["/position/vehicle1/D/estimate"]
    assert len(t_true) > 100 and len(t_est) > 100
    # Airborne (above 1 m): the estimate, moved into the truth's frame, beside the truth.
    # Where both were drawn (under load the view may stop with one stream behind the other).
    up = airborne(t_est, t_true, d_true)
    assert len(up) > 50
    truth_at = np.interp(up, t_true, d_true)
    gap = np.abs(np.interp(up, t_est, d_est) - truth_at)
    # 0.06-0.09 m measured once PX4 answers the view's commands; regression: addressed to
    # system 0, PX4 ignored them, the origin never came and the gap was 0.1-0.57 m by run,
    # all flight long. Percentiles, not the maximum: in one CI run on a slow machine (this
    # test 177 s) the gap was ~0.04 m but for one moment of 0.40 m among 10,006 samples.
    assert np.median(gap) < 0.1, np.median(gap)
    assert np.percentile(gap, 99) < 0.3, np.percentile(gap, 99)
    assert -d_true.min() > TAKEOFF_ALT - 0.5
    _, n_estimate = series["/position/vehicle1/N/estimate"]
    assert np.isfinite(n_estimate).all()

    # docs/view.md's plot with PX4's own log (.ulg, written while armed): its estimate beside
    # the truth. Its local frame's origin is where its estimator started, about home: 1 m
    # allowed (0.23 and 0.74 m seen at real time; a frame or unit misread would be metres).
    ulg = sorted((Path(px4.log.name).parent / "log").glob("*/*.ulg"))[-1]
    png = tmp_path / "px4_plot.png"
    plot = ["-m", "flyloop.plot", str(tmp_path / "px4.rrd"), "--ulg", str(ulg), "-o", str(png)]
    plotted = subprocess.run([sys.executable, *plot], capture_output=True, text=True, timeout=120)
    assert plotted.returncode == 0 and png.stat().st_size > 20_000, plotted.stderr
    t_ulg, d_ulg = series_of_ulg(ulg)["/position/vehicle1/D/estimate"]
    up = airborne(t_ulg, t_true, d_true)
    assert len(up) > 100
    gap = np.abs(np.interp(up, t_ulg, d_ulg) - np.interp(up, t_true, d_true))
    assert gap.max() < 1.0, gap.max()
    assert n_ground >= 30, "no vehicle drawn"
    assert risen > 40, f"the vehicle did not take off on the screen: {tmp_path / 'px4.png'}"
