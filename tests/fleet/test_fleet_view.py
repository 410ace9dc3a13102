"""docs/view.md's fleet in the live view and the recording: flyloop-sitl flies 2 PX4s in one
world with --view and --record; `python -m flyloop.view` hears every vehicle's truth on one
port and talks to each PX4's ground-station port for its estimate (told apart by system id).
Headless Chromium must draw both vehicles; the recording must hold both vehicles' truth at
every world step (equal to the --track's, and to what the view drew at its times), each
PX4's sensor samples, and the collision when one is sent into the other, and the view must
show it."""

from __future__ import annotations

import signal
import socket
import subprocess
import sys
from pathlib import Path

import numpy as np
from ardupilot_support import ArduPilot, ardupilot_ports_free
from ardupilot_support import collect as ap_collect
from fleet_support import HOME, FleetSitl, free_block, read_track
from flyloop.plot import series_of
from flyloop.view.screenshot import Browser, hub_pixels
from px4_support import Px4, collect, fresh_dir, launch, px4_ports_free, settle
from test_fleet_mixed import quiet
from test_fleet_px4 import start_fleet

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "view"))
from flight import free_port  # noqa: E402
from test_view_fleet import clusters  # noqa: E402
from tlog import statustexts, tlog_by_type  # noqa: E402

STEP_US = 4000
FLEET_SYSTEM = 250


def stop_view(view: subprocess.Popen) -> None:
    """Ctrl-C to the view and its exit. It writes out what it logged before it exits: on a
    loaded machine Rerun's encoder runs tens of seconds behind a fleet's stream, so give it
    two minutes; past that the view is killed and the failure holds its last words."""
    view.send_signal(signal.SIGINT)
    try:
        view.wait(timeout=120)
    except subprocess.TimeoutExpired:
        view.kill()
        _, err = view.communicate()
        why = f"the view did not exit within 120 s of Ctrl-C: {err[-2000:]}"
        raise AssertionError(why) from None


