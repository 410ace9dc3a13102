"""The Lander2D picture, one function per element, drawn in this order by LanderView."""

from __future__ import annotations

import math

import numpy as np

from .painter import Painter, rotate2d
from .plane import PlaneView
from .scene import LanderScene

SKY_TOP = (196, 220, 246)
SKY_BOTTOM = (226, 238, 250)
OUTSIDE = (120, 130, 145)
GROUND = (96, 148, 82)
GROUND_EDGE = (62, 112, 58)
BOUNDS = (200, 70, 70)
SPAWN = (178, 160, 80)
PLATFORM = (150, 150, 170)
PLATFORM_EDGE = (50, 50, 60)
PLATFORM_TOP = (245, 200, 40)
FRAME = (52, 72, 168)
MOTOR = (36, 48, 120)
OUTLINE = (10, 10, 20)
SHADE = (70, 90, 180)
PATH = (16, 19, 97)
SENSOR = (230, 120, 20)
THRUST_TRACK = (170, 170, 170)
THRUST = (235, 50, 50)
WIND = (50, 50, 200)
TEXT = (15, 15, 25)
GOOD = (0, 140, 0)
BAD = (200, 0, 0)

THRUST_BAR_PX = 40  # a full-thrust bar's length, as the reference (docs/reference/lander2d.md)


def background(p: Painter, plane: PlaneView, s: LanderScene) -> None:
    """Grey outside the world, a sky gradient (by altitude) inside it."""
    p.fill(OUTSIDE)
    width, height = p.surface.get_size()
    (u0, v_top), (u1, v_bottom) = plane.to_screen(
        np.array([[0.0, s.world_height], [s.world_width, 0.0]])
    )
    left, right = max(0, round(u0)), min(width, round(u1))
    top, bottom = max(0, round(v_top)), min(height, round(v_bottom))
    span = max(1.0, v_bottom - v_top)
    for v in range(top, bottom, 4):
        t = (v - v_top) / span
        color = tuple(round(a + (b - a) * t) for a, b in zip(SKY_TOP, SKY_BOTTOM, strict=True))
        p.pg.draw.rect(p.surface, color, (left, v, right - left, min(4, bottom - v)))


def ground(p: Painter, plane: PlaneView, s: LanderScene) -> None:
    top_left = plane.to_screen((0.0, s.ground_height))
    bottom_right = plane.to_screen((s.world_width, 0.0))
    rect = (*top_left, *(bottom_right - top_left))
    p.pg.draw.rect(p.surface, GROUND, tuple(round(x) for x in rect))
    p.line(top_left, (bottom_right[0], top_left[1]), GROUND_EDGE, 4)


def bounds(p: Painter, plane: PlaneView, s: LanderScene) -> None:
    w, h = s.world_width, s.world_height
    corners = plane.to_screen(np.array([[0, 0], [w, 0], [w, h], [0, h], [0, 0]], dtype=float))
    for a, b in zip(corners[:-1], corners[1:], strict=True):
        p.dashed_line(a, b, BOUNDS, 2, dash_px=8)


def spawn_zone(p: Painter, plane: PlaneView, s: LanderScene) -> None:
    r = s.spawn_half_range
    if r <= 0:
        return
    cx, cy = s.spawn_center
    lo = plane.to_screen((cx - r, cy + r))
    hi = plane.to_screen((cx + r, cy - r))
    p.pg.draw.rect(p.surface, SPAWN, (*np.round(lo), *np.round(hi - lo)), 1)
    p.text("spawn zone", (lo[0] + 4, lo[1] + 3), SPAWN, 16)


def platform(p: Painter, plane: PlaneView, s: LanderScene) -> None:
    half = s.platform_width / 2.0
    x0, x1 = s.platform_x - half, s.platform_x + half
    y0, y1 = s.ground_height, s.ground_height + s.platform_height
    box = plane.to_screen(np.array([[x0, y0], [x1, y0], [x1, y1], [x0, y1]]))
    p.polygon(box, PLATFORM, PLATFORM_EDGE, 2)
    p.line(box[3], box[2], PLATFORM_TOP, 3)
    if abs(s.platform_vx) > 1e-6:
        mid = plane.to_screen((s.platform_x, y0 - 0.6))
        tip = mid + np.array(
            [math.copysign(min(30.0, 12 + 8 * abs(s.platform_vx)), s.platform_vx), 0]
        )
        p.arrow(mid, tip, PLATFORM_EDGE, 2, head_px=7)


def path(p: Painter, plane: PlaneView, points: np.ndarray) -> None:
    if len(points) >= 2:
        p.polyline(plane.to_screen(points), PATH, 1)


