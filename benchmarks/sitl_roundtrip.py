"""Lockstep round trips per second from a Python pymavlink client over loopback.

Each round trip encodes the HIL_ACTUATOR_CONTROLS (one per vehicle) in one datagram, sends it,
receives the reply datagram and decodes every message in it, as a gym env does. Scenarios:
one vehicle with HIL_STATE_QUATERNION + task frame, one vehicle with the task frame only, and
16 vehicles per datagram (task frames only, and with states).

The floor is the same client against `udp_echo` (sitl/examples), a one-thread tokio UDP server
that answers with a reply recorded from the SITL for the same scenario: the difference per round
trip is what the SITL adds (parsing, physics, encoding; its syscalls are in both). The SITL's own
counters (busy time per datagram, physics per step) are printed too.

    CARGO_TARGET_DIR=... python benchmarks/sitl_roundtrip.py [--seconds 3]

Run it on a quiet machine (nothing compiling).
"""

from __future__ import annotations

import argparse
import os
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

os.environ["MAVLINK20"] = "1"

from pymavlink.dialects.v20 import common as mavlink2  # noqa: E402

REPO = Path(__file__).resolve().parents[1]
LOCKSTEP = mavlink2.HIL_ACTUATOR_CONTROLS_FLAGS_LOCKSTEP


def target_dir() -> Path:
    target = Path(os.environ.get("CARGO_TARGET_DIR", REPO / "target"))
    return target if target.is_absolute() else REPO / target


def build() -> tuple[Path, Path]:
    cmd = ["cargo", "build", "--release", "-p", "flyloop-sitl", "--quiet"]
    subprocess.run(cmd, cwd=REPO, check=True)
    subprocess.run([*cmd, "--example", "udp_echo"], cwd=REPO, check=True)
    release = target_dir() / "release"
    return release / "flyloop-sitl", release / "examples" / "udp_echo"


def start(args: list[str]) -> tuple[subprocess.Popen, tuple[str, int]]:
    proc = subprocess.Popen(
        args, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, bufsize=1
    )
    line = proc.stdout.readline()
    addr = line.split("listen=")[1].split()[0]
    host, port = addr.rsplit(":", 1)
    return proc, (host, int(port))


def stop(proc: subprocess.Popen) -> str:
    proc.send_signal(signal.SIGTERM)
    _, err = proc.communicate(timeout=10)
    return err


class Client:
    def __init__(self, address, vehicles: int):
        self.address = address
        self.vehicles = vehicles
        self.sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self.sock.settimeout(5)
        self.mav = mavlink2.MAVLink(None, srcSystem=1, srcComponent=1)
        self.parser = mavlink2.MAVLink(None)

    def request(self, k: int) -> bytes:
        a = 0.5 + 0.001 * (k % 7)
        parts = []
        for v in range(1, self.vehicles + 1):
            self.mav.srcSystem = v
            msg = self.mav.hil_actuator_controls_encode(0, [a, a, a, a] + [0.0] * 12, 0, LOCKSTEP)
            parts.append(msg.pack(self.mav))
        return b"".join(parts)

    def round_trip(self, k: int) -> list:
        self.sock.sendto(self.request(k), self.address)
        data, _ = self.sock.recvfrom(65536)
        return self.parser.parse_buffer(data) or []

    def command(self, msg) -> bytes:
        self.mav.srcSystem = 255
        self.sock.sendto(msg.pack(self.mav), self.address)
        return self.sock.recvfrom(65536)[0]

    def run(self, seconds: float) -> tuple[float, int]:
        for k in range(200):  # warm up
            self.round_trip(k)
        n, start = 0, time.perf_counter()
        while (elapsed := time.perf_counter() - start) < seconds:
            for _ in range(100):
                msgs = self.round_trip(n)
                n += 1
            assert msgs, "empty reply"
        return n / elapsed, n


