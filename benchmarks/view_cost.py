"""What recording and a connected live view cost the SITL: lockstep steps/s of one vehicle
(HIL_STATE_QUATERNION + task frame per reply, a pymavlink client as a gym env is) in three
set-ups, alternated round by round in the same run:

- base: flyloop-sitl as it is (its ground-station telemetry goes to a port nobody reads);
- record: the same with `--record FILE.tlog` (every step written);
- view: the same with `python -m flyloop.view` listening on the ground-station port (the
  view's four streams on at 25 Hz, drawn into a served Rerun recording).

Also the size of a recording per simulated minute. Figures in docs/performance.md.

    .venv/bin/python benchmarks/view_cost.py [--seconds 5] [--rounds 3]
"""

from __future__ import annotations

import argparse
import os
import platform
import signal
import socket
import subprocess
import sys
import tempfile
import time
from pathlib import Path

os.environ["MAVLINK20"] = "1"
from proc_cpu import cpu_seconds  # noqa: E402
from pymavlink.dialects.v20 import common as mavlink2  # noqa: E402

REPO = Path(__file__).resolve().parents[1]
LOCKSTEP = mavlink2.HIL_ACTUATOR_CONTROLS_FLAGS_LOCKSTEP


def free_port(kind: int = socket.SOCK_DGRAM) -> int:
    with socket.socket(socket.AF_INET, kind) as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def steps_per_second(sitl_args: list[str], seconds: float) -> tuple[float, float, int]:
    """Lockstep steps/s over `seconds` (after 0.5 s of warm-up), the SITL's CPU µs per step
    over the same window (less moved by other load than the wall clock), and the steps made."""
    binary = REPO / "target" / "release" / "flyloop-sitl"
    proc = subprocess.Popen(
        [str(binary), "--listen", "127.0.0.1:0", *sitl_args],
        stdout=subprocess.PIPE,
        stderr=subprocess.DEVNULL,
        text=True,
    )
    line = proc.stdout.readline()
    host, port = line.split("listen=")[1].split()[0].rsplit(":", 1)
    sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    sock.settimeout(5)
    mav = mavlink2.MAVLink(None, srcSystem=1)
    datagram = mav.hil_actuator_controls_encode(0, [0.5] * 4 + [0.0] * 12, 0, LOCKSTEP).pack(mav)
    parser = mavlink2.MAVLink(None)
    try:
        steps, start, warm = 0, time.perf_counter(), None
        while True:
            sock.sendto(datagram, (host, int(port)))
            parser.parse_buffer(sock.recvfrom(65536)[0])
            steps += 1
            now = time.perf_counter()
            if warm is None and now - start > 0.5:
                warm, warm_steps, cpu0 = now, steps, cpu_seconds(proc.pid)
            if warm is not None and now - warm >= seconds:
                cpu_us = (cpu_seconds(proc.pid) - cpu0) * 1e6 / (steps - warm_steps)
                return (steps - warm_steps) / (now - warm), cpu_us, steps
    finally:
        sock.close()
        proc.send_signal(signal.SIGINT)
        proc.wait(timeout=10)


def summary(results: dict[str, list[float]], unit: str, fmt: str) -> None:
    """Each set-up's mean, as a ratio to the base's, and its rounds."""
    base = sum(results["base"]) / len(results["base"])
    for name, values in results.items():
        mean = sum(values) / len(values)
        rounds = ", ".join(format(x, fmt) for x in values)
        print(f"{name:6s} mean {mean:{fmt}} {unit} = {mean / base:.3f} of base ({rounds})")


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--seconds", type=float, default=5.0)
    p.add_argument("--rounds", type=int, default=3)
    args = p.parse_args()
    cpu = next(
        (
            line.split(":", 1)[1].strip()
            for line in open("/proc/cpuinfo")
            if line.startswith("model name")
        ),
        platform.processor(),
    )
    print(f"CPU {cpu}, {os.cpu_count()} cores, load {os.getloadavg()[0]:.2f} at the start")
    results: dict[str, list[float]] = {"base": [], "record": [], "view": []}
    cpu: dict[str, list[float]] = {name: [] for name in results}
    with tempfile.TemporaryDirectory() as tmp:
        tlog = Path(tmp) / "run.tlog"
        for r in range(args.rounds):
            for name in results:
                gcs = free_port()
                sitl_args = ["--gcs", f"127.0.0.1:{gcs}"]
                view = None
                if name == "record":
                    sitl_args += ["--record", str(tlog)]
                if name == "view":
                    web, grpc = free_port(socket.SOCK_STREAM), free_port(socket.SOCK_STREAM)
                    cmd = [
                        sys.executable,
                        "-m",
                        "flyloop.view",
                        "--listen",
                        f"127.0.0.1:{gcs}",
                        "--web-port",
                        str(web),
                        "--grpc-port",
                        str(grpc),
                    ]
                    view = subprocess.Popen(
                        cmd, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True
                    )
                    view.stdout.readline()
                    view.stdout.readline()  # "listening ...": ready
                rate, cpu_us, steps = steps_per_second(sitl_args, args.seconds)
                cpu[name].append(cpu_us)
                if view is not None:
                    view.send_signal(signal.SIGINT)
                    view.wait(timeout=15)
                results[name].append(rate)
                extra = ""
                if name == "record":
                    size = tlog.stat().st_size
                    per_minute = size / steps * 6000 / 2**20  # 6,000 steps of 10 ms
                    extra = f", recording {size / 2**20:.2f} MiB for {steps} steps"
                    extra += f" = {per_minute:.2f} MiB per simulated minute"
                line = (
                    f"round {r + 1} {name:6s} {rate:8.0f} steps/s, SITL CPU {cpu_us:5.1f} us/step"
                )
                print(line + extra, flush=True)
    summary(results, "steps/s", ".0f")
    summary(cpu, "us/step SITL CPU", ".1f")
    print(f"load {os.getloadavg()[0]:.2f} at the end")
    return 0


if __name__ == "__main__":
    sys.exit(main())