def _drone_parts(s: LanderScene, x: float, y: float, angle: float) -> list[np.ndarray]:
    """World polygons of the frame and the two motors (the core's three colliders)."""
    w, h = s.drone_width, s.drone_height
    motor_x = (w - h) / 2.0
    frame = np.array([[-motor_x, -h / 4], [motor_x, -h / 4], [motor_x, h / 4], [-motor_x, h / 4]])
    square = np.array([[-h / 2, -h / 2], [h / 2, -h / 2], [h / 2, h / 2], [-h / 2, h / 2]])
    parts = [frame, square + [-motor_x, 0.0], square + [motor_x, 0.0]]
    return [rotate2d(part, angle) + [x, y] for part in parts]


def shades(p: Painter, plane: PlaneView, s: LanderScene, poses: list) -> None:
    for x, y, angle in poses:
        for part in _drone_parts(s, x, y, angle):
            p.translucent_polygon(plane.to_screen(part), SHADE, 95)


def sensor_line(p: Painter, plane: PlaneView, s: LanderScene, label: bool = True) -> None:
    a = plane.to_screen(s.position)
    b = plane.to_screen(s.platform_top)
    p.dashed_line(a, b, SENSOR, 2, dash_px=7)
    p.disc(b, 4, SENSOR)
    if not label:
        return
    mid = (a + b) / 2.0
    p.text(f"{s.distance_to_platform:.1f} m", (mid[0] + 8, mid[1]), SENSOR, 18, "midleft", True)


def drone(p: Painter, plane: PlaneView, s: LanderScene) -> None:
    x, y = s.position
    frame, left, right = _drone_parts(s, x, y, s.angle)
    for part, color in ((frame, FRAME), (left, MOTOR), (right, MOTOR)):
        p.polygon(plane.to_screen(part), color, OUTLINE, 1)


def thrust_bars(
    p: Painter, plane: PlaneView, s: LanderScene, full_px: float = THRUST_BAR_PX
) -> None:
    """Over each motor, along the body's +y: grey = max thrust, red = this step's thrust."""
    motor_x = (s.drone_width - s.drone_height) / 2.0
    up = rotate2d(np.array([[0.0, 1.0]]), s.angle)[0] * np.array([1.0, -1.0])  # screen v down
    for side, thrust in ((-1.0, s.thrust[0]), (1.0, s.thrust[1])):
        attach = rotate2d(np.array([[side * motor_x, s.drone_height / 2]]), s.angle)[0]
        start = plane.to_screen(attach + s.position)
        fraction = min(max(thrust / s.max_thrust, 0.0), 1.0)
        p.line(start, start + up * full_px, THRUST_TRACK, 3)
        if fraction > 0:
            p.line(start, start + up * full_px * fraction, THRUST, 3)


def wind_indicator(p: Painter, s: LanderScene) -> None:
    """Top-right dial: arrow along the wind force, with speed and direction."""
    width = p.surface.get_width()
    center = np.array([width - 66.0, 62.0])
    p.disc(center, 36, (250, 250, 255), WIND, 2)
    magnitude = float(np.hypot(*s.wind_force))
    if magnitude > 1e-9:
        direction = s.wind_force / magnitude
        tip = center + np.array([direction[0], -direction[1]]) * 30
        p.arrow(center - (tip - center) * 0.6, tip, WIND, 3, head_px=11)
        heading = math.degrees(math.atan2(s.wind_force[1], s.wind_force[0])) % 360
        label = f"Wind {s.wind_speed:.1f} m/s @ {heading:.0f}°"
    else:
        label = "Wind: calm"
    p.text(label, (width - 20, center[1] + 42), TEXT, 19, "topright")
    p.text(f"force {magnitude:.2f} N", (width - 20, center[1] + 60), TEXT, 17, "topright")


def status_text(s: LanderScene) -> tuple[str, tuple[int, int, int]]:
    if s.landed:
        return "Landed safely!", GOOD
    if s.crashed:
        return "Crashed!", BAD
    if s.outcome:
        return s.outcome[:1].upper() + s.outcome[1:] + "!", BAD
    if s.max_steps is not None and s.step >= s.max_steps:
        return "Time limit reached", BAD
    return "Flying", TEXT


