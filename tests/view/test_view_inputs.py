"""The view, the recordings and the plot without a browser: what a recording holds (the SITL's
--record: every step, the same bytes for the same seed and commands; an env's Watch: every
step, equal to the env's info), the plot's PNG, and bad input: one clear line, never a
traceback alone, never a hang."""

from __future__ import annotations

import os
import signal
import socket
import subprocess
import sys
import time

import flyloop  # noqa: F401  (registers the envs)
import gymnasium as gym
import numpy as np
import pytest
from flight import free_port
from flyloop import find_sitl_binary, plot
from flyloop.plot import series_of
from flyloop.view import Viewer, Watch, WatchVector, scene
from flyloop.view.mavlink import MavlinkScene, read_tlog

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "sitl"))
from sitl_client import Client, Sitl, mavlink2  # noqa: E402
from tlog import statustexts, tlog_by_type  # noqa: E402


def run(*args: str, timeout: float = 60, env=None) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, *args], capture_output=True, text=True, timeout=timeout, env=env
    )


@pytest.fixture(scope="module")
def binary():
    return find_sitl_binary(build=True)


def record(binary, path, steps: int = 200) -> list:
    sitl = Sitl(binary, "--gcs", "off", "--record", str(path))
    client = Client(sitl.address)
    try:
        client.reset(5)
        states = []
        for k in range(steps):
            msgs = client.step([0.5, 0.5, 0.5, 0.5] if k < 100 else [0.45, 0.5, 0.45, 0.5])
            states += [m for m in msgs if m.get_type() == "HIL_STATE_QUATERNION"]
    finally:
        client.close()
        assert sitl.stop() == 0
    return states


def test_sitl_recording_holds_every_step_and_is_reproducible(binary, tmp_path):
    states = record(binary, tmp_path / "a.tlog")
    record(binary, tmp_path / "b.tlog")
    a = (tmp_path / "a.tlog").read_bytes()
    assert a == (tmp_path / "b.tlog").read_bytes()
    series = series_of(tmp_path / "a.tlog")
    t, roll = series["/attitude/vehicle1/roll/truth"]
    assert len(t) == 201  # the reset and 200 steps
    assert [round(x * 1e6) for x in t[1:]] == [s.time_usec for s in states]
    _, m0 = series["/motors/vehicle1_command/m0"]
    assert m0[1:101] == pytest.approx(0.5) and m0[101:] == pytest.approx(0.45)
    assert "/task/vehicle1/reward" in series
    # 4 messages per step (motor command, truth, wind, task frame): the size per simulated minute.
    minute = len(a) / (t[-1] - t[0]) * 60
    print(
        f"SITL recording: {len(a)} bytes for {t[-1] - t[0]:.2f} s:"
        f" {minute / 2**20:.2f} MiB per simulated minute"
    )


def test_a_real_time_recording_holds_the_failsafe_line_at_its_step(binary, tmp_path):
    """--record in real time: the line the controller is sent when its commands stop (the
    failsafe) is in the .tlog as STATUSTEXT from the vehicle, at the simulation time of a
    recorded step (pymavlink reads it back)."""
    tlog = tmp_path / "rt.tlog"
    args = ["--realtime", "--failsafe-timeout", "0.3", "--gcs", "off", "--record", str(tlog)]
    sitl = Sitl(binary, *args)
    client = Client(sitl.address)
    try:
        client.param_set("en_crash_det", 0)  # on the ground the episode goes on
        client.reset(1)
        end, hover = time.monotonic() + 0.5, [(9.81 / 40) ** 0.5] * 4
        while time.monotonic() < end:
            client.send_raw(client.controls(hover))
            client.drain(0.02)
        sent = [m for m in client.drain(1.0) if m.get_type() == "STATUSTEXT"]
    finally:
        client.close()
        assert sitl.stop() == 0
    by_type = tlog_by_type(tlog)
    lines = statustexts(by_type)
    failsafe = "vehicle 1: no command for 0.3 s, motors off (failsafe)"
    assert [(system, text) for _, system, text in lines] == [(1, failsafe)], lines
    assert "".join(m.text for m in sent) == failsafe  # what the controller got
    steps = {t for t, _ in by_type["HIL_STATE_QUATERNION"]}
    assert lines[0][0] in steps and 0.5e6 < lines[0][0] < 1.5e6, lines[0][0]


