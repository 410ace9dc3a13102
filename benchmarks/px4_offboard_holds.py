"""Waypoint holds through the real PX4, side by side: the shipped rates policy
(examples/px4_offboard.py) against PX4's own position controller flying the same targets
(`--controller px4`), on the stock Iris and on the unseen vehicle (mass +20 %, thrust
coefficient −10 %: sitl/presets/px4_iris_unseen.toml). One fresh flyloop + PX4 pair per run.

    FLYLOOP_PX4=... .venv/bin/python benchmarks/px4_offboard_holds.py [--policy DIR] \\
        [--waypoints "0,0,3;2,0,3;2,2,4"] [--hold 5] [--speed 4]

Prints one row per run: mean hold error per waypoint and over all, and the largest error.
"""

from __future__ import annotations

import argparse
import re
import subprocess
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "tests" / "px4"))

import px4_support  # noqa: E402
from flyloop import find_sitl_binary  # noqa: E402

UNSEEN = REPO / "sitl" / "presets" / "px4_iris_unseen.toml"


def run(root: Path, policy: Path, controller: str, config: Path | None, args) -> str:
    instance = px4_support.free_instance()
    work = px4_support.fresh_dir("px4-holds-")
    extra = ("--config", str(config)) if config else ()
    flyloop = px4_support.Flyloop(find_sitl_binary(), instance, work, *extra)
    px4 = None
    try:
        px4 = px4_support.Px4(root, instance, px4_support.fresh_dir("px4-work-"))
        result = subprocess.run(
            [
                sys.executable,
                str(REPO / "examples" / "px4_offboard.py"),
                str(policy),
                "--controller",
                controller,
                "--connect",
                f"udpout:127.0.0.1:{14580 + instance}",
                "--waypoints",
                args.waypoints,
                "--hold",
                str(args.hold),
            ],
            capture_output=True,
            text=True,
            timeout=600,
        )
    finally:
        if px4 is not None:
            px4.kill()
        flyloop.stop()
    if result.returncode != 0:
        return f"failed ({result.returncode}): {result.stderr.strip()[-300:]}"
    means = re.findall(r"hold error mean ([\d.]+) m", result.stdout)
    overall = re.search(r"mean hold error ([\d.]+) m", result.stdout).group(1)
    worst = re.search(r"max hold error ([\d.]+) m", result.stdout).group(1)
    return f"{' / '.join(means)} | {overall} | {worst}"


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--policy", type=Path, default=REPO / "policies" / "px4_offboard_hover")
    parser.add_argument("--waypoints", default="0,0,3;2,0,3;2,2,4")
    parser.add_argument("--hold", type=float, default=5.0)
    parser.add_argument("--speed", type=int, default=4, help="simulation speed factor")
    args = parser.parse_args()
    px4_support.SPEED = args.speed
    root = px4_support.px4_root(px4_support.fresh_dir("px4-build-"))
    print(f"waypoints {args.waypoints} (N,E,U m from home), hold {args.hold} s each")
    print("| controller | vehicle | mean hold error per waypoint, m | mean, m | max, m |")
    print("|---|---|---|---|---|")
    for controller in ("policy", "px4"):
        for vehicle, config in (("Iris", None), ("unseen (mass +20 %, thrust -10 %)", UNSEEN)):
            row = run(root, args.policy, controller, config, args)
            name = "rates policy" if controller == "policy" else "PX4 position controller"
            print(f"| {name} | {vehicle} | {row} |", flush=True)


if __name__ == "__main__":
    main()
