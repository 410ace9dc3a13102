"""N PX4 instances in one flyloop world (docs/performance.md, "Fleets"): every vehicle arms,
takes off, holds 5 m (worst error over 2 s of PX4 time must be ≤ 0.3 m) and lands; prints
per run the real-time factor (world time / wall time, from flyloop's stop line), the CPU
seconds of flyloop and of the PX4s (from /proc), and flyloop's share.

    FLYLOOP_PX4=/work/shared/px4 python benchmarks/fleet_px4.py --vehicles 8 --runs 3
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
for folder in ("sitl", "px4", "ardupilot", "fleet"):
    sys.path.insert(0, str(REPO / "tests" / folder))

from fleet_report import fleet_result, held, run_line  # noqa: E402
from fleet_support import FleetSitl, free_block, land_all, px4_ports_free  # noqa: E402
from flyloop import find_sitl_binary  # noqa: E402
from proc_cpu import cpu_seconds, machine_line  # noqa: E402
from px4_support import Px4, collect, fresh_dir, launch, px4_root, settle  # noqa: E402


def run(binary: Path, root: Path, n: int, speed: float) -> dict:
    base = free_block(n, px4_ports_free, 10, 240)
    sitl = FleetSitl(
        binary, fresh_dir("bench-fleet-"), "--px4", "--vehicles", str(n),
        "--px4-listen", f"127.0.0.1:{4560 + base}", speed=speed,
    )  # fmt: skip
    px4s = [Px4(root, base + k, fresh_dir(f"bench-px4-{k}-")) for k in range(n)]
    try:
        for p in px4s:
            p.heartbeat(180)
        targets = [launch(p)[1] for p in px4s]
        for p, t in zip(px4s, targets, strict=True):
            settle(p, t, 0.3, 300)
        worst = 0.0
        for p, t in zip(px4s, targets, strict=True):
            h, v = collect(p, 2.0).worst(t)
            worst = max(worst, h, v)
        land_all(px4s, 300)
        cpu_px4 = sum(cpu_seconds(p.proc.pid) for p in px4s)
        cpu_flyloop = cpu_seconds(sitl.proc.pid)
    finally:
        for p in px4s:
            p.kill()
        sitl.stop()
    return fleet_result(sitl, worst, cpu_flyloop, cpu_px4)


def main() -> int:
    a = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    a.add_argument("--vehicles", type=int, default=8)
    a.add_argument("--runs", type=int, default=3)
    a.add_argument("--speed-factor", type=float, default=0.0)
    args = a.parse_args()
    root = px4_root(Path(tempfile.mkdtemp(prefix="bench-px4-build-")))
    binary = find_sitl_binary(build=True)
    print(machine_line())
    ok = True
    for k in range(args.runs):
        start = time.monotonic()
        r = run(binary, root, args.vehicles, args.speed_factor)
        ok &= held(r)
        print(run_line(k, args.vehicles, "PX4", r, start), flush=True)
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
