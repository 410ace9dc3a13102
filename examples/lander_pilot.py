"""A scripted landing pilot for flyloop/Lander2D (no learning): it shows the task is feasible
and is the baseline the trained policies are compared with.

    .venv/bin/python examples/lander_pilot.py --episodes 50            # static pad
    .venv/bin/python examples/lander_pilot.py --episodes 50 --moving   # moving pad

A cascaded controller on the env's info (position, velocity, angle, angular rate, platform
position) and, for a moving pad, the observation's platform velocity: velocity targets from
the position error (toward the pad, and down once within 2 m of its centre), accelerations from the
velocity error with an integral term that cancels the episode's constant wind, a tilt and a
collective thrust from the acceleration, and two motor commands from the collective and an
attitude PD. The same pilot, in Rust, is the core's "hovering earns less than landing" test
(core/tests/lander2d_reward.rs).
"""

from __future__ import annotations

import argparse
import math
import sys
from collections.abc import Mapping
from typing import Any

import flyloop  # noqa: F401  (registers the envs)
import gymnasium as gym
import numpy as np

# The core's default Lander2D (docs/parameters.md).
MASS = 1.5  # kg
GRAVITY = 9.81  # m/s²
MAX_THRUST = 15.0  # N per motor
INERTIA = 0.21625  # kg·m², composite of the frame and two motor boxes
MOTOR_ARM = 0.4  # m, motor centre from the body centre
HALF_HEIGHT = 0.1  # m
DT = 0.02  # s
PLATFORM_SPEED = 1.5  # m/s


def _clamp(v: float, lo: float, hi: float) -> float:
    return max(lo, min(hi, v))


class LanderPilot:
    """Motor commands for one episode; call :meth:`reset` at every episode start."""

    def __init__(self, platform_speed: float = PLATFORM_SPEED) -> None:
        self.platform_speed = platform_speed
        self.integral = [0.0, 0.0]

    def reset(self) -> None:
        self.integral = [0.0, 0.0]

    def act(self, obs: np.ndarray, info: Mapping[str, Any]) -> np.ndarray:
        x, y = (float(v) for v in info["position"])
        vx, vy = (float(v) for v in info["velocity"])
        angle = float(info["angle"])
        rate = float(info["angular_velocity"])
        px, top = (float(v) for v in info["platform_position"])
        pvx = float(obs[11]) * self.platform_speed if len(obs) > 11 else 0.0
        ex = px - x
        height = y - top - HALF_HEIGHT
        vx_target = pvx + _clamp(0.6 * ex, -4.0, 4.0)
        if abs(ex) < 2.0:  # over the pad (half width 2.5 m): descend, slowing near it
            vy_target = -_clamp(0.4 * height + 0.3, 0.3, 5.0)
        else:  # approach 3 m above it
            vy_target = _clamp(0.8 * (3.0 - height), -5.0, 3.0)
        err = (vx_target - vx, vy_target - vy)
        self.integral = [
            _clamp(i + e * DT, -3.0, 3.0) for i, e in zip(self.integral, err, strict=True)
        ]
        ax = 1.5 * err[0] + self.integral[0]
        ay = 2.0 * err[1] + self.integral[1]
        # Touch down nearly level (the limit is 0.2 rad): drifting with the wind is safer.
        max_tilt = 0.16 if height < 1.0 else 0.35
        tilt = _clamp(-math.atan2(ax, GRAVITY + ay), -max_tilt, max_tilt)
        collective = _clamp(MASS * (GRAVITY + ay) / math.cos(tilt), 0.0, 2.0 * MAX_THRUST)
        torque = INERTIA * (20.0 * (tilt - angle) - 8.0 * rate)
        half = torque / (2.0 * MOTOR_ARM)
        thrust = (collective / 2.0 - half, collective / 2.0 + half)
        return np.array([_clamp(2.0 * t / MAX_THRUST - 1.0, -1.0, 1.0) for t in thrust], np.float32)


def fly(env: gym.Env, seed: int, pilot: LanderPilot | None = None) -> dict[str, Any]:
    """One episode: return, steps, landed and the last info."""
    pilot = pilot or LanderPilot()
    pilot.reset()
    obs, info = env.reset(seed=seed)
    total, steps = 0.0, 0
    while True:
        obs, reward, terminated, truncated, info = env.step(pilot.act(obs, info))
        total += float(reward)
        steps += 1
        if terminated or truncated:
            return {"return": total, "steps": steps, "landed": bool(info["landed"]), "info": info}


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--episodes", type=int, default=50)
    parser.add_argument("--seed-offset", type=int, default=0)
    parser.add_argument("--moving", action="store_true", help="moving platform")
    parser.add_argument("--env", default="flyloop/Lander2D-v1")
    parser.add_argument(
        "--backend",
        default="native",
        choices=("native", "sitl"),
        help="the core in this process (default) or a flyloop-sitl process: same episodes",
    )
    args = parser.parse_args(argv)
    if args.episodes < 1:
        parser.error("--episodes must be >= 1")
    env = gym.make(args.env, moving_platform=args.moving, backend=args.backend)
    try:
        flights = [fly(env, args.seed_offset + i) for i in range(args.episodes)]
    finally:
        env.close()
    landed = sum(f["landed"] for f in flights)
    speeds = [float(f["info"]["touchdown_speed"]) for f in flights if f["landed"]]
    print(
        f"{args.env}, {'moving' if args.moving else 'static'} pad, seeds "
        f"{args.seed_offset}..{args.seed_offset + args.episodes - 1}: landed {landed} of "
        f"{args.episodes} ({100 * landed / args.episodes:.0f} %), mean return "
        f"{np.mean([f['return'] for f in flights]):.1f}"
        + (f", touchdown speed mean {np.mean(speeds):.2f} m/s" if speeds else "")
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
