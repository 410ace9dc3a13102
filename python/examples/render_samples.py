"""Render one sample frame per model from hand-built scenes (no SITL needed).

    python python/examples/render_samples.py [--out docs/img] [--gif]

Writes quadrotor_frame.png and lander2d_frame.png (and, with --gif, a short GIF of each) to
--out. The scenes follow made-up smooth trajectories so the trail, path and shades show.
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path

import numpy as np
from PIL import Image

from flyloop.rendering import LanderScene, LanderView, QuadrotorView, QuadScene, save_video

REPO = Path(__file__).resolve().parents[2]


def quaternion_from_euler(roll: float, pitch: float, yaw: float) -> np.ndarray:
    """The unit quaternion [w, x, y, z] of intrinsic Z-Y-X angles in radians."""
    cr, sr = math.cos(roll / 2), math.sin(roll / 2)
    cp, sp = math.cos(pitch / 2), math.sin(pitch / 2)
    cy, sy = math.cos(yaw / 2), math.sin(yaw / 2)
    w, x = cr * cp * cy + sr * sp * sy, sr * cp * cy - cr * sp * sy
    y, z = cr * sp * cy + sr * cp * sy, cr * cp * sy - sr * sp * cy
    return np.array([w, x, y, z])


def quad_scenes(steps: int = 90) -> list[QuadScene]:
    """A quadrotor in the Waypoints task curving toward its target in a south-east wind."""
    dt = 0.02
    target = np.array([0.8, 0.7, 2.0])
    scenes, total = [], 0.0
    for i in range(steps):
        t = i / (steps - 1)
        position = np.array([-1.1 + 1.3 * t, -0.9 + 0.9 * math.sin(1.7 * t), 0.9 + 0.7 * t])
        velocity = np.array([1.3, 0.9 * 1.7 * math.cos(1.7 * t), 0.7]) / (steps * dt) * 1.6
        distance = float(np.linalg.norm(target - position))
        reward = math.exp(-distance) + 0.3
        total += reward
        scenes.append(
            QuadScene(
                time_s=3.2 + i * dt,
                step=160 + i,
                position=position,
                velocity=velocity,
                quaternion=quaternion_from_euler(0.16, -0.22, math.radians(30 + 25 * t)),
                motors=(0.58, 0.49, 0.52, 0.61),
                wind=(2.1, -1.4, 0.15),
                target=target,
                next_waypoint=(-0.9, 1.1, 2.6),
                reward=reward,
                episode_return=total,
                waypoints_reached=3,
            )
        )
    return scenes


def lander_scenes(steps: int = 260) -> list[LanderScene]:
    """A Lander2D descending from its spawn zone onto a moving platform, wind from the left."""
    dt = 0.02
    scenes, total = [], 0.0
    for i in range(steps):
        t = i / (steps - 1)
        x = 21.5 + 9.0 * t - 2.0 * math.sin(math.pi * t)
        y = 43.0 - 27.0 * t + 2.0 * math.sin(2.5 * math.pi * t) * (1 - t)
        angle = -0.1 - 0.12 * math.sin(2.5 * math.pi * t) * (1 - t)
        left = 7.4 + 2.2 * math.sin(3.0 * math.pi * t + 1.0)
        right = 7.4 - 2.2 * math.sin(3.0 * math.pi * t + 1.0)
        platform_x = 17.0 + 1.5 * (i * dt) * 2.0
        reward = 2.0 * math.exp(-0.1 * math.hypot(platform_x - x, 10.5 - y) / 50.0) - 0.05
        total += reward
        scenes.append(
            LanderScene(
                time_s=i * dt * 2.0,
                step=i * 2,
                position=(x, y),
                velocity=(9.0 / (steps * dt * 2.0) - 0.4, -27.0 / (steps * dt * 2.0)),
                angle=angle,
                angular_velocity=-0.3 * math.cos(2.5 * math.pi * t) * (1 - t) - 0.05,
                thrust=(left, right),
                battery=100.0 - 14.0 * t,
                platform_x=platform_x,
                platform_vx=1.5,
                wind_force=(2.5 * math.cos(0.35), 2.5 * math.sin(0.35)),
                wind_speed=5.0,
                max_steps=1000,
                reward=reward,
                episode_return=total,
            )
        )
    return scenes


def render_all(view, scenes) -> list[np.ndarray]:
    frames = [view.render(scene) for scene in scenes]
    view.close()
    return frames


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=REPO / "docs" / "img")
    parser.add_argument("--gif", action="store_true", help="also write a short GIF per model")
    args = parser.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    for name, view, scenes in (
        ("quadrotor", QuadrotorView("rgb_array"), quad_scenes()),
        ("lander2d", LanderView("rgb_array"), lander_scenes()),
    ):
        frames = render_all(view, scenes)
        png = args.out / f"{name}_frame.png"
        Image.fromarray(frames[-1]).save(png, optimize=True)
        print(f"wrote {png} ({frames[-1].shape[1]} x {frames[-1].shape[0]})")
        if args.gif:
            gif = save_video(frames[::3], args.out / f"{name}_episode.gif", fps=25)
            print(f"wrote {gif} ({len(frames[::3])} frames)")


if __name__ == "__main__":
    main()
