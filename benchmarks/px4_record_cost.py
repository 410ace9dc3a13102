"""What `--record` costs a PX4 flight: PX4 v1.16.0 flying flyloop-sitl --px4 unpaced
(`--speed-factor 0`; PX4's own PX4_SIM_SPEED_FACTOR as given), armed and taken off to 5 m and
held for a fixed wall time, in two set-ups alternated in the same run (ABBA: the order swaps
every round):

- base: flyloop-sitl --px4 as it is;
- record: the same with `--record FILE.tlog` (every 4 ms step written).

Per round: the real-time factor flyloop reports at its stop (simulated / wall time, the whole
connection) and flyloop's CPU µs per step; for `record` the size per simulated minute. Needs
$FLYLOOP_PX4 (as tests/px4). Figures in docs/performance.md.

    FLYLOOP_PX4=/work/shared/px4 .venv/bin/python benchmarks/px4_record_cost.py \
        [--seconds 20] [--rounds 3]
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "tests" / "px4"))
sys.path.insert(0, str(REPO / "benchmarks"))
import px4_support  # noqa: E402
from proc_cpu import cpu_seconds  # noqa: E402
from px4_support import Flyloop, Px4, free_instance, fresh_dir, px4_root  # noqa: E402
from view_cost import summary  # noqa: E402


def flight(px4_dir: Path, seconds: float, record: Path | None) -> tuple[float, float, float]:
    """One takeoff held for `seconds` of wall time: (real-time factor, flyloop CPU µs per
    step, simulated seconds)."""
    binary = REPO / "target" / "release" / "flyloop-sitl"
    instance = free_instance()
    work = fresh_dir("flyloop-px4-bench-")
    extra = ["--record", str(record)] if record else []
    flyloop = Flyloop(binary, instance, work, *extra, speed=0)
    px4 = Px4(px4_dir, instance, fresh_dir("px4-bench-"))
    try:
        px4.heartbeat(60)
        px4.arm_when_ready(60)
        px4.takeoff()
        end = time.monotonic() + seconds
        while time.monotonic() < end:
            px4.heartbeat(10)
        cpu = cpu_seconds(flyloop.proc.pid)
    finally:
        flyloop.stop()
        px4.kill()
    stats = dict(
        kv.split("=", 1) for kv in flyloop.stderr().split("stopped: ", 1)[1].split() if "=" in kv
    )
    simulated = float(stats["simulated_s"])
    steps = simulated / 0.004
    return float(stats["real_time_factor"]), cpu * 1e6 / steps, simulated


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--seconds", type=float, default=20.0)
    p.add_argument("--rounds", type=int, default=3)
    p.add_argument(
        "--px4-speed", type=float, default=px4_support.SPEED, help="PX4_SIM_SPEED_FACTOR"
    )
    args = p.parse_args()
    px4_support.SPEED = args.px4_speed
    print(f"{os.cpu_count()} cores, load {os.getloadavg()[0]:.2f} at the start")
    factor: dict[str, list[float]] = {"base": [], "record": []}
    cpu: dict[str, list[float]] = {"base": [], "record": []}
    with tempfile.TemporaryDirectory() as tmp:
        px4_dir = px4_root(Path(tmp) / "px4")
        tlog = Path(tmp) / "px4.tlog"
        for r in range(args.rounds):
            # Order swapped every round: a load that rises or falls through the run does not
            # always fall on the same set-up.
            for name in list(factor)[:: 1 if r % 2 == 0 else -1]:
                f, cpu_us, simulated = flight(
                    px4_dir, args.seconds, tlog if name == "record" else None
                )
                factor[name].append(f)
                cpu[name].append(cpu_us)
                extra = ""
                if name == "record":
                    size = tlog.stat().st_size
                    extra = f", recording {size / 2**20:.2f} MiB for {simulated:.1f} s simulated"
                    extra += f" = {size / simulated * 60 / 2**20:.2f} MiB per simulated minute"
                print(
                    f"round {r + 1} {name:6s} real-time factor {f:6.2f}, flyloop CPU "
                    f"{cpu_us:5.1f} us/step{extra}",
                    flush=True,
                )
    summary(factor, "x real time", ".2f")
    summary(cpu, "us/step flyloop CPU", ".1f")
    print(f"load {os.getloadavg()[0]:.2f} at the end")
    return 0


if __name__ == "__main__":
    sys.exit(main())