def overlay(p: Painter, plane: PlaneView, s: LanderScene) -> None:
    """Text panel over the ground band: battery, status, step, position, velocity, angle,
    angular velocity, distance, and the two motor force bars."""
    steps = f"{s.step} / {s.max_steps}" if s.max_steps is not None else f"{s.step}"
    angle_deg = math.degrees(math.remainder(s.angle, math.tau))
    status, status_color = status_text(s)
    reward = "Reward: -" if s.reward is None else f"Reward: {s.reward:+.3f}"
    if s.episode_return is not None:
        reward += f"  (return {s.episode_return:.1f})"
    columns = [
        [
            (f"Battery: {s.battery:.1f} / {s.initial_battery:.0f}", TEXT),
            (f"Status: {status}", status_color),
            (f"Step: {steps}   t = {s.time_s:.2f} s", TEXT),
            (reward, TEXT),
        ],
        [
            (f"Position: ({s.position[0]:.2f}, {s.position[1]:.2f}) m", TEXT),
            (f"Velocity: ({s.velocity[0]:+.2f}, {s.velocity[1]:+.2f}) m/s", TEXT),
            (f"Angle: {angle_deg:+.1f}°", TEXT),
            (f"Angular velocity: {s.angular_velocity:+.2f} rad/s", TEXT),
        ],
        [
            (f"Distance to platform: {s.distance_to_platform:.2f} m", TEXT),
            (f"Thrust L: {s.thrust[0]:.1f} N", TEXT),
            (f"Thrust R: {s.thrust[1]:.1f} N", TEXT),
            (f"Platform: x {s.platform_x:.1f} m, {s.platform_vx:+.1f} m/s", TEXT),
        ],
    ]
    width, height = p.surface.get_size()
    line_h, pad = 22, 10
    panel_h = 4 * line_h + 2 * pad
    ground_v = float(plane.to_screen((0.0, s.ground_height))[1])
    top = min(max(ground_v + 14, 0), height - panel_h - 16)
    rect = (16, round(top), width - 32, panel_h)
    p.panel(rect, (255, 255, 248))
    col_w = (rect[2] - 2 * pad) // 3
    for c, lines in enumerate(columns):
        x = rect[0] + pad + c * col_w
        for i, (text, color) in enumerate(lines):
            p.text(text, (x, rect[1] + pad + i * line_h), color, 19, bold=(c == 0 and i == 1))
    bar_x = rect[0] + pad + 2 * col_w + 120
    for i, thrust in enumerate(s.thrust):
        _bar(
            p,
            (bar_x, rect[1] + pad + (i + 1) * line_h + 2, col_w - 130, 11),
            thrust / s.max_thrust,
            THRUST,
        )
    fraction = s.battery / s.initial_battery
    fill = GOOD if fraction > 0.3 else (230, 150, 0) if fraction > 0.1 else BAD
    _bar(p, (rect[0] + pad + 175, rect[1] + pad + 2, col_w - 190, 11), fraction, fill)


def _bar(p: Painter, rect: tuple[int, int, int, int], fraction: float, color: tuple) -> None:
    fraction = min(max(fraction, 0.0), 1.0)
    p.pg.draw.rect(p.surface, (210, 210, 210), rect)
    p.pg.draw.rect(p.surface, color, (rect[0], rect[1], round(rect[2] * fraction), rect[3]))
    p.pg.draw.rect(p.surface, OUTLINE, rect, 1)


def world(
    p: Painter,
    plane: PlaneView,
    s: LanderScene,
    shade_poses: list,
    path_points: np.ndarray,
    *,
    spawn: bool = True,
    labels: bool = True,
    thrust_px: float = THRUST_BAR_PX,
) -> None:
    """Everything that lives in world coordinates, back to front."""
    background(p, plane, s)
    if spawn:
        spawn_zone(p, plane, s)
    ground(p, plane, s)
    bounds(p, plane, s)
    shades(p, plane, s, shade_poses)
    path(p, plane, path_points)
    platform(p, plane, s)
    sensor_line(p, plane, s, label=labels)
    drone(p, plane, s)
    thrust_bars(p, plane, s, thrust_px)


CLOSE_UP_SIZE = (250, 180)
CLOSE_UP_SCALE = 48.0  # px per metre: a 1 m drone is 48 px wide


def close_up(
    p: Painter, s: LanderScene, shade_poses: list, path_points: np.ndarray, zoom: float
) -> None:
    """A zoomed window on the drone (top-left), framed and titled; p draws on that window."""
    width, height = p.surface.get_size()
    # The drone sits a little low so its thrust bars fit above it.
    center = np.array(s.position) + np.array([0.0, 0.12 * height / CLOSE_UP_SCALE])
    plane = PlaneView.centred_on(center, CLOSE_UP_SCALE, (width, height))
    world(p, plane, s, shade_poses, path_points, spawn=False, labels=False, thrust_px=70)
    p.pg.draw.rect(p.surface, (40, 40, 50), (0, 0, width, height), 2)
    p.text(f"close-up ×{zoom:.0f}", (8, 6), TEXT, 18, bold=True)
