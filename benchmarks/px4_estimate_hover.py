"""A long hover through the real PX4 at its default takeoff height (2.5 m), PX4's estimate
(LOCAL_POSITION_NED) against flyloop's truth: how far the truth wanders while PX4 holds its
estimate, and the largest estimate error (from 20 s after arming: the climb is over).

    FLYLOOP_PX4=... .venv/bin/python benchmarks/px4_estimate_hover.py [--seconds 900] \\
        [--config FILE] [--speed 4]

Prints one line: the true height's range and the largest height and horizontal errors.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "tests" / "px4"))
sys.path.insert(0, str(REPO / "tests" / "sitl"))

import px4_support  # noqa: E402
from estimate_record import Recorder, compare  # noqa: E402
from flyloop import find_sitl_binary  # noqa: E402


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--seconds", type=float, default=900.0, help="hover, simulated s")
    parser.add_argument("--config", type=Path, help="flyloop-sitl --config (default: Iris)")
    parser.add_argument("--speed", type=float, default=px4_support.SPEED)
    args = parser.parse_args()
    px4_support.SPEED = args.speed
    px4_support.TAKEOFF_ALT = 2.5  # PX4's MIS_TAKEOFF_ALT default
    root = px4_support.px4_root(px4_support.fresh_dir("px4-build-"))
    instance = px4_support.free_instance()
    extra = ("--config", str(args.config)) if args.config else ()
    work = px4_support.fresh_dir("px4-hover-")
    flyloop = px4_support.Flyloop(find_sitl_binary(), instance, work, *extra)
    px4 = px4_support.Px4(root, instance, px4_support.fresh_dir("px4-work-"), EKF2_REQ_GPS_H=10)
    try:
        px4.heartbeat(60)
        recorder = Recorder(
            px4.link, "LOCAL_POSITION_NED", lambda m: (m.time_boot_ms, m.x, m.y, m.z)
        )
        px4.arm_when_ready(90)
        armed = recorder.now_ms()
        px4.takeoff()
        frame = px4.frame()
        recorder.wait_until(armed + args.seconds * 1000, px4)
    finally:
        px4.kill()
        flyloop.stop()
    track = [r for r in flyloop.rows() if r["connection"] == 1]
    samples = [(t, *frame.to_flyloop((x, y, z))) for t, x, y, z in recorder.samples]
    flight = compare(track, samples, armed + 20_000)
    height, horizontal = flight.worst()
    heights = [-r["down"] for r in flight.rows]
    print(
        f"{args.seconds:.0f} s hover: true height {min(heights):.2f}..{max(heights):.2f} m, "
        f"max |height error| {height:.3f} m, horizontal {horizontal:.3f} m"
    )


if __name__ == "__main__":
    main()