def test_two_px4s_in_the_view_and_the_recording_with_their_collision(
    started, sitl_binary, px4_dir, tmp_path
):
    truth_port = free_port()
    tlog, rrd, track = tmp_path / "fleet.tlog", tmp_path / "fleet.rrd", tmp_path / "track.csv"
    view_args = ["--view", f"127.0.0.1:{truth_port}", "--record", str(tlog), "--track", str(track)]
    sitl, (a, b) = start_fleet(started, sitl_binary, px4_dir, 2, *view_args, speed=1)
    web, grpc = free_port(socket.SOCK_STREAM), free_port(socket.SOCK_STREAM)
    view = subprocess.Popen(
        [
            sys.executable, "-m", "flyloop.view",
            "--listen", f"127.0.0.1:{truth_port}",
            "--connect", f"127.0.0.1:{18570 + a.instance}",
            "--connect", f"127.0.0.1:{18570 + b.instance}",
            "--web-port", str(web), "--grpc-port", str(grpc),
            "--save", str(rrd), "--wait", "120",
        ],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
    )  # fmt: skip
    try:
        url = view.stdout.readline().split("open ", 1)[1].strip()
        frame_a, target_a = launch(a)
        frame_b, target_b = launch(b)
        browser = Browser()
        try:
            browser.open(url)
            # Both hubs drawn apart (the viewer ingests in order: wait for every one).
            shot, _ = browser.wait_for_vehicle(60, timeout=120, until=lambda p: clusters(p) == 2)
            settle(a, target_a, 0.3, 90)
            settle(b, target_b, 0.3, 90)
            air, _ = browser.wait_for_vehicle(60, timeout=60, until=lambda p: clusters(p) == 2)
            (tmp_path / "fleet_px4.png").write_bytes(air)
        finally:
            browser.close()
        hover_a = collect(a, 1.0).estimate[-1]
        # b flies to where a hovers.
        b.goto(frame_b, frame_b.from_global(*frame_a.to_global(target_a)))
        sitl.statustext("collision px4-000 px4-001", 60)
    finally:
        try:
            stop_view(view)
        finally:
            sitl.stop()
    assert view.returncode == 0, view.stderr.read()
    assert clusters(hub_pixels(shot)) == 2 and clusters(hub_pixels(air)) == 2, tmp_path

    # The vehicles' system ids: PX4 instance i's, i + 1 (the fleet takes them from the ports).
    one, two = systems = (a.target, b.target)
    by_type = tlog_by_type(tlog)
    states: dict[int, list] = {one: [], two: []}
    for t, m in by_type["HIL_STATE_QUATERNION"]:
        states[m.get_srcSystem()].append((t, m))
    homes = {m.get_srcSystem(): m for _, m in by_type["HOME_POSITION"]}
    assert sorted(homes) == sorted(systems)
    # Every world step holds both vehicles' truth: the same times for both.
    times = {s: [t for t, _ in states[s]] for s in states}
    assert times[one] == times[two] and len(times[one]) > 5000
    assert np.all(np.diff(times[one]) > 0)
    # Each PX4's sensor samples under its own system id, one per step of its own.
    sensors = {s: [t for t, m in by_type["HIL_SENSOR"] if m.get_srcSystem() == s] for s in systems}
    for s in systems:
        assert len(sensors[s]) > 0.4 * len(times[s]), (s, len(sensors[s]))
        assert set(np.diff(sensors[s][-500:])) == {STEP_US}
    # The truth equals the track's (mm against the CSV's 0.1 mm) at every row of each vehicle.
    ground = homes[one].altitude / 1000
    for s, rows in zip(systems, read_track(track).values(), strict=True):
        down = {t: -(m.alt / 1000 - ground) for t, m in states[s]}
        gap = [abs(down[int(r["time_us"])] - r["down"]) for r in rows if r["time_us"] in down]
        assert len(gap) > 0.9 * len(rows) and max(gap) < 0.002, (s, len(gap), max(gap))
    # Both climbed to the takeoff height; a hovered where PX4 estimated it (its local frame).
    height = {s: np.array([m.alt / 1000 - ground for _, m in states[s]]) for s in systems}
    assert height[one].max() > 4.5 and height[two].max() > 4.5
    # PX4's height through the origin it reports: its local z = 0 is where its estimator
    # started, up to ~1 m off the ground when it arms early (1.05 m in one CI run).
    at_hover = np.searchsorted(times[one], hover_a[0] * 1000)
    down_a = frame_a.to_flyloop((0.0, 0.0, hover_a[3]))[2]
    assert abs(height[one][min(at_hover, len(times[one]) - 1)] + down_a) < 0.5

    # The collision: a NAMED_VALUE_FLOAT from each vehicle, the fleet's line as STATUSTEXT.
    hits = [(m.get_srcSystem(), m.value) for _, m in by_type["NAMED_VALUE_FLOAT"]]
    assert {s for s, _ in hits} == set(systems) and all(v > 0 for _, v in hits)
    lines = [text for _, s, text in statustexts(by_type) if s == FLEET_SYSTEM]
    assert any(t.startswith("collision px4-000 px4-001 at t=") for t in lines), lines
    assert any("PX4 connected" in t for t in lines), lines

    # The view drew what the recording holds: both truths equal at the view's times, each
    # PX4's estimate beside its truth, and the collision.
    series = series_of(rrd)
    for s in systems:
        t_view, d_view = series[f"/position/vehicle{s}/D/truth"]
        recorded = {t: -(m.alt / 1000 - ground) for t, m in states[s]}
        shared = [(d, recorded[round(t * 1e6)]) for t, d in zip(t_view, d_view, strict=True)
                  if round(t * 1e6) in recorded]  # fmt: skip
        assert len(shared) > 500, (s, len(shared))
        assert all(v == r for v, r in shared), s
        _, d_est = series[f"/position/vehicle{s}/D/estimate"]
        assert len(d_est) > 100 and -d_est.min() > 4.0
    # The view is fed over UDP: on a loaded machine (load 25 on 2 cores) it falls behind and
    # the kernel drops datagrams (once, one vehicle's collision); the .tlog has them all.
    assert any(f"/task/vehicle{s}/collision_speed" in series for s in systems)

    # The recording replays into the view: both vehicles and the collision.
    replayed = series_of(tlog)
    for s in systems:
        assert len(replayed[f"/position/vehicle{s}/D/truth"][0]) == len(times[s])
        assert len(replayed[f"/sensors/vehicle{s}/accel/z"][0]) == len(sensors[s])
        assert f"/task/vehicle{s}/collision_speed" in replayed


