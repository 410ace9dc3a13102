"""PX4 mode's TCP link with a hand-driven peer over real sockets (no PX4 needed): the
lockstep rule, bad bytes, NaN controls, a refused second connection and a reconnect."""

from __future__ import annotations

import os
import socket
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import pytest

os.environ["MAVLINK20"] = "1"
from px4_support import stop  # noqa: E402
from pymavlink.dialects.v20 import common as mavlink2  # noqa: E402


class Peer:
    """A fake PX4: a TCP client that decodes what the simulator sends."""

    def __init__(self, address: tuple[str, int]):
        self.sock = socket.create_connection(address, timeout=5)
        self.mav = mavlink2.MAVLink(None, srcSystem=1)
        self.mav.robust_parsing = True
        self.pending: list = []

    def messages(self, wanted: int, kind: str = "HIL_SENSOR") -> list:
        """The next `wanted` messages of `kind` (later ones stay queued)."""
        while len([m for m in self.pending if m.get_type() == kind]) < wanted:
            data = self.sock.recv(65536)
            assert data, "the simulator closed the connection"
            self.pending += self.mav.parse_buffer(data) or []
        out = [m for m in self.pending if m.get_type() == kind][:wanted]
        self.pending = self.pending[self.pending.index(out[-1]) + 1 :]
        return out

    def controls(self, value: float) -> bytes:
        m = mavlink2.MAVLink_hil_actuator_controls_message(
            0, [value] * 4 + [0.0] * 12, mavlink2.MAV_MODE_FLAG_SAFETY_ARMED, 1
        )
        return m.pack(self.mav)

    def drain(self) -> None:
        self.pending = []
        self.sock.settimeout(0.2)
        try:
            while self.sock.recv(65536):
                pass
        except TimeoutError:
            pass
        self.sock.settimeout(5)


@pytest.fixture
def simulator(sitl_binary):
    log = tempfile.NamedTemporaryFile("w+", prefix="px4-link-", suffix=".log", delete=False)
    proc = subprocess.Popen(
        [str(sitl_binary), "--px4", "--px4-listen", "127.0.0.1:0", "--speed-factor", "0"],
        stdout=subprocess.PIPE,
        stderr=log,
        text=True,
    )
    line = proc.stdout.readline()
    assert line.startswith("flyloop-sitl ready "), line
    ready = dict(kv.split("=", 1) for kv in line.split()[2:])
    host, port = ready["px4"].rsplit(":", 1)

    def logged() -> str:
        log.flush()
        return Path(log.name).read_text()

    yield (host, int(port)), proc, logged
    stop(proc)


def wait_for_log(logged, text: str) -> None:
    deadline = time.monotonic() + 5
    while text not in logged() and time.monotonic() < deadline:
        time.sleep(0.05)
    assert text in logged(), logged()


def test_lockstep_bad_input_second_connection_and_reconnect(simulator):
    address, proc, logged = simulator
    peer = Peer(address)
    # Before any controls the simulator sends sensors on its own (never waits for PX4).
    first = peer.messages(3)
    assert [m.time_usec for m in first] == [4000, 8000, 12000]
    assert abs(first[0].zacc + 9.81) < 0.5 and first[0].fields_updated == 0x1BFF

    # Controls: from now on exactly one HIL_SENSOR per controls message, 4 ms apart.
    peer.sock.sendall(peer.controls(0.0))
    peer.drain()
    for _ in range(3):
        peer.sock.sendall(peer.controls(0.2))
    got = peer.messages(3)
    assert [b.time_usec - a.time_usec for a, b in zip(got, got[1:], strict=False)] == [4000, 4000]
    peer.sock.settimeout(0.3)
    with pytest.raises(TimeoutError):
        peer.sock.recv(65536)  # lockstep: nothing more without controls
    peer.sock.settimeout(5)

    # Garbage, a frame split in two writes and NaN controls: skipped or held, lockstep lives.
    frame = peer.controls(0.3)
    peer.sock.sendall(b"\x00\x13garbage" + frame[:7])
    time.sleep(0.05)
    peer.sock.sendall(frame[7:] + peer.controls(float("nan")))
    assert len(peer.messages(2)) == 2

    # A second connection while one is active is refused with a log line.
    other = socket.create_connection(address, timeout=5)
    assert other.recv(100) == b""
    other.close()
    wait_for_log(logged, "refused a second PX4 connection")

    # PX4 goes away: logged, the vehicle reset, the next connection starts over.
    peer.sock.close()
    wait_for_log(logged, "PX4 disconnected")
    again = Peer(address)
    assert again.messages(1)[0].time_usec == 4000
    again.sock.close()
    assert proc.poll() is None
    stop(proc)
    stats = logged().split("stopped: ", 1)[1]
    counts = dict(kv.split("=") for kv in stats.split())
    assert int(counts["garbage"]) >= 1
    assert int(counts["refused_controls"]) == 1


