"""What a connected live view and a recording cost a fleet (docs/performance.md, "Fleets"):
N PX4s (default 2) in one flyloop world, unpaced (`--speed-factor 0`), armed, taken off to
5 m and held for a fixed wall time, in three set-ups alternated in the same run (the order
reverses every round, so a load that rises or falls does not always favour one):

- base: flyloop-sitl --px4 --vehicles N as it is;
- view: the same with `--view` and `python -m flyloop.view` listening to it and talking to
  every PX4's ground-station port (every truth, motor command and estimate drawn into a
  served Rerun recording);
- record: the same with `--record FILE.tlog` (every world step of every vehicle written).

Per round: the world's real-time factor (flyloop's stop line: world time / wall time since it
started), flyloop's CPU µs per world step, the view's CPU seconds, and the recording's size
per simulated minute. Needs $FLYLOOP_PX4 (as tests/px4).

    FLYLOOP_PX4=/work/shared/px4 .venv/bin/python benchmarks/fleet_view_cost.py \\
        [--vehicles 2] [--seconds 20] [--rounds 2]
"""

from __future__ import annotations

import argparse
import os
import signal
import socket
import subprocess
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
for folder in ("sitl", "px4", "ardupilot", "fleet"):
    sys.path.insert(0, str(REPO / "tests" / folder))
sys.path.insert(0, str(REPO / "benchmarks"))

from fleet_support import FleetSitl, free_block, px4_ports_free  # noqa: E402
from flyloop import find_sitl_binary  # noqa: E402
from proc_cpu import cpu_seconds  # noqa: E402
from px4_support import Px4, fresh_dir, launch, px4_root  # noqa: E402
from view_cost import free_port, summary  # noqa: E402

SETUPS = ("base", "view", "record")


def flight(binary: Path, root: Path, n: int, seconds: float, setup: str, tlog: Path) -> dict:
    """One fleet takeoff held for `seconds` of wall time under `setup`."""
    base = free_block(n, px4_ports_free, 10, 240)
    truth = free_port()
    extra = {"base": [], "view": ["--view", f"127.0.0.1:{truth}"], "record": ["--record", tlog]}
    sitl = FleetSitl(
        binary, fresh_dir("bench-fleet-view-"), "--px4", "--vehicles", str(n),
        "--px4-listen", f"127.0.0.1:{4560 + base}", *map(str, extra[setup]), speed=0,
    )  # fmt: skip
    px4s = [Px4(root, base + k, fresh_dir(f"bench-px4-{k}-")) for k in range(n)]
    view = None
    if setup == "view":
        web, grpc = free_port(socket.SOCK_STREAM), free_port(socket.SOCK_STREAM)
        connect = [a for k in range(n) for a in ("--connect", f"127.0.0.1:{18570 + base + k}")]
        view = subprocess.Popen(
            [sys.executable, "-m", "flyloop.view", "--listen", f"127.0.0.1:{truth}", *connect,
             "--web-port", str(web), "--grpc-port", str(grpc), "--wait", "300"],
            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
        )  # fmt: skip
    try:
        for p in px4s:
            p.heartbeat(180)
        for p in px4s:
            launch(p)
        end = time.monotonic() + seconds
        while time.monotonic() < end:
            for p in px4s:
                p.heartbeat(10)
        cpu_flyloop = cpu_seconds(sitl.proc.pid)
        cpu_view = cpu_seconds(view.pid) if view else 0.0
    finally:
        if view:
            view.send_signal(signal.SIGINT)
            view.wait(timeout=60)
        for p in px4s:
            p.kill()
        sitl.stop()
    c = sitl.counters()
    return {
        "rtf": float(c["real_time_factor"]),
        "sim_s": float(c["time_s"]),
        "cpu_us_per_step": cpu_flyloop * 1e6 / int(c["world_steps"]),
        "cpu_view_s": cpu_view,
    }


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--vehicles", type=int, default=2)
    p.add_argument("--seconds", type=float, default=20.0)
    p.add_argument("--rounds", type=int, default=2)
    args = p.parse_args()
    binary = find_sitl_binary(build=True)
    print(f"{os.cpu_count()} cores, load {os.getloadavg()[0]:.2f} at the start")
    factor: dict[str, list[float]] = {s: [] for s in SETUPS}
    cpu: dict[str, list[float]] = {s: [] for s in SETUPS}
    with tempfile.TemporaryDirectory() as tmp:
        root = px4_root(Path(tmp) / "px4")
        tlog = Path(tmp) / "fleet.tlog"
        for r in range(args.rounds):
            for setup in SETUPS[:: 1 if r % 2 == 0 else -1]:
                f = flight(binary, root, args.vehicles, args.seconds, setup, tlog)
                factor[setup].append(f["rtf"])
                cpu[setup].append(f["cpu_us_per_step"])
                extra = ""
                if setup == "view":
                    extra = f", view CPU {f['cpu_view_s']:.1f} s"
                if setup == "record":
                    size = tlog.stat().st_size
                    extra = f", recording {size / f['sim_s'] * 60 / 2**20:.2f} MiB per sim minute"
                print(
                    f"round {r + 1} {setup:6s} real-time factor {f['rtf']:6.2f} "
                    f"({f['sim_s']:.1f} s simulated), flyloop CPU {f['cpu_us_per_step']:5.1f} "
                    f"us/world step{extra}, load {os.getloadavg()[0]:.2f}",
                    flush=True,
                )
    summary(factor, "x real time", ".2f")
    summary(cpu, "us/world step flyloop CPU", ".1f")
    print(f"load {os.getloadavg()[0]:.2f} at the end")
    return 0


if __name__ == "__main__":
    sys.exit(main())
