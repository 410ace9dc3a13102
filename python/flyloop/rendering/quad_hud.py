"""The quadrotor view's overlays: info panel, motor bars, axis gizmo, wind dial, legend."""

from __future__ import annotations

import math

import numpy as np

from . import quad_world as qw
from .camera import OrbitCamera
from .geometry import ROTOR_NAMES, ROTOR_SPIN, euler_rpy
from .painter import Painter
from .scene import QuadScene

TEXT = (20, 20, 30)
PANEL = (255, 255, 236)
BAD = (200, 0, 0)


def info_lines(scene: QuadScene) -> list[tuple[str, tuple[int, int, int]]]:
    """The info panel's text: time, step, distance, height, speed, wind, attitude, reward."""
    roll, pitch, yaw = (math.degrees(a) for a in euler_rpy(scene.quaternion))
    distance = (
        f"{np.linalg.norm(scene.target - scene.position):.2f} m"
        if scene.target is not None
        else "-"
    )
    reward = "-" if scene.reward is None else f"{scene.reward:+.3f}"
    lines = [
        (f"Time {scene.time_s:.2f} s    Step {scene.step}", TEXT),
        (f"Distance {distance}    Height {scene.position[2]:.2f} m", TEXT),
        (
            f"Speed {np.linalg.norm(scene.velocity):.2f} m/s    "
            f"Wind {np.linalg.norm(scene.wind):.2f} m/s",
            TEXT,
        ),
        (f"Roll {roll:+.1f}°  Pitch {pitch:+.1f}°  Yaw {yaw:+.1f}°", TEXT),
    ]
    if scene.episode_return is not None:
        lines.append((f"Reward {reward}    Return {scene.episode_return:.2f}", TEXT))
    else:
        lines.append((f"Reward {reward}", TEXT))
    if scene.waypoints_reached is not None:
        lines.append((f"Waypoints reached {scene.waypoints_reached}", TEXT))
    if scene.status:
        lines.append((scene.status[:1].upper() + scene.status[1:], BAD))
    lines.extend((f"{label}: {text}", TEXT) for label, text in scene.extras)
    return lines


def info_panel(p: Painter, scene: QuadScene) -> None:
    lines = info_lines(scene)
    line_h = 24
    width = max(p.text_size(t, 21)[0] for t, _ in lines) + 28
    p.panel((12, 12, width, len(lines) * line_h + 18), PANEL)
    for i, (text, color) in enumerate(lines):
        p.text(text, (26, 22 + i * line_h), color, 21, bold=(color == BAD))


def motor_bars(p: Painter, scene: QuadScene) -> None:
    """Bottom-right: one bar per motor (PX4 order), labelled with position and spin colour."""
    width, height = p.surface.get_size()
    bar_w, bar_h, gap = 26, 120, 20
    x0 = width - 4 * (bar_w + gap) - 14
    y0 = height - bar_h - 50
    p.panel((x0 - 12, y0 - 34, 4 * (bar_w + gap) + 8, bar_h + 76), PANEL)
    for i, level in enumerate(scene.motors):
        x = x0 + i * (bar_w + gap)
        fill = round(bar_h * float(level))
        p.pg.draw.rect(p.surface, (215, 215, 215), (x, y0, bar_w, bar_h))
        color = (255, round(230 * (1 - float(level))), 0)
        p.pg.draw.rect(p.surface, color, (x, y0 + bar_h - fill, bar_w, fill))
        p.pg.draw.rect(p.surface, (0, 0, 0), (x, y0, bar_w, bar_h), 1)
        p.text(f"{round(float(level) * 100)}%", (x + bar_w / 2, y0 - 6), TEXT, 17, "midbottom")
        p.disc((x + bar_w / 2, y0 - 26), 5, qw.rotor_color(i))
        spin = "CCW" if ROTOR_SPIN[i] < 0 else "CW"
        p.text(f"M{i} {ROTOR_NAMES[i]}", (x + bar_w / 2, y0 + bar_h + 4), TEXT, 17, "midtop")
        p.text(spin, (x + bar_w / 2, y0 + bar_h + 20), TEXT, 15, "midtop")