AP_SYSID = 240


def test_a_px4_and_an_ardupilot_in_the_view_and_the_recording(
    started, sitl_binary, px4_dir, ardupilot, tmp_path
):
    """A fleet file with one PX4 and one ArduPilot, 4 m apart on the ground: Chromium draws
    both hubs, the .tlog holds both truths at every world step (each equal to the --track's)
    with each autopilot's sensor samples and the fleet's lines, and the view's .rrd holds
    each autopilot's estimate beside its truth (PX4's from its ground-station port,
    ArduPilot's from its --serial1 telemetry)."""
    px4_base = free_block(1, px4_ports_free, 10, 150)
    ap_base = free_block(1, ardupilot_ports_free, 3, 150)
    fleet = tmp_path / "fleet.toml"
    fleet.write_text(
        f'[[vehicle]]\nautopilot = "px4"\ninstance = {px4_base}\nposition = [0.0, 0.0]\n\n'
        f'[[vehicle]]\nautopilot = "ardupilot"\ninstance = {ap_base}\nsysid = {AP_SYSID}\n'
        "position = [0.0, 4.0]\n"
    )
    truth_port, ap_port = free_port(), free_port()
    tlog, rrd, track = tmp_path / "fleet.tlog", tmp_path / "fleet.rrd", tmp_path / "track.csv"
    sitl = FleetSitl(
        sitl_binary, fresh_dir("flyloop-fleet-view-mixed-"), "--fleet", str(fleet),
        "--view", f"127.0.0.1:{truth_port}", "--record", str(tlog), "--track", str(track),
        speed=1,
    )  # fmt: skip
    started.append(sitl)
    web, grpc = free_port(socket.SOCK_STREAM), free_port(socket.SOCK_STREAM)
    view = subprocess.Popen(
        [
            sys.executable, "-m", "flyloop.view",
            "--listen", f"127.0.0.1:{truth_port}", "--listen", f"127.0.0.1:{ap_port}",
            "--connect", f"127.0.0.1:{18570 + px4_base}",
            "--web-port", str(web), "--grpc-port", str(grpc),
            "--save", str(rrd), "--wait", "120",
        ],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
    )  # fmt: skip
    try:
        url = view.stdout.readline().split("open ", 1)[1].strip()
        px4 = Px4(px4_dir, px4_base, fresh_dir("px4-fleet-view-mixed-"))
        started.append(px4)
        home = ",".join(str(v) for v in HOME)
        ap = ArduPilot(
            ardupilot, ap_base, 9002 + 10 * ap_base, fresh_dir("ap-fleet-view-mixed-"),
            "--home", home, "--sysid", str(AP_SYSID),
            "--serial1", f"udpclient:127.0.0.1:{ap_port}",
        )  # fmt: skip
        started.append(ap)
        px4.heartbeat(120)
        ap.connect(60)
        quiet(ap)
        browser = Browser()
        try:
            browser.open(url)
            shot, _ = browser.wait_for_vehicle(60, timeout=120, until=lambda p: clusters(p) == 2)
            (tmp_path / "fleet_mixed.png").write_bytes(shot)
        finally:
            browser.close()
        # ArduPilot reports a local position (its estimate's) once its EKF has a GPS origin,
        # ~40 s into the flight: from then on for 2 s.
        ap.wait_for_gps(240)  # wall seconds: a loaded machine runs the world slower
        ap_collect(ap, 2.0)
    finally:
        try:
            stop_view(view)
        finally:
            sitl.stop()
    assert view.returncode == 0, view.stderr.read()
    assert clusters(hub_pixels(shot)) == 2, tmp_path

    systems = (px4.target, AP_SYSID)
    by_type = tlog_by_type(tlog)
    states: dict[int, list] = {s: [] for s in systems}
    for t, m in by_type["HIL_STATE_QUATERNION"]:
        states[m.get_srcSystem()].append((t, m))
    homes = {m.get_srcSystem(): m for _, m in by_type["HOME_POSITION"]}
    assert sorted(homes) == sorted(systems)
    # Every world step holds both vehicles' truth: the same times for both.
    times = {s: [t for t, _ in states[s]] for s in systems}
    assert times[px4.target] == times[AP_SYSID] and len(times[AP_SYSID]) > 5000
    # Each autopilot's sensor samples under its own system id, from its connection on: PX4's
    # one per 4 ms step, ArduPilot's IMU one per step it was due.
    sensors = {s: [t for t, m in by_type["HIL_SENSOR"] if m.get_srcSystem() == s] for s in systems}
    assert min(len(sensors[s]) for s in systems) > 1000, {s: len(v) for s, v in sensors.items()}
    assert set(np.diff(sensors[px4.target][-500:])) == {STEP_US}
    assert np.all(np.diff(sensors[AP_SYSID]) > 0)
    # The truth equals the track's at every row of each vehicle; the two stand 4 m apart.
    ground = homes[px4.target].altitude / 1000
    tracks = read_track(track)
    names = {px4.target: f"px4-{px4_base:03d}", AP_SYSID: f"ardupilot-{ap_base:03d}"}
    assert sorted(tracks) == sorted(names.values())
    for s in systems:
        rows = tracks[names[s]]
        down = {t: -(m.alt / 1000 - ground) for t, m in states[s]}
        gap = [abs(down[int(r["time_us"])] - r["down"]) for r in rows if r["time_us"] in down]
        assert len(gap) > 0.9 * len(rows) and max(gap) < 0.002, (s, len(gap), max(gap))
    last = {s: tracks[names[s]][-1] for s in systems}
    north = last[AP_SYSID]["north"] - last[px4.target]["north"]
    assert abs(north - 4.0) < 0.2, last  # the fleet file's position = [north, east]
    (_, a), (_, b) = states[px4.target][-1], states[AP_SYSID][-1]
    # 1e-7 degree of latitude is 11.13 mm.
    apart = np.hypot(
        (a.lat - b.lat) * 0.01113, (a.lon - b.lon) * 0.01113 * np.cos(np.radians(47.4))
    )
    assert abs(apart - 4.0) < 0.2, apart
    lines = [text for _, s, text in statustexts(by_type) if s == FLEET_SYSTEM]
    assert any("PX4 connected" in t for t in lines), lines
    assert any("ArduPilot connected" in t for t in lines), lines

    # The view drew both truths and each autopilot's estimate beside its truth (both on the
    # ground: their heights within 0.5 m); ArduPilot's from its GPS origin on only.
    series = series_of(rrd)
    for s, least in ((px4.target, 100), (AP_SYSID, 20)):
        t_true, d_true = series[f"/position/vehicle{s}/D/truth"]
        t_est, d_est = series[f"/position/vehicle{s}/D/estimate"]
        assert len(t_true) > 1000 and len(t_est) >= least, (s, len(t_true), len(t_est))
        both = t_est <= t_true[-1]
        gap = np.abs(d_est[both] - np.interp(t_est[both], t_true, d_true))
        assert gap.max() < 0.5, (s, gap.max())