def test_env_watch_records_every_step(tmp_path):
    env = Watch(
        gym.make("flyloop/QuadHover-v0", backend="native", max_steps=300),
        serve=False,
        save=tmp_path / "eval.rrd",
    )
    obs, info = env.reset(seed=1)
    positions = [info["position"]]
    rewards, done = [], False
    while not done:
        obs, reward, terminated, truncated, info = env.step(np.full(4, 0.5, np.float32))
        positions.append(info["position"])
        rewards.append(reward)
        done = terminated or truncated
    env.close()
    series = series_of(tmp_path / "eval.rrd")
    t, up = series["/position/vehicle1/D/truth"]
    assert len(t) == len(positions)
    np.testing.assert_allclose(-up, [p[2] for p in positions], atol=1e-6)
    _, r = series["/task/vehicle1/reward"]
    np.testing.assert_allclose(r, rewards, atol=1e-6)
    assert (tmp_path / "eval.rrd").stat().st_size > 10_000
    # docs/view.md's replay and plot of an evaluation.
    web, grpc = free_port(socket.SOCK_STREAM), free_port(socket.SOCK_STREAM)
    replay = run(
        "-m", "flyloop.view", str(tmp_path / "eval.rrd"), "--seconds", "0",
        "--web-port", str(web), "--grpc-port", str(grpc),
    )  # fmt: skip
    assert replay.returncode == 0 and "replayed" in replay.stdout, replay.stderr
    png = tmp_path / "eval.png"
    plotted = run("-m", "flyloop.plot", str(tmp_path / "eval.rrd"), "-o", str(png))
    assert plotted.returncode == 0 and png.stat().st_size > 20_000, plotted.stderr
    # An env reports no body rates: that panel says so, and no matplotlib warning (a new user's
    # first plot printed "No artists with labels found to put in legend").
    assert "Warning" not in plotted.stderr, plotted.stderr


def test_vector_watch_records_the_chosen_env(tmp_path):
    envs = gym.make_vec(
        "flyloop/QuadHover-v0",
        num_envs=4,
        vectorization_mode="vector_entry_point",
        backend="native",
    )
    envs = WatchVector(envs, index=2, serve=False, save=tmp_path / "vec.rrd")
    obs, infos = envs.reset(seed=0)
    north = [infos["position"][2][1]]
    for _ in range(50):
        obs, rewards, terminated, truncated, infos = envs.step(np.full((4, 4), 0.5, np.float32))
        north.append(infos["position"][2][1])  # ENU y is north
    envs.close()
    t, n = series_of(tmp_path / "vec.rrd")["/position/env2/N/truth"]
    np.testing.assert_allclose(n, north, atol=1e-6)
    assert t[-1] == pytest.approx(0.5)


def test_plot_writes_a_png_of_a_recording(binary, tmp_path):
    record(binary, tmp_path / "run.tlog")
    out = run("-m", "flyloop.plot", str(tmp_path / "run.tlog"), "-o", str(tmp_path / "run.png"))
    assert out.returncode == 0, out.stderr
    from PIL import Image

    img = np.asarray(Image.open(tmp_path / "run.png").convert("RGB"))
    assert img.shape[0] > 600 and (img < 200).any(axis=2).mean() > 0.01  # lines were drawn


@pytest.mark.parametrize(
    "content, expected",
    [
        (b"", "no MAVLink"),
        (b"\x89PNG\r\n\x1a\n" + bytes(range(256)) * 4, "no MAVLink"),
    ],
)
def test_a_foreign_recording_is_one_line(tmp_path, content, expected):
    path = tmp_path / "foreign.tlog"
    path.write_bytes(content)
    for args in (
        ["-m", "flyloop.plot", str(path)],
        ["-m", "flyloop.view", str(path), "--seconds", "0", *free_view_ports()],
    ):
        out = run(*args)
        assert out.returncode == 1 and "Traceback" not in out.stderr, out.stderr
        assert (
            expected in out.stderr
            and str(path) in out.stderr
            and len(out.stderr.strip().splitlines()) == 1
        )


