"""How fast PX4 + flyloop run in lockstep, and what share of the CPU flyloop takes.

Starts flyloop-sitl with `--speed-factor 0` (no pacing: each step as soon as PX4 answers) and a
PX4 SITL build from $FLYLOOP_PX4 (PX4_SIM_SPEED_FACTOR=--px4-speed), arms it, takes off to
5 m and, while it hovers, measures over a wall-clock window:

- the real-time factor: PX4's clock (= flyloop's simulation time) advanced per wall second,
- CPU seconds of flyloop and of PX4 (utime + stime from /proc) and their ratio,
- flyloop's CPU per 4 ms step, and its own work per step (physics + sensors + encoding, from
  its counters: no socket calls).

    FLYLOOP_PX4=... .venv/bin/python benchmarks/px4_speed.py [--seconds 10] [--px4-speed 10] \
        [--view] [--config sitl/presets/px4_hexa_x.toml]

`--view`: the same with the live view connected (flyloop-sitl --view, `python -m flyloop.view`
talking to PX4's ground-station port for its estimate: docs/view.md), to measure its cost.

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

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "tests" / "px4"))
sys.path.insert(0, str(REPO / "tests" / "sitl"))

import px4_support  # noqa: E402
from flyloop import find_sitl_binary  # noqa: E402
from proc_cpu import cpu_seconds  # noqa: E402


def _free_port(kind: int) -> int:
    with socket.socket(socket.AF_INET, kind) as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def position_time_ms(px4) -> int:
    return px4.estimate().time_ms


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--seconds", type=float, default=10.0)
    parser.add_argument("--px4-speed", type=int, default=10)
    parser.add_argument("--view", action="store_true", help="with the live view connected")
    parser.add_argument(
        "--config", type=Path, help="a preset (e.g. sitl/presets/px4_hexa_x.toml): its frame"
    )
    args = parser.parse_args()
    px4_support.SPEED = args.px4_speed
    root = px4_support.px4_root(px4_support.fresh_dir("px4-build-"))
    instance = px4_support.free_instance()
    work = px4_support.fresh_dir("px4-bench-")
    # Unpaced: each step as soon as PX4 answers.
    view_args = view = None
    if args.view:
        truth = _free_port(socket.SOCK_DGRAM)
        view_args = ["--view", f"127.0.0.1:{truth}"]
    binary = find_sitl_binary()
    preset_args, mixer = [], {}
    if args.config is not None:
        # The autopilot's mixer for the preset's frame (as tests/px4/test_px4_frames.py).
        preset_args = ["--config", str(args.config)]
        mixer = px4_support.autopilot_params(binary, args.config, "px4")
    flyloop = px4_support.Flyloop(binary, instance, work, *preset_args, *(view_args or []), speed=0)
    px4 = None
    try:
        px4 = px4_support.Px4(root, instance, px4_support.fresh_dir("px4-work-"), **mixer)
        if args.view:
            view = subprocess.Popen(
                [
                    sys.executable, "-m", "flyloop.view", "--listen", f"127.0.0.1:{truth}",
                    "--connect", f"127.0.0.1:{18570 + instance}", "--wait", "120",
                    "--web-port", str(_free_port(socket.SOCK_STREAM)),
                    "--grpc-port", str(_free_port(socket.SOCK_STREAM)),
                ],
                stdout=subprocess.DEVNULL,
            )  # fmt: skip
        px4.heartbeat(60)
        px4.arm_when_ready(60)
        px4.takeoff()
        home = px4.home()
        target = (home[0], home[1], home[2] - px4_support.TAKEOFF_ALT)
        px4_support.settle(px4, target, 0.5, 120)
        wall0, sim0 = time.monotonic(), position_time_ms(px4)
        cpu0 = (cpu_seconds(flyloop.proc.pid), cpu_seconds(px4.proc.pid))
        # Read PX4's estimates all along (a full socket buffer would drop the newest).
        while time.monotonic() - wall0 < args.seconds:
            sim1 = position_time_ms(px4)
        wall1 = time.monotonic()
        cpu1 = (cpu_seconds(flyloop.proc.pid), cpu_seconds(px4.proc.pid))
    finally:
        if px4 is not None:
            px4.kill()
        if view is not None:
            px4_support.stop(view, signal.SIGINT)
        flyloop.stop()
    sim = (sim1 - sim0) / 1000
    wall = wall1 - wall0
    fly_cpu, px4_cpu = cpu1[0] - cpu0[0], cpu1[1] - cpu0[1]
    steps = sim / 0.004
    stats = flyloop.stderr().split("stopped: ", 1)[1].split()
    counters = dict(kv.split("=") for kv in stats)
    print(f"preset: {args.config or 'the default quad X'}; with the live view: {args.view}")
    print(f"load {os.getloadavg()[0]:.2f}")
    print(f"real-time factor: {sim / wall:.1f}x ({sim:.1f} simulated s in {wall:.1f} wall s)")
    share = 100 * fly_cpu / px4_cpu
    print(f"CPU: flyloop {fly_cpu:.2f} s, PX4 {px4_cpu:.2f} s, flyloop/PX4 = {share:.1f} %")
    print(f"flyloop CPU per 4 ms step (incl. syscalls): {1e6 * fly_cpu / steps:.1f} us")
    print(
        "flyloop own work per step (physics + sensors + encoding): "
        f"{counters['physics_us_per_step']} us; per read incl. decoding: "
        f"{counters['handling_us_per_datagram']} us"
    )


if __name__ == "__main__":
    main()
