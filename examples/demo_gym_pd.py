"""A scripted PD controller flies flyloop/QuadHover-v0 through the gym env and the SITL, and
the flight is written to runs/demo/quadhover_demo.gif (docs/gym.md's GIF is drawn with
``--out docs/img/quadhover_demo.gif``).

    cargo build --release -p flyloop-sitl && .venv/bin/python examples/demo_gym_pd.py

The controller is core/examples/hover.rs ported to Python. It reads only the observation
(target − position, velocity, attitude quaternion, body rates), asks for a tilt that
accelerates the vehicle toward the target, and mixes collective thrust and body torques into
the four PX4 quad-X motors (0 front-right, 1 rear-left, 2 front-left, 3 rear-right).
World ENU, body FLU.
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from pathlib import Path

import flyloop  # noqa: F401  (registers the envs)
import gymnasium as gym
import numpy as np
from flyloop.rendering import save_video

ROOT = Path(__file__).resolve().parents[1]
# runs/ is git-ignored: running the demo leaves the checkout clean.
DEFAULT_GIF = ROOT / "runs" / "demo" / "quadhover_demo.gif"

# The core's default quadrotor (docs/parameters.md).
MASS = 1.0
GRAVITY = 9.81
INERTIA = (0.01, 0.01, 0.02)
THRUST_COEFFICIENT = 10.0
ARM_LENGTH = 0.1
YAW_TORQUE_COEFFICIENT = 0.02


def euler_from_quaternion(w: float, x: float, y: float, z: float) -> tuple[float, float, float]:
    """Roll, pitch, yaw (ZYX) of a body → world quaternion."""
    roll = math.atan2(2.0 * (w * x + y * z), 1.0 - 2.0 * (x * x + y * y))
    pitch = math.asin(max(-1.0, min(1.0, 2.0 * (w * y - z * x))))
    yaw = math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))
    return roll, pitch, yaw


def _clamp(v: float, limit: float) -> float:
    return max(-limit, min(limit, v))


def pd_action(obs: np.ndarray) -> np.ndarray:
    """Motor commands in [0, 1] that steer the vehicle toward the target in a QuadHover
    observation (values 0–2 target − position, 3–5 velocity, 9–12 quaternion, 13–15 body
    rates) and hold it there."""
    ex, ey, ez = (float(v) for v in obs[0:3])
    vx, vy, vz = (float(v) for v in obs[3:6])
    roll, pitch, yaw = euler_from_quaternion(*(float(v) for v in obs[9:13]))
    wx, wy, wz = (float(v) for v in obs[13:16])
    # Desired world acceleration, limited so the demanded tilt stays small.
    ax = _clamp(1.2 * ex - 1.8 * vx, 3.0)
    ay = _clamp(1.2 * ey - 1.8 * vy, 3.0)
    az = _clamp(2.0 * ez - 2.0 * vz, 4.0)
    # Into the yaw frame: +pitch accelerates forward, +roll accelerates to the right (−y).
    s, c = math.sin(yaw), math.cos(yaw)
    forward = c * ax + s * ay
    left = -s * ax + c * ay
    pitch_wanted = _clamp(forward / GRAVITY, 0.35)
    roll_wanted = _clamp(-left / GRAVITY, 0.35)
    tx = INERTIA[0] * (60.0 * (roll_wanted - roll) - 12.0 * wx)
    ty = INERTIA[1] * (60.0 * (pitch_wanted - pitch) - 12.0 * wy)
    tz = INERTIA[2] * (4.0 * (0.0 - yaw) - 3.0 * wz)
    tilt = max(math.cos(roll) * math.cos(pitch), 0.5)
    thrust = MASS * (GRAVITY + az) / tilt
    # Squared motor states from thrust and torques: the inverse of the quad-X mixing.
    k = THRUST_COEFFICIENT
    lever = ARM_LENGTH * math.sqrt(0.5)
    base = thrust / (4.0 * k)
    r = tx / (4.0 * k * lever)
    q = ty / (4.0 * k * lever)
    y = tz / (4.0 * k * YAW_TORQUE_COEFFICIENT)
    squares = (base - r - q - y, base + r + q - y, base + r - q + y, base - r + q + y)
    return np.array([min(1.0, math.sqrt(max(0.0, v))) for v in squares], np.float32)


def fly(
    seed: int = 3,
    seconds: float = 6.0,
    frame_every: int = 4,
    frame_width: int = 480,
    sitl_path: str | None = None,
    **env_kwargs,
) -> dict:
    """Flies one episode with pd_action; returns the distances per step, the frames (every
    `frame_every`-th step, scaled to `frame_width`), the return and how the episode ended."""
    from PIL import Image

    env = gym.make(
        "flyloop/QuadHover-v0",
        render_mode="rgb_array",
        max_steps=round(seconds / 0.01),
        sitl_path=sitl_path,
        **env_kwargs,
    )
    frames: list[np.ndarray] = []
    distances: list[float] = []
    episode_return = 0.0
    try:
        obs, info = env.reset(seed=seed)
        step = 0
        while True:
            if step % frame_every == 0:
                image = Image.fromarray(env.render())
                height = round(image.height * frame_width / image.width)
                frames.append(np.asarray(image.resize((frame_width, height), Image.LANCZOS)))
            obs, reward, terminated, truncated, info = env.step(pd_action(obs))
            episode_return += reward
            distances.append(float(info["distance_to_target"]))
            step += 1
            if terminated or truncated:
                break
        return dict(
            distances=np.array(distances),
            frames=frames,
            episode_return=episode_return,
            terminated=terminated,
            truncated=truncated,
            info=info,
            fps=1.0 / (env.unwrapped.dt * frame_every),
        )
    finally:
        env.close()


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--seed", type=int, default=3, help="episode seed (target and wind)")
    parser.add_argument("--seconds", type=float, default=6.0, help="flight time, s")
    parser.add_argument("--out", type=Path, default=DEFAULT_GIF, help="GIF to write")
    parser.add_argument("--no-wind", action="store_true", help="switch the wind off")
    args = parser.parse_args(argv)

    start = time.perf_counter()
    kwargs = {"use_wind": False} if args.no_wind else {}
    flight = fly(seed=args.seed, seconds=args.seconds, **kwargs)
    save_video(flight["frames"], args.out, fps=flight["fps"])
    d = flight["distances"]
    ending = "time limit reached" if flight["truncated"] else "terminated (crash/out of bounds)"
    print(f"QuadHover-v0, seed {args.seed}, PD controller through the gym env and the SITL:")
    for t in (0.5, 1.0, 2.0, 3.0, 4.0, 5.0, args.seconds):
        i = min(len(d), round(t / 0.01)) - 1
        print(f"  t = {t:4.1f} s  distance to target {d[i]:.3f} m")
    print(f"  {ending} after {len(d)} steps, return {flight['episode_return']:.1f}")
    seconds = time.perf_counter() - start
    print(f"  wrote {args.out} ({len(flight['frames'])} frames) in {seconds:.1f} s")
    return 0 if flight["truncated"] else 1


if __name__ == "__main__":
    sys.exit(main())