def axis_gizmo(p: Painter, camera: OrbitCamera) -> None:
    """Bottom-left: the world axes as the camera sees them (far axis drawn first)."""
    height = p.surface.get_height()
    origin = np.array([70.0, height - 70.0])
    right, up, forward = camera.basis()
    p.disc(origin, 50, (250, 250, 250), (180, 180, 180), 1)
    items = []
    for axis, color, label in ((0, qw.AXIS_X, "X"), (1, qw.AXIS_Y, "Y"), (2, qw.AXIS_Z, "Z")):
        unit = np.eye(3)[axis]
        tip = origin + np.array([unit @ right, -(unit @ up)]) * 36
        items.append((float(unit @ forward), tip, color, label))
    for _, tip, color, label in sorted(items, key=lambda item: -item[0]):
        p.arrow(origin, tip, color, 3, head_px=8)
        direction = tip - origin
        norm = float(np.hypot(*direction))
        label_at = tip + (direction / norm * 9 if norm > 1e-6 else 0)
        p.text(label, label_at, color, 19, "center", bold=True)
    p.disc(origin, 3, (0, 0, 0))


def wind_dial(p: Painter, scene: QuadScene, camera: OrbitCamera) -> None:
    """Top-right: the horizontal wind seen from above, turned so 'up' is where the camera
    looks; its length grows with speed (full radius at 5 m/s)."""
    width = p.surface.get_width()
    center = np.array([width - 70.0, 72.0])
    radius = 44.0
    p.disc(center, radius, (255, 255, 255), (0, 0, 0), 2)
    az = math.radians(camera.azimuth_deg)
    ground_right = np.array([math.cos(az), -math.sin(az), 0.0])
    ground_forward = np.array([math.sin(az), math.cos(az), 0.0])
    dial = np.array([scene.wind @ ground_right, -(scene.wind @ ground_forward)])
    speed = float(np.linalg.norm(scene.wind))
    horizontal = float(np.hypot(*dial))
    if horizontal > 0.05:
        length = radius * 0.85 * min(1.0, 0.3 + horizontal / 5.0)
        p.arrow(center, center + dial / horizontal * length, qw.WIND, 4, head_px=11)
    p.disc(center, 3, (0, 0, 0))
    p.text("Wind", (center[0], center[1] - radius - 4), TEXT, 19, "midbottom", bold=True)
    p.text(f"{speed:.2f} m/s", (center[0], center[1] + radius + 4), TEXT, 18, "midtop")
    p.text(f"vz {scene.wind[2]:+.2f}", (center[0], center[1] + radius + 20), TEXT, 16, "midtop")


LEGEND = (
    ("Drone body", qw.BODY, "disc"),
    ("CCW rotor", qw.ROTOR_CCW, "disc"),
    ("CW rotor", qw.ROTOR_CW, "disc"),
    ("Nose (front)", qw.NOSE, "line"),
    ("Target", qw.TARGET, "disc"),
    ("Next waypoint", qw.WAYPOINT, "ring"),
    ("Up vector", qw.UP, "line"),
    ("Velocity", qw.VELOCITY, "line"),
    ("Wind", qw.WIND, "line"),
    ("Trail", qw.TRAIL, "line"),
)


def legend(p: Painter) -> None:
    """Right side, under the wind dial: what each colour means."""
    width = p.surface.get_width()
    line_h = 20
    x, y = width - 168, 170
    p.panel((x - 10, y - 8, 166, len(LEGEND) * line_h + 12), PANEL)
    for i, (label, color, kind) in enumerate(LEGEND):
        cy = y + i * line_h + 8
        if kind == "disc":
            p.disc((x + 8, cy), 6, color)
        elif kind == "ring":
            p.ring((x + 8, cy), 6, color, 2)
        else:
            p.line((x, cy), (x + 18, cy), color, 3)
        p.text(label, (x + 26, cy), TEXT, 17, "midleft")


def controls_hint(p: Painter) -> None:
    """Bottom centre in a window: how to move the camera."""
    width, height = p.surface.get_size()
    hint = "drag: rotate   wheel: zoom   W/A/S/D: move   Q/E: down/up   R: reset   Esc: close"
    p.text(hint, (width / 2, height - 8), (90, 90, 100), 17, "midbottom")
