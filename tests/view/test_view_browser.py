"""The live view as a person sees it: a SITL flight, `python -m flyloop.view`, Debian's
Chromium (headless, SwiftShader) on the printed URL. The vehicle's hub must be drawn (a pixel
count that is 0 without it) and move up the screen as the vehicle climbs; the view's own
recording, replayed in a second view, must show it again and hold the same frames as the
flight (every sample equal to the ground truth the controller got at that time)."""

from __future__ import annotations

import time

import numpy as np
import pytest
from flight import Flight, View, free_port, rise
from flyloop import find_sitl_binary
from flyloop.plot import series_of
from flyloop.view.screenshot import Browser, hub_pixels

MIN_PIXELS = 30


@pytest.fixture(scope="module")
def binary():
    return find_sitl_binary(build=True)


def test_live_view_draws_the_vehicle_where_it_is_and_replays(binary, tmp_path):
    gcs = free_port()
    view = View(
        "--listen", f"127.0.0.1:{gcs}", "--save", str(tmp_path / "live.rrd"), "--wait", "120"
    )
    flight = Flight(binary, gcs, record=tmp_path / "run.tlog")
    browser = Browser()
    try:
        _fly_watch_and_replay(browser, view, flight, tmp_path)
    finally:  # a failed check must not leave the page open: the next test needs the loop
        browser.close()


def _fly_watch_and_replay(browser, view, flight, tmp_path) -> None:
    try:
        browser.open(view.url)
        low, n_low = browser.wait_for_vehicle(MIN_PIXELS, timeout=90)  # the wasm loads (~20 s)
        (tmp_path / "low.png").write_bytes(low)
        assert n_low >= MIN_PIXELS, f"no vehicle drawn ({n_low} hub pixels): {tmp_path / 'low.png'}"
        flight.fly_to([0.0, 0.0, -4.0])  # climb from 1.5 m to 4 m
        deadline = time.monotonic() + 30
        while time.monotonic() < deadline and -flight.truth[-1][1][2] < 3.8:
            time.sleep(0.2)
        # Up the screen: the hub's centre rises by more than 40 px (of 720) for 2.5 m.
        risen, high = rise(browser, hub_pixels(low)[:, 0], 40, timeout=120)
        (tmp_path / "high.png").write_bytes(high)
        assert risen > 40, f"the vehicle rose {risen:.0f} px on the screen: {tmp_path / 'high.png'}"
    finally:
        flight.stop()
        code, err = view.stop()
    assert code == 0, err
    truth = {t: p for t, p in flight.truth}

    # The view's recording holds the flight's frames: each sample is the truth at its time.
    live = series_of(tmp_path / "live.rrd")
    t, north = live["/position/vehicle1/N/truth"]
    _, down = live["/position/vehicle1/D/truth"]
    assert len(t) > 100
    for ts, n, d in zip(t, north, down, strict=True):
        n_true, _, d_true = truth[round(ts * 1e6)]
        assert (n, d) == pytest.approx((n_true, d_true), abs=1e-9)
    # The SITL's own recording holds every step, each equal to the reply the controller got.
    rec = series_of(tmp_path / "run.tlog")
    t_rec, d_rec = rec["/position/vehicle1/D/truth"]
    steps = sorted(truth)
    assert [round(x * 1e6) for x in t_rec[-len(steps) :]] == steps
    np.testing.assert_allclose(
        d_rec[-len(steps) :], [truth[s][2] for s in steps], rtol=0, atol=1e-9
    )

    # The recording replays in the same view.
    replay = View(str(tmp_path / "live.rrd"))
    try:
        browser.open(replay.url)
        shot, n = browser.wait_for_vehicle(MIN_PIXELS, timeout=90)
        (tmp_path / "replay.png").write_bytes(shot)
        assert n >= MIN_PIXELS, f"the replay draws no vehicle: {tmp_path / 'replay.png'}"
    finally:
        replay.stop()