def measure_sitl(sitl_bin, vehicles, with_state, seconds):
    sitl, address = start(
        [str(sitl_bin), "--listen", "127.0.0.1:0", "--gcs", "off", "--vehicles", str(vehicles)]
    )
    client = Client(address, vehicles)
    if not with_state:
        cmd = client.mav.command_long_encode(
            0, 1, mavlink2.MAV_CMD_SET_MESSAGE_INTERVAL, 0, 115, -1, 0, 0, 0, 0, 0
        )
        client.command(cmd)
    sitl_rate, n = client.run(seconds)
    client.sock.sendto(client.request(0), address)
    recorded = client.sock.recvfrom(65536)[0]
    messages = len(client.parser.parse_buffer(recorded) or [])
    stats_line = stop(sitl)
    stats = {}
    for line in stats_line.splitlines():
        if "stopped: " in line:
            stats = dict(kv.split("=") for kv in line.split("stopped: ")[1].split())
    return sitl_rate, n, recorded, messages, len(recorded), stats


def measure_echo(echo_bin, vehicles, recorded, seconds) -> float:
    echo, echo_address = start([str(echo_bin)])
    floor = Client(echo_address, vehicles)
    floor.sock.sendto(b"SET " + recorded, echo_address)
    assert floor.sock.recvfrom(16)[0] == b"OK"
    echo_rate, _ = floor.run(seconds)
    stop(echo)
    return echo_rate


def scenario(sitl_bin, echo_bin, name, vehicles, with_state, seconds, repeats) -> dict:
    """Alternates SITL and echo runs `repeats` times; the best rate of each counts (noise on a
    shared machine only ever slows a run down)."""
    best = None
    echo_rate = 0.0
    for _ in range(repeats):
        run = measure_sitl(sitl_bin, vehicles, with_state, seconds)
        if best is None or run[0] > best[0]:
            best = run
        echo_rate = max(echo_rate, measure_echo(echo_bin, vehicles, run[2], seconds))
    sitl_rate, n, _, messages, size, stats = best

    added_us = (1 / sitl_rate - 1 / echo_rate) * 1e6
    return {
        "name": name,
        "vehicles": vehicles,
        "messages": messages,
        "bytes": size,
        "round_trips": sitl_rate,
        "steps": sitl_rate * vehicles,
        "floor": echo_rate,
        "added_us_per_round_trip": added_us,
        "added_us_per_step": added_us / vehicles,
        "busy_us": float(stats.get("busy_us_per_datagram", "nan")),
        "handling_us": float(stats.get("handling_us_per_datagram", "nan")),
        "physics_us": float(stats.get("physics_us_per_step", "nan")),
        "n": n,
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--seconds", type=float, default=2.0, help="per measurement")
    parser.add_argument("--repeats", type=int, default=3, help="alternating runs per scenario")
    args = parser.parse_args()
    sitl_bin, echo_bin = build()
    rows = [
        scenario(
            sitl_bin, echo_bin, "1 vehicle, state + frame", 1, True, args.seconds, args.repeats
        ),
        scenario(sitl_bin, echo_bin, "1 vehicle, frame only", 1, False, args.seconds, args.repeats),
        scenario(
            sitl_bin, echo_bin, "16 vehicles, frames only", 16, False, args.seconds, args.repeats
        ),
        scenario(
            sitl_bin, echo_bin, "16 vehicles, state + frame", 16, True, args.seconds, args.repeats
        ),
    ]
    print(f"python {sys.version.split()[0]}, pymavlink client, loopback UDP, hover task")
    print(
        "| scenario | msgs/reply | round trips/s | steps/s | echo floor rt/s "
        "| end-to-end µs/step over floor | SITL handling µs/step | of which physics "
        "| SITL busy µs/datagram (incl. send) |"
    )
    print("|---|---|---|---|---|---|---|---|---|")
    for r in rows:
        print(
            f"| {r['name']} | {r['messages']} | {r['round_trips']:,.0f} | {r['steps']:,.0f} "
            f"| {r['floor']:,.0f} | {r['added_us_per_step']:.1f} "
            f"| {r['handling_us'] / r['vehicles']:.2f} | {r['physics_us']:.2f} "
            f"| {r['busy_us']:.1f} |"
        )


if __name__ == "__main__":
    main()
