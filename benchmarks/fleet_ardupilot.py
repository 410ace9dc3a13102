"""N ArduCopter instances in one flyloop world (docs/performance.md, "Fleets"): every vehicle
arms in GUIDED, takes off to 5 m, holds it (worst height error over 2 s of ArduPilot time must
be ≤ 0.3 m), lands and disarms; prints per run the real-time factor (world time / wall time,
from flyloop's stop line), the CPU seconds of flyloop and of the ArduPilots (from /proc), and
flyloop's share. The sibling of fleet_px4.py.

    FLYLOOP_ARDUPILOT=/work/shared/ardupilot python benchmarks/fleet_ardupilot.py --vehicles 8
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

from ardupilot_support import GUIDED, LAND, PARM, ArduPilot, ardupilot_build, collect, settle  # noqa: E402
from fleet_report import fleet_result, held, run_line  # noqa: E402
from fleet_support import HOME, FleetSitl, ardupilot_ports_free, free_block  # noqa: E402
from flyloop import find_sitl_binary  # noqa: E402
from proc_cpu import cpu_seconds, machine_line  # noqa: E402
from processes import fresh_dir  # noqa: E402

ALT = 5.0


def quiet(ap) -> None:
    """Positions at 5 Hz besides heartbeats and texts: while the benchmark waits on one
    vehicle it reads no other link, and an ArduPilot whose TCP link fills up blocks in its
    write and is silenced (tests/fleet/test_fleet_mixed.py)."""
    from pymavlink import mavutil

    mav = ap.link.mav
    mav.request_data_stream_send(ap.target, 1, mavutil.mavlink.MAV_DATA_STREAM_ALL, 0, 0)
    mav.request_data_stream_send(ap.target, 1, mavutil.mavlink.MAV_DATA_STREAM_POSITION, 5, 1)


# The fleet's ArduPilot parameters, after the Iris's (docs/fleet.md).
FLEET_PARM = REPO / "sitl" / "presets" / "ardupilot_fleet.parm"


def start(binary: Path, build, n: int, speed: float, parm: str) -> tuple[FleetSitl, list]:
    """flyloop-sitl with `n` ArduPilots (sysids 1..n, `parm` after copter.parm) in one world."""
    base = free_block(n, ardupilot_ports_free, 3, 150)
    listen = f"127.0.0.1:{9002 + 10 * base}"
    sitl = FleetSitl(
        binary, fresh_dir("bench-fleet-ap-"), "--ardupilot", "--vehicles", str(n),
        "--ardupilot-listen", listen, speed=speed,
    )  # fmt: skip
    home = ",".join(str(v) for v in HOME)
    aps = [
        ArduPilot(
            build,
            base + k,
            9002 + 10 * (base + k),
            fresh_dir(f"bench-ap-{k}-"),
            "--home",
            home,
            "--sysid",
            str(k + 1),
            parm=parm,
        )  # fmt: skip
        for k in range(n)
    ]
    return sitl, aps


def stop(sitl: FleetSitl, aps: list) -> tuple[list[float], float, dict[str, str]]:
    """Stops the fleet: each ArduPilot's CPU seconds, flyloop's, flyloop's stop counters."""
    try:
        cpu_ap = [cpu_seconds(ap.proc.pid) for ap in aps]
        cpu_flyloop = cpu_seconds(sitl.proc.pid)
    finally:
        for ap in aps:
            ap.kill()
        sitl.stop()
    return cpu_ap, cpu_flyloop, sitl.counters()


def run(binary: Path, build, n: int, speed: float, parm: str) -> dict:
    sitl, aps = start(binary, build, n, speed, parm)
    try:
        for ap in aps:
            ap.connect(120)
            quiet(ap)
        for ap in aps:
            ap.wait_for_gps(300)
            ap.mode(GUIDED)
            ap.arm(120)
            ap.takeoff(ALT)
        origins = []
        for ap in aps:
            origin = ap.estimate().position
            origins.append(origin)
            settle(ap, origin[0], origin[1], ALT, 0.3, 300)
        worst = 0.0
        for ap, origin in zip(aps, origins, strict=True):
            h, v = collect(ap, 2.0).worst(origin[0], origin[1], ALT)
            worst = max(worst, h, v)
        for ap in aps:
            ap.mode(LAND)
        for ap in aps:
            ap.wait_for(
                "the automatic disarm after landing",
                lambda m, ap=ap: m.get_srcSystem() == ap.target and not ap.armed(m),
                300,
                "HEARTBEAT",
            )
    finally:
        cpu_ap, cpu_flyloop, _ = stop(sitl, aps)
    return fleet_result(sitl, worst, cpu_flyloop, sum(cpu_ap))


def main() -> int:
    a = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    a.add_argument("--vehicles", type=int, default=8)
    a.add_argument("--runs", type=int, default=1)
    a.add_argument("--speed-factor", type=float, default=0.0)
    a.add_argument(
        "--stock", action="store_true", help="the Iris's parameters only (1200 Hz, logging)"
    )
    args = a.parse_args()
    parm = str(PARM) if args.stock else f"{PARM},{FLEET_PARM}"
    build = ardupilot_build(Path(tempfile.mkdtemp(prefix="bench-ap-build-")))
    binary = find_sitl_binary(build=True)
    print(machine_line())
    print(f"flyloop {binary}, ArduPilot parameters {parm}")
    ok = True
    for k in range(args.runs):
        start = time.monotonic()
        r = run(binary, build, args.vehicles, args.speed_factor, parm)
        ok &= held(r)
        print(run_line(k, args.vehicles, "ArduPilot", r, start), flush=True)
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
