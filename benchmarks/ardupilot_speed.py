"""How fast ArduCopter + flyloop run in lockstep through ArduPilot's JSON interface, and what
share of the CPU flyloop takes; with --px4, the same for PX4 right after (benchmarks/px4_speed.py)
so both stand side by side from one run.

Starts flyloop-sitl --ardupilot with `--speed-factor 0` (no pacing: each frame answered as
soon as it comes) and an ArduCopter SITL build from $FLYLOOP_ARDUPILOT with `--speedup`
(ArduPilot paces itself to that many times real time; a high value means as fast as it can),
arms it in GUIDED, takes off to 5 m and, while it hovers, measures over a wall-clock window:

- the real-time factor: ArduPilot's clock (= flyloop's physics time) advanced per wall second,
- CPU seconds of flyloop and of ArduPilot (utime + stime from /proc) and their ratio,
- flyloop's CPU per frame (1/1200 s of physics by default), and its own work per frame
  (decode, physics, IMU, JSON; from its counters: no socket calls).

    FLYLOOP_ARDUPILOT=... .venv/bin/python benchmarks/ardupilot_speed.py [--seconds 10]
        [--speedup 100] [--px4 --px4-speed 20]   (--px4 needs FLYLOOP_PX4 too)

Run it on a quiet machine (nothing compiling).
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "tests" / "ardupilot"))
sys.path.insert(0, str(REPO / "tests" / "sitl"))

import ardupilot_support as aps  # noqa: E402
from flyloop import find_sitl_binary  # noqa: E402
from proc_cpu import cpu_seconds  # noqa: E402


def fly_and_time(
    seconds: float, preset: Path | None = None
) -> tuple[float, float, float, float, dict]:
    """Takes ArduPilot off over flyloop (--speed-factor 0) and times `seconds` of the hover:
    (simulated s, wall s, flyloop CPU s, ArduPilot CPU s, flyloop's counters). `preset`: a
    frame preset flown with its .parm beside it (as tests/ardupilot/test_ardupilot_frames.py)."""
    build = aps.ardupilot_build(aps.fresh_dir("ardupilot-build-"))
    work = aps.fresh_dir("ardupilot-bench-")
    preset_args = [] if preset is None else ["--config", str(preset)]
    parm = aps.PARM if preset is None else preset.resolve().with_suffix(".parm")
    flyloop = aps.Flyloop(find_sitl_binary(), work, *preset_args, speed=0)
    ap = None
    try:
        ap = aps.ArduPilot(
            build, aps.free_instance(), flyloop.port, aps.fresh_dir("apw-"), parm=parm
        )
        ap.connect()
        ap.wait_for_gps(120)
        ap.mode(aps.GUIDED)
        ap.arm()
        ap.takeoff()
        aps.settle(ap, 0.0, 0.0, aps.TAKEOFF_ALT, 0.5, 120)
        wall0, sim0 = time.monotonic(), ap.estimate().time_ms
        cpu0 = (cpu_seconds(flyloop.proc.pid), cpu_seconds(ap.proc.pid))
        # Read ArduPilot's messages all along (a full socket buffer would stall it).
        while time.monotonic() - wall0 < seconds:
            sim1 = ap.estimate().time_ms
        wall1 = time.monotonic()
        cpu1 = (cpu_seconds(flyloop.proc.pid), cpu_seconds(ap.proc.pid))
    finally:
        if ap is not None:
            ap.kill()
        flyloop.stop()
    sim = (sim1 - sim0) / 1000
    wall = wall1 - wall0
    return sim, wall, cpu1[0] - cpu0[0], cpu1[1] - cpu0[1], flyloop.counters()


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--seconds", type=float, default=10.0)
    parser.add_argument("--speedup", type=int, default=100)
    parser.add_argument("--px4", action="store_true", help="then run benchmarks/px4_speed.py")
    parser.add_argument("--px4-speed", type=int, default=20)
    parser.add_argument(
        "--config", type=Path, help="a preset (e.g. sitl/presets/ardupilot_octo_x.toml): its frame"
    )
    args = parser.parse_args()
    aps.SPEEDUP = args.speedup
    sim, wall, fly_cpu, ap_cpu, counters = fly_and_time(args.seconds, args.config)
    print(f"preset: {args.config or 'the default quad X'}")
    frames = sim * 1200  # SIM_RATE_HZ 1200: one frame per 833 us
    print(f"ArduPilot --speedup {args.speedup}, flyloop --speed-factor 0, load {os.getloadavg()}")
    print(f"real-time factor: {sim / wall:.1f}x ({sim:.1f} simulated s in {wall:.1f} wall s)")
    share = 100 * fly_cpu / ap_cpu
    print(
        f"CPU: flyloop {fly_cpu:.2f} s, ArduPilot {ap_cpu:.2f} s, flyloop/ArduPilot = {share:.1f} %"
    )
    print(f"flyloop CPU per frame (incl. syscalls): {1e6 * fly_cpu / frames:.1f} us")
    print(f"ArduPilot CPU per frame: {1e6 * ap_cpu / frames:.1f} us")
    print(
        "flyloop own work per frame (physics + IMU): "
        f"{counters['physics_us_per_step']} us; per datagram incl. decoding and JSON: "
        f"{counters['handling_us_per_datagram']} us"
    )
    sys.stdout.flush()
    if args.px4:
        print(
            f"\nPX4 (benchmarks/px4_speed.py --seconds {args.seconds:g} "
            f"--px4-speed {args.px4_speed}):"
        )
        sys.stdout.flush()
        script = REPO / "benchmarks" / "px4_speed.py"
        subprocess.run(
            [
                sys.executable,
                str(script),
                "--seconds",
                f"{args.seconds:g}",
                "--px4-speed",
                str(args.px4_speed),
            ],
            check=True,
        )


if __name__ == "__main__":
    main()
