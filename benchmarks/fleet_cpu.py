"""CPU per simulated second of a fleet of N ArduCopters standing in one flyloop world
(docs/performance.md, "Fleets"): CPU-seconds of flyloop and of each ArduPilot per second of
world time, which the machine's load changes little (unlike the real-time factor). The
vehicles only stand (an ArduPilot's CPU per frame is the same on the ground and in the air:
fleet_ardupilot.py flies them). The ArduPilots get the fleet's parameters
(sitl/presets/ardupilot_fleet.parm) after the Iris's, `--stock`: the Iris's only; `--perf FILE`
records flyloop with `perf record -g`, `--strace FILE` counts the first ArduPilot's syscalls.

    FLYLOOP_ARDUPILOT=PATH_TO_ARDUCOPTER_BUILD python benchmarks/fleet_cpu.py --seconds 30
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
for folder in ("sitl", "px4", "ardupilot", "fleet"):
    sys.path.insert(0, str(REPO / "tests" / folder))
sys.path.insert(0, str(REPO / "benchmarks"))

from ardupilot_support import PARM, ardupilot_build  # noqa: E402
from fleet_ardupilot import FLEET_PARM, start, stop  # noqa: E402
from flyloop import find_sitl_binary  # noqa: E402
from proc_cpu import cpu_model  # noqa: E402


def drain(aps, seconds: float) -> None:
    """Reads every ArduPilot's link for `seconds` (an unread link blocks its ArduPilot)."""
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        for ap in aps:
            while ap.link.recv_msg() is not None:
                pass
        time.sleep(0.05)


def run(binary, build, n: int, seconds: float, parm, perf: str | None, strace: str | None) -> dict:
    sitl, aps = start(binary, build, n, 0.0, parm)
    recorders = []
    try:
        for ap in aps:
            ap.connect(120)
        if perf:
            recorder = subprocess.Popen(
                ["perf", "record", "-g", "-o", perf, "-p", str(sitl.proc.pid)],
                stdout=subprocess.DEVNULL,
                stderr=subprocess.DEVNULL,
            )
            recorders.append(recorder)
        if strace:
            tracer = subprocess.Popen(
                ["strace", "-c", "-f", "-o", strace, "-p", str(aps[0].proc.pid)],
                stdout=subprocess.DEVNULL,
                stderr=subprocess.DEVNULL,
            )
            recorders.append(tracer)
        load = os.getloadavg()[0]
        drain(aps, seconds)
        for r in recorders:
            r.send_signal(2)
            r.wait(60)
    finally:
        cpu_ap, cpu_flyloop, c = stop(sitl, aps)
    sim = float(c["time_s"])
    return {
        "sim_s": sim,
        "rtf": float(c["real_time_factor"]),
        "flyloop": cpu_flyloop / sim,
        "ardupilot": sum(cpu_ap) / sim / n,
        "share": cpu_flyloop / (cpu_flyloop + sum(cpu_ap)),
        "load": (load + os.getloadavg()[0]) / 2,
    }


def main() -> int:
    a = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    a.add_argument("--vehicles", type=int, default=8)
    a.add_argument("--seconds", type=float, default=30.0, help="wall time measured")
    a.add_argument("--stock", action="store_true", help="the Iris's parameters only")
    a.add_argument("--perf", help="perf record flyloop into this file")
    a.add_argument("--strace", help="strace -c the first ArduPilot into this file")
    args = a.parse_args()
    build = ardupilot_build(Path(tempfile.mkdtemp(prefix="bench-ap-build-")))
    binary = find_sitl_binary(build=True)
    parm = str(PARM) if args.stock else f"{PARM},{FLEET_PARM}"
    print(f"cpu: {os.cpu_count()} x {cpu_model()}, flyloop {binary}, parameters {parm}")
    r = run(binary, build, args.vehicles, args.seconds, parm, args.perf, args.strace)
    print(
        f"{args.vehicles} ArduPilots standing: world {r['sim_s']:.1f} s at {r['rtf']:.2f}x,"
        f" CPU per simulated s: flyloop {r['flyloop']:.4f} s, per ArduPilot"
        f" {r['ardupilot']:.4f} s, fleet {r['flyloop'] + args.vehicles * r['ardupilot']:.3f} s"
        f" (flyloop {100 * r['share']:.1f} %), load {r['load']:.2f}",
        flush=True,
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