def free_view_ports() -> list[str]:
    """--web-port and --grpc-port on free ports (not 9090/9876: another view may hold them)."""
    web, grpc = free_port(socket.SOCK_STREAM), free_port(socket.SOCK_STREAM)
    return ["--web-port", str(web), "--grpc-port", str(grpc)]


def test_a_view_port_in_use_is_one_line(tmp_path):
    """Regression: with its gRPC port taken (another view), the view printed the SDK's
    errors and a traceback; now one line naming the port and the option."""
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as taken:
        taken.bind(("127.0.0.1", 0))
        taken.listen()
        port = taken.getsockname()[1]
        for option in ("--grpc-port", "--web-port"):
            other = "--web-port" if option == "--grpc-port" else "--grpc-port"
            out = run(
                "-m", "flyloop.view", "--listen", f"127.0.0.1:{free_port()}", "--wait", "1",
                option, str(port), other, str(free_port(socket.SOCK_STREAM)),
            )  # fmt: skip
            assert out.returncode == 1 and "Traceback" not in out.stderr, out.stderr
            assert len(out.stderr.strip().splitlines()) == 1, out.stderr
            assert f"port {port}: Address already in use" in out.stderr, out.stderr
            assert option in out.stderr, out.stderr


def test_a_truncated_recording_replays_what_it_holds(binary, tmp_path):
    record(binary, tmp_path / "full.tlog")
    data = (tmp_path / "full.tlog").read_bytes()
    (tmp_path / "cut.tlog").write_bytes(data[: len(data) // 2 + 7])
    t, _ = series_of(tmp_path / "cut.tlog")["/position/vehicle1/N/truth"]
    assert 90 < len(t) < 110
    bad = tmp_path / "bad.rrd"
    bad.write_bytes(b"RRF2" + bytes(100))
    out = run("-m", "flyloop.plot", str(bad))
    assert out.returncode == 1 and "Traceback" not in out.stderr and str(bad) in out.stderr, (
        out.stderr
    )


def test_a_view_pointed_at_nothing_says_so(tmp_path):
    port = free_port()
    out = run(
        "-m",
        "flyloop.view",
        "--listen",
        f"127.0.0.1:{port}",
        "--wait",
        "1",
        "--web-port",
        str(free_port(socket.SOCK_STREAM)),
        "--grpc-port",
        str(free_port(socket.SOCK_STREAM)),
    )
    assert out.returncode == 1, out.stderr
    assert (
        f"no MAVLink on udp 127.0.0.1:{port} within 1 s" in out.stderr
        and "Traceback" not in out.stderr
    )


def test_a_missing_recording_is_one_line_before_any_url(tmp_path):
    missing = run("-m", "flyloop.view", str(tmp_path / "nothing.rrd"))
    assert missing.returncode == 1 and "open http" not in missing.stdout
    assert missing.stderr.strip() == f"flyloop.view: {tmp_path / 'nothing.rrd'}: no such file"


def test_a_browser_that_cannot_start_is_one_line(tmp_path):
    env = {**os.environ, "FLYLOOP_CHROMIUM": str(tmp_path / "no-chromium")}
    out = run(
        "-m", "flyloop.view.screenshot", "http://127.0.0.1:1/", str(tmp_path / "x.png"), env=env
    )
    assert out.returncode == 1 and "Traceback" not in out.stderr
    assert f"no Chromium at {tmp_path / 'no-chromium'}" in out.stderr


def test_the_view_draws_every_vehicle_of_a_real_time_sitl(binary, tmp_path):
    """Real time, 3 vehicles, a live view saving what it draws: each vehicle's truth on the
    simulation clock, its motor commands, and the view's streams turned off again after."""
    gcs = free_port()
    sitl = Sitl(binary, "--realtime", "--vehicles", "3", "--gcs", f"127.0.0.1:{gcs}")
    client = Client(sitl.address)
    web, grpc = free_port(socket.SOCK_STREAM), free_port(socket.SOCK_STREAM)
    view = subprocess.Popen(
        [
            sys.executable, "-m", "flyloop.view", "--listen", f"127.0.0.1:{gcs}",
            "--web-port", str(web), "--grpc-port", str(grpc),
            "--save", str(tmp_path / "rt.rrd"), "--seconds", "4",
        ],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
    )  # fmt: skip
    try:
        view.stdout.readline()  # the URL
        view.stdout.readline()  # listening: from now on for 4 s
        end = time.monotonic() + 3.5
        hover = [(9.81 / 40) ** 0.5] * 4
        while time.monotonic() < end:  # commands keep the vehicles running (no failsafe)
            for k in (1, 2, 3):
                client.send_raw(realtime_controls(client, hover, k))
            time.sleep(0.05)
        assert view.wait(timeout=30) == 0, view.stderr.read()
        # Nobody watches now: the SITL's usual telemetry only, none of the view's streams.
        after = []
        with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as gcs_sock:
            gcs_sock.bind(("127.0.0.1", gcs))
            gcs_sock.settimeout(0.2)
            parser, end = mavlink2.MAVLink(None), time.monotonic() + 1.5
            while time.monotonic() < end:
                try:
                    after += parser.parse_buffer(gcs_sock.recv(65536)) or []
                except TimeoutError:
                    pass
        kinds = {m.get_type() for m in after}
        assert "HEARTBEAT" in kinds and not kinds & {"HIL_STATE_QUATERNION", "SERVO_OUTPUT_RAW"}
    finally:
        client.close()
        sitl.stop()
    series = series_of(tmp_path / "rt.rrd")
    for k in (1, 2, 3):
        t, d = series[f"/position/vehicle{k}/D/truth"]
        assert len(t) > 20 and np.all(np.diff(t) >= 0) and t[-1] > 1.0, (k, len(t))
        assert np.median(d) == pytest.approx(-1.5, abs=0.1)  # hover thrust holds the height
        _, m0 = series[f"/motors/vehicle{k}_command/m0"]
        assert np.median(m0) == pytest.approx(hover[0], abs=1e-3)  # 1000-2000 us: 0.001


def realtime_controls(client, controls, system_id: int) -> bytes:
    """HIL_ACTUATOR_CONTROLS without the lockstep flag (real time), from vehicle `system_id`."""
    msg = client.mav.hil_actuator_controls_encode(0, list(controls) + [0.0] * 12, 0, 0)
    return client.pack(msg, system_id)


@pytest.mark.parametrize("n", [2, 4, 6, 8])
def test_frames_drawn_for_each_motor_count(n):
    """The lander (2), quad X (4), hexa X (6), octo X (8): rotors at the arm's length (the
    lander's at half its width), spins balanced (as many CW as CCW)."""
    from flyloop.view.scene import Frame

    f = Frame.for_motors(n)
    assert len(f.rotors) == len(f.spins) == n and sum(f.spins) == 0
    radii = np.linalg.norm(f.rotors, axis=1)
    assert np.allclose(radii, radii[0]) and radii[0] > 0


def test_a_view_slower_than_its_stream_stops_at_ctrl_c():
    """Regression: a view that could not keep up with the MAVLink arriving (a loaded machine,
    a fleet's stream) never left its read loop, so Ctrl-C never ended the watch and the view
    ran until killed. Here a sender floods it with vehicle states far faster than it draws
    them; Ctrl-C must still stop it, with its recording closed, within seconds. It is
    started the way a script's background job starts it, with SIGINT ignored (the second
    regression: Python then left Ctrl-C ignored)."""
    port = free_port()
    view = subprocess.Popen(
        [
            sys.executable, "-m", "flyloop.view", "--listen", f"127.0.0.1:{port}",
            "--web-port", str(free_port(socket.SOCK_STREAM)),
            "--grpc-port", str(free_port(socket.SOCK_STREAM)),
        ],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_IGN),
    )  # fmt: skip
    mav = mavlink2.MAVLink(None, srcSystem=1)
    state = mav.hil_state_quaternion_encode(
        0, [1.0, 0.0, 0.0, 0.0], 0, 0, 0, 473977420, 85455940, 490000, 0, 0, 0, 0, 0, 0, 0, 0
    )
    datagram = state.pack(mav) * 8
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as flood:
        try:
            view.stdout.readline()  # the URL
            view.stdout.readline()  # listening
            end, sent = time.monotonic() + 3.0, 0
            while time.monotonic() < end:
                flood.sendto(datagram, ("127.0.0.1", port))
                sent += 8
            view.send_signal(signal.SIGINT)
            stop = time.monotonic() + 15.0
            while view.poll() is None and time.monotonic() < stop:
                flood.sendto(datagram, ("127.0.0.1", port))  # the flood goes on
                time.sleep(0.0005)
            assert view.poll() == 0, f"no exit within 15 s of Ctrl-C ({sent} states sent)"
        finally:
            view.kill()
            view.wait()


def test_sigterm_ends_a_watch_with_its_recording_written(tmp_path):
    """A supervisor's SIGTERM stops the view like Ctrl-C: exit 0, the .rrd complete (its
    footer written) with the states that arrived."""
    port, rrd = free_port(), tmp_path / "term.rrd"
    view = subprocess.Popen(
        [
            sys.executable, "-m", "flyloop.view", "--listen", f"127.0.0.1:{port}",
            "--web-port", str(free_port(socket.SOCK_STREAM)),
            "--grpc-port", str(free_port(socket.SOCK_STREAM)), "--save", str(rrd),
        ],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
    )  # fmt: skip
    mav = mavlink2.MAVLink(None, srcSystem=3)
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as out:
        try:
            view.stdout.readline()  # the URL
            view.stdout.readline()  # listening
            for k in range(50):
                state = mav.hil_state_quaternion_encode(
                    20_000 * (k + 1), [1.0, 0.0, 0.0, 0.0], 0, 0, 0,
                    473977420, 85455940, 490000 + 10 * k, 0, 0, 0, 0, 0, 0, 0, 0,
                )  # fmt: skip
                out.sendto(state.pack(mav), ("127.0.0.1", port))
                time.sleep(0.01)
            time.sleep(0.5)
            view.send_signal(signal.SIGTERM)
            assert view.wait(timeout=30) == 0, view.stderr.read()
        finally:
            view.kill()
            view.wait()
    t, _ = series_of(rrd)["/position/vehicle3/D/truth"]
    assert len(t) == 50 and t[-1] == pytest.approx(1.0), (len(t), t[-1:])


def _rows(rrd, column: str) -> dict[str, list]:
    """Entity path -> [(sim time s, value)] of one column of an .rrd, in time order."""
    out: dict[str, list] = {}
    for name, t, values in plot._columns(rrd, column):
        out.setdefault(name, []).extend(zip(t.tolist(), values, strict=True))
    return {name: sorted(rows, key=lambda r: r[0]) for name, rows in out.items()}


def test_a_replay_sent_in_columns_reads_back_as_logged_row_by_row(binary, tmp_path, monkeypatch):
    """Regression: a replay logged every step's rows one `rr.log` each (a one-minute ArduPilot
    flight took a minute); it now sends them as columns, in several batches here. Series,
    poses and wind arrows must read back with the same times and values."""
    record(binary, tmp_path / "run.tlog")
    monkeypatch.setattr(scene, "BATCH_ROWS", 97)  # a batch ends mid-step, several times
    columns_rrd, rows_rrd = tmp_path / "columns.rrd", tmp_path / "rows.rrd"
    viewer = Viewer(web_port=None, grpc_port=None, save=columns_rrd, serve=False)
    assert viewer.replay(tmp_path / "run.tlog") > 800
    viewer.close()
    viewer = Viewer(web_port=None, grpc_port=None, save=rows_rrd, serve=False)
    read_tlog(str(tmp_path / "run.tlog"), MavlinkScene(viewer.scene))  # live: row by row
    viewer.close()
    wanted = (
        "Scalars:scalars",
        "Transform3D:translation",
        "Transform3D:quaternion",
        "Arrows3D:origins",
        "Arrows3D:vectors",
    )
    for column in wanted:
        batched, logged = _rows(columns_rrd, column), _rows(rows_rrd, column)
        assert batched == logged, column
        assert sum(map(len, logged.values())) >= 201, (column, list(logged))