def test_speed_is_logged_and_a_track_still_being_written_plots(sitl_binary, tmp_path):
    """flyloop-sitl says how fast it runs (every 5 s of wall time and in its stop line), and
    examples/px4_track_plot.py plots the track it is still writing (a partial last row)."""
    track, log = tmp_path / "track.csv", tmp_path / "sitl.log"
    with open(log, "w") as err:
        proc = subprocess.Popen(
            [str(sitl_binary), "--px4", "--px4-listen", "127.0.0.1:0", "--speed-factor", "0"]
            + ["--track", str(track)],
            stdout=subprocess.PIPE,
            stderr=err,
            text=True,
        )
    try:
        ready = dict(kv.split("=", 1) for kv in proc.stdout.readline().split()[2:])
        host, port = ready["px4"].rsplit(":", 1)
        peer = Peer((host, int(port)))
        first = peer.messages(1)[0].time_usec
        start = time.monotonic()
        while time.monotonic() - start < 6.0:  # past the first 5 s line
            peer.sock.sendall(peer.controls(0.0) * 50)
            last = peer.messages(50)[-1].time_usec
        wall = time.monotonic() - start

        # The track mid-flight: the SITL writes whole buffers, so its last row is usually
        # cut; a copy cut inside a number makes sure of it.
        script = Path(__file__).resolve().parents[2] / "examples" / "px4_track_plot.py"
        text = track.read_text()
        complete = text[: text.rfind("\n") + 1]
        rows = complete.count("\n") - 1  # the header
        cut = tmp_path / "cut.csv"
        cut.write_text(complete + text[len(complete) :] + "12.3")
        assert rows > 100 and not cut.read_text().endswith("\n")
        png = tmp_path / "cut.png"
        done = subprocess.run(
            [sys.executable, str(script), str(cut), str(png)], capture_output=True, text=True
        )
        assert done.returncode == 0, done.stderr
        assert f"plotted {rows} rows" in done.stdout and "left out" in done.stdout
        assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
        # Not a track, or no file: one line naming it, no traceback.
        other = tmp_path / "other.csv"
        other.write_text("a,b\n1,2\n")
        bad = ((other, "is not a flyloop-sitl --track file"), (tmp_path, "cannot read"))
        for path, said in bad:
            done = subprocess.run(
                [sys.executable, str(script), str(path), str(png)], capture_output=True, text=True
            )
            assert done.returncode == 1 and said in done.stderr, done.stderr
            assert "Traceback" not in done.stderr
    finally:
        stop(proc)
    logged = log.read_text()
    # The 5-second line: simulated time, the window's and the overall real-time factor.
    line = next(x for x in logged.splitlines() if "x real time over the last" in x)
    assert " INFO " in line, line
    simulated = float(line.split("simulated ", 1)[1].split(" s,", 1)[0])
    factor = float(line.split(" s, ", 1)[1].split("x real time", 1)[0])
    assert 0 < simulated <= (last - first) * 1e-6 + 0.3 and factor > 1, line
    # The stop line: totals over the whole run, the factor = simulated / wall.
    stats = dict(kv.split("=") for kv in logged.split("stopped: ", 1)[1].split())
    sim_s, wall_s = float(stats["simulated_s"]), float(stats["wall_s"])
    assert abs(sim_s - (last - first) * 1e-6) <= 64 * 0.004 + 1e-6, (sim_s, first, last)
    assert 5.0 < wall_s <= wall + 0.5
    assert float(stats["real_time_factor"]) == pytest.approx(sim_s / wall_s, rel=1e-3, abs=0.01)
    assert int(stats["steps"]) >= (last - first) // 4000
