"""The baseline fleets in one world are measured against (issue 34, docs/fleet.md "What makes
a starved PX4 refuse to arm or fail its takeoff"): N single-vehicle flyloop-sitl processes
(`--px4 --speed-factor 1`, one world each) with N PX4s (PX4_SIM_SPEED_FACTOR=1; both set by
`--speed-factor`: above 1 the PX4s need more CPU than the machine has), all asked at
once to arm, take off to 5 m and hover. Prints per vehicle how far it got (armed, took off,
held 5 m within 0.3 m), its real-time factor (its flyloop's last track time over the wall
time), and what PX4 itself said on its console (warnings and errors: preflight failures,
denied commands, simulator timeouts), counted.

    FLYLOOP_PX4=/work/shared/px4 python benchmarks/fleet_px4_separate.py --vehicles 8 [--realtime]

`--realtime` lets PX4 give its threads real-time priorities, as it does when started as root
(the tests and the other benchmarks start it without CAP_SYS_NICE; px4_support.py says why).
On a shared machine that takes the cores from everyone else for the run.
"""

from __future__ import annotations

import argparse
import collections
import os
import re
import sys
import tempfile
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
for folder in ("sitl", "px4", "ardupilot", "fleet"):
    sys.path.insert(0, str(REPO / "tests" / folder))

import px4_support  # noqa: E402
from fleet_support import free_block, px4_ports_free  # noqa: E402
from flyloop import find_sitl_binary  # noqa: E402
from proc_cpu import cpu_seconds, machine_line  # noqa: E402
from px4_support import Flyloop, Px4, collect, fresh_dir, px4_root, settle  # noqa: E402

# The time each stage may take on the wall clock (at 1x real time, PX4 needs ~15 s to arm).
ARM_S, TAKEOFF_S, HOLD_S = 120, 30, 90
# PX4's console lines worth counting: its warnings and errors, with the instance-specific
# numbers taken out so that the same message counts once per kind.
SAID = re.compile(r"(WARN|ERROR)\s+\[([^\]]+)\]\s+(.*)")


def fly(px4: Px4) -> str:
    """How far `px4` got: 'no heartbeat', 'not armed', 'no takeoff', 'no hold' or 'held'."""
    stage = "no heartbeat"
    try:
        px4.heartbeat(180)
        stage = "not armed"
        px4.arm_when_ready(ARM_S)
        stage = "no takeoff"
        px4.takeoff()
        home = px4.home()
        target = (home[0], home[1], home[2] - px4_support.TAKEOFF_ALT)
        stage = "no hold"
        settle(px4, target, 0.3, HOLD_S)
        h, v = collect(px4, 2.0).worst(target)
        return "held" if max(h, v) <= 0.3 else f"no hold ({max(h, v):.2f} m)"
    except AssertionError:
        return stage


def said(px4: Px4) -> collections.Counter:
    kinds = collections.Counter()
    for line in px4.output().splitlines():
        m = SAID.search(line)
        if m:
            kinds[f"{m[1]} [{m[2]}] {re.sub(r'[0-9.]+', 'N', m[3])}"] += 1
    return kinds


def main() -> int:
    a = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    a.add_argument("--vehicles", type=int, default=8)
    a.add_argument("--realtime", action="store_true", help="PX4 with CAP_SYS_NICE (as root)")
    a.add_argument(
        "--speed-factor", type=float, default=1.0, help="flyloop's pacing and PX4's alike"
    )
    args = a.parse_args()
    n = args.vehicles
    if args.realtime:
        px4_support.WITHOUT_REALTIME = ()
    # PX4 told the pace flyloop keeps (PX4_SIM_SPEED_FACTOR).
    px4_support.SPEED = args.speed_factor
    root = px4_root(Path(tempfile.mkdtemp(prefix="bench-px4-build-")))
    binary = find_sitl_binary(build=True)
    print(machine_line())
    base = free_block(n, px4_ports_free, 10, 240)
    start = time.monotonic()
    sitls = [
        Flyloop(binary, base + k, fresh_dir(f"bench-sep-{k}-"), speed=args.speed_factor)
        for k in range(n)
    ]
    px4s = [Px4(root, base + k, fresh_dir(f"bench-sep-px4-{k}-")) for k in range(n)]
    try:
        with ThreadPoolExecutor(n) as pool:
            outcomes = list(pool.map(fly, px4s))
        cpu_px4 = sum(cpu_seconds(p.proc.pid) for p in px4s)
        cpu_flyloop = sum(cpu_seconds(s.proc.pid) for s in sitls)
    finally:
        for p in px4s:
            p.kill()
        for s in sitls:
            s.stop()
    wall = time.monotonic() - start
    total = collections.Counter()
    for k, (p, s, outcome) in enumerate(zip(px4s, sitls, outcomes, strict=True)):
        rows = s.rows()
        rtf = rows[-1]["time_us"] * 1e-6 / wall if rows else 0.0
        kinds = said(p)
        total.update(kinds)
        print(f"vehicle {k}: {outcome}, real-time factor {rtf:.2f}, PX4 said {sum(kinds.values())}")
    held = outcomes.count("held")
    print(
        f"{held} of {n} held 5 m; wall {wall:.0f} s, CPU flyloops {cpu_flyloop:.1f} s /"
        f" PX4s {cpu_px4:.1f} s, load {os.getloadavg()[0]:.2f}"
    )
    print("what the PX4s said (count over all, most frequent first):")
    for kind, count in total.most_common(40):
        print(f"  {count:5d}  {kind}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
