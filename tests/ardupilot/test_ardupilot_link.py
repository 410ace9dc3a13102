"""ArduPilot mode's UDP link with a hand-driven peer over real sockets (no ArduPilot needed):
the lockstep rule (one step per new frame count, a repeated count answered again without a
step), the JSON line, garbage and absurd PWM, a restart and silence."""

from __future__ import annotations

import json
import socket
import struct
import subprocess
import tempfile
import time
from pathlib import Path

import pytest
from ardupilot_support import stop

MAGIC_16 = 18458
MAGIC_32 = 29569


def servo(count: int, pwm: int, rate: int = 1200, magic: int = MAGIC_16, channels: int = 16):
    return struct.pack(f"<HHI{channels}H", magic, rate, count, *([pwm] * 4 + [0] * (channels - 4)))


class Peer:
    """A fake ArduPilot: a UDP socket of its own (an ephemeral port, as ArduPilot's)."""

    def __init__(self, port: int):
        self.sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self.sock.settimeout(2)
        self.address = ("127.0.0.1", port)

    def send(self, packet: bytes) -> None:
        self.sock.sendto(packet, self.address)

    def step(self, packet: bytes) -> dict:
        self.send(packet)
        data = self.sock.recv(65536)
        assert data.startswith(b"\n{") and data.endswith(b"}\n"), data
        assert b" " not in data and b"NaN" not in data
        return json.loads(data)

    def silent(self, seconds: float = 0.3) -> bool:
        self.sock.settimeout(seconds)
        try:
            self.sock.recv(65536)
            return False
        except TimeoutError:
            return True
        finally:
            self.sock.settimeout(2)


@pytest.fixture
def simulator(sitl_binary):
    log = tempfile.NamedTemporaryFile("w+", prefix="ardupilot-link-", suffix=".log", delete=False)
    proc = subprocess.Popen(
        [
            str(sitl_binary),
            "--ardupilot",
            "--ardupilot-listen",
            "127.0.0.1:0",
            "--speed-factor",
            "0",
        ],
        stdout=subprocess.PIPE,
        stderr=log,
        text=True,
    )
    line = proc.stdout.readline()
    assert line.startswith("flyloop-sitl ready "), line
    ready = dict(kv.split("=", 1) for kv in line.split()[2:])
    assert ready["mode"] == "ardupilot"
    port = int(ready["ardupilot"].rsplit(":", 1)[1])

    def logged() -> str:
        log.flush()
        return Path(log.name).read_text()

    yield port, proc, logged
    stop(proc)


def wait_for_log(logged, text: str, timeout: float = 5) -> None:
    deadline = time.monotonic() + timeout
    while text not in logged() and time.monotonic() < deadline:
        time.sleep(0.05)
    assert text in logged(), logged()


def test_lockstep_repeats_bad_input_restart_and_silence(simulator):
    port, proc, logged = simulator
    ap = Peer(port)
    # Frame 0: one step of 833 us (1/1200 s in whole microseconds), at rest on the ground.
    first = ap.step(servo(0, 1000))
    assert first["timestamp"] == 0.000833
    assert abs(first["imu"]["accel_body"][2] + 9.81) < 0.6
    assert first["quaternion"][0] == pytest.approx(1.0, abs=1e-6)
    assert first["position"][2] == pytest.approx(-0.0538, abs=1e-3)
    # Nothing without a frame.
    assert ap.silent()
    # The same frame again: the same answer, no step.
    assert ap.step(servo(0, 1000)) == first
    # 1,199 frames at full climb power: physics time 1200 * 833 us, climbing.
    for k in range(1, 1200):
        state = ap.step(servo(k, 1900))
    assert state["timestamp"] == pytest.approx(0.9996, abs=1e-9)
    assert state["velocity"][2] < -3.0 and state["position"][2] < -1.0, state

    # Garbage, a short packet, a 32-channel magic in 40 bytes, frame rate 0: no answer.
    for bad in (
        b"garbage",
        servo(1200, 1500)[:30],
        servo(1200, 1500, magic=MAGIC_32),
        servo(1200, 1500, rate=0),
    ):
        ap.send(bad)
        assert ap.silent(0.2)
    # The lockstep goes on; absurd PWM holds the previous command but is answered.
    t = ap.step(servo(1200, 40000))["timestamp"]
    assert t == pytest.approx(1.000433, abs=1e-9)
    # A valid 32-channel packet flies too.
    assert ap.step(servo(1201, 1000, magic=MAGIC_32, channels=32))["timestamp"] > t

    # Silence is logged once; a restarted ArduPilot (another port, count from 0) gets the
    # start state and time from 0 again, the same first answer.
    wait_for_log(logged, "no servo packet from ArduPilot", timeout=5)
    again = Peer(port)
    assert again.step(servo(0, 1000)) == first
    wait_for_log(logged, "ArduPilot restarted")
    assert proc.poll() is None
    stop(proc)
    counters = dict(kv.split("=") for kv in logged().split("stopped: ", 1)[1].split())
    assert counters["steps"] == "1203" and counters["repeats"] == "1", counters
    assert counters["connections"] == "2", counters
    assert (counters["bad_length"], counters["bad_magic"], counters["bad_frame_rate"]) == (
        "2",
        "1",
        "1",
    )
    assert counters["absurd_pwm"] == "1", counters
    # How fast it ran: the simulated time (read every 64 frames: the last few may be left
    # out) against the wall time it took, and their ratio.
    simulated, wall = float(counters["simulated_s"]), float(counters["wall_s"])
    assert 1.0013 - 64 * 0.000833 <= simulated <= 1.0013 + 1e-6, counters
    assert 0 < wall < 60 and float(counters["real_time_factor"]) == pytest.approx(
        simulated / wall, rel=1e-3, abs=0.01
    )
    # Each kind of bad input logged once.
    assert logged().count("skipped: ") == 3, logged()
