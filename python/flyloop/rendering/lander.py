"""The Lander2D view (task Landing): its scene, metres to pixels, the world back to front, a
close-up, the wind dial, the text panel and LanderView. x right, y up, angles CCW."""

from __future__ import annotations

import math
from collections import deque
from dataclasses import dataclass, field

import numpy as np

from ..tasks import LANDING
from .canvas import Painter, View

SKY_TOP, SKY_BOTTOM, OUTSIDE = (196, 220, 246), (226, 238, 250), (120, 130, 145)
GROUND, GROUND_EDGE, BOUNDS, SPAWN = (96, 148, 82), (62, 112, 58), (200, 70, 70), (178, 160, 80)
PLATFORM, PLATFORM_EDGE, PLATFORM_TOP = (150, 150, 170), (50, 50, 60), (245, 200, 40)
FRAME, MOTOR, OUTLINE, SHADE = (52, 72, 168), (36, 48, 120), (10, 10, 20), (70, 90, 180)
PATH, SENSOR, THRUST_TRACK, THRUST = (16, 19, 97), (230, 120, 20), (170, 170, 170), (235, 50, 50)
WIND, TEXT, GOOD, BAD = (50, 50, 200), (15, 15, 25), (0, 140, 0), (200, 0, 0)

THRUST_BAR_PX = 40  # a full-thrust bar's length, as the reference (docs/reference/lander2d.md)
CLOSE_UP_SIZE = (250, 180)
CLOSE_UP_SCALE = 48.0  # px per metre: a 1 m drone is 48 px wide
_CORE = LANDING.defaults  # what a scene shows when not told


@dataclass(eq=False)
class LanderScene:
    """One frame of the Lander2D; sizes default to the core's Lander2D defaults."""

    time_s: float  # episode time, s
    step: int  # steps since reset
    position: np.ndarray  # (2,) m, drone centre
    velocity: np.ndarray  # (2,) m/s
    angle: float  # rad, counter-clockwise
    angular_velocity: float  # rad/s, counter-clockwise
    thrust: np.ndarray  # (2,) N, (left, right) motor thrust of the last step
    battery: float  # charge left, units
    platform_x: float  # m, platform centre x
    wind_force: np.ndarray = field(default_factory=lambda: np.zeros(2))  # (2,) N on the drone
    wind_speed: float = 0.0  # m/s, for the label (the force is what acts)
    platform_vx: float = 0.0  # m/s
    landed: bool = False
    crashed: bool = False
    outcome: str = ""  # another ending: "lost control", "out of bounds", "battery empty", ...
    max_steps: int | None = None
    reward: float | None = None
    episode_return: float | None = None
    max_thrust: float = _CORE["max_thrust"]  # N per motor
    initial_battery: float = _CORE["initial_battery"]  # units
    world_width: float = _CORE["world_width"]  # m: the world is x in (0, W)
    world_height: float = _CORE["world_height"]  # m: y in (0, H)
    ground_height: float = _CORE["ground_height"]  # m
    platform_width: float = _CORE["platform_width"]  # m
    platform_height: float = _CORE["platform_height"]  # m above the ground
    drone_width: float = _CORE["drone_width"]  # m, tip to tip
    drone_height: float = _CORE["drone_height"]  # m, side of each square motor
    # (2,) m, centre of the spawn square, and its half side (0 = fixed start)
    spawn_center: np.ndarray = (_CORE["spawn_x"], _CORE["spawn_y"])
    spawn_half_range: float = _CORE["initial_pos_random_range_m"]

    def __post_init__(self) -> None:
        for name in ("position", "velocity", "thrust", "wind_force", "spawn_center"):
            setattr(self, name, np.array(getattr(self, name), float).ravel())
        self.step = int(self.step)

    @property
    def platform_top(self) -> tuple[float, float]:
        """Top centre of the platform, m: where the sensor line points."""
        return self.platform_x, self.ground_height + self.platform_height

    @property
    def distance_to_platform(self) -> float:
        """Distance from the drone centre to the platform's top centre, m."""
        tx, ty = self.platform_top
        return math.hypot(tx - self.position[0], ty - self.position[1])


@dataclass
class PlaneView:
    """Metres to pixels: a uniform scale (px per metre) and the pixel (u0, v0) of (0, 0)."""

    scale: float
    u0: float
    v0: float

    def to_screen(self, points: np.ndarray) -> np.ndarray:
        p = np.asarray(points, dtype=float)
        return np.stack([self.u0 + p[..., 0] * self.scale, self.v0 - p[..., 1] * self.scale], -1)


def fit_world(s: LanderScene, size: tuple[int, int], margin_px: int = 12) -> PlaneView:
    """The world box (0, 0)-(W, H), centred, filling the frame less margin_px per side."""
    (width, height), w, h = size, s.world_width, s.world_height
    scale = min((width - 2 * margin_px) / w, (height - 2 * margin_px) / h)
    return PlaneView(scale, (width - w * scale) / 2.0, (height + h * scale) / 2.0)


def rotate2d(points: np.ndarray, angle: float) -> np.ndarray:
    """Rotate (N, 2) points counter-clockwise by angle radians."""
    c, s = math.cos(angle), math.sin(angle)
    return np.asarray(points, dtype=float) @ np.array([[c, s], [-s, c]])


def _drone_parts(s: LanderScene, x: float, y: float, angle: float) -> list[np.ndarray]:
    """World polygons of the frame and the two motors (the core's three colliders)."""
    w, h = s.drone_width, s.drone_height
    motor_x = (w - h) / 2.0
    frame = np.array([[-motor_x, -h / 4], [motor_x, -h / 4], [motor_x, h / 4], [-motor_x, h / 4]])
    square = np.array([[-h / 2, -h / 2], [h / 2, -h / 2], [h / 2, h / 2], [-h / 2, h / 2]])
    parts = [frame, square + [-motor_x, 0.0], square + [motor_x, 0.0]]
    return [rotate2d(part, angle) + [x, y] for part in parts]


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
    """The text panel over the ground band: the state in three columns, the force bars."""
    steps = f"{s.step} / {s.max_steps}" if s.max_steps is not None else f"{s.step}"
    angle_deg = math.degrees(math.remainder(s.angle, math.tau))
    status, status_color = status_text(s)
    reward = "Reward: -" if s.reward is None else f"Reward: {s.reward:+.3f}"
    if s.episode_return is not None:
        reward += f"  (return {s.episode_return:.1f})"
    lines = [
        f"Battery: {s.battery:.1f} / {s.initial_battery:.0f}",
        f"Status: {status}",
        f"Step: {steps}   t = {s.time_s:.2f} s",
        reward,
        f"Position: ({s.position[0]:.2f}, {s.position[1]:.2f}) m",
        f"Velocity: ({s.velocity[0]:+.2f}, {s.velocity[1]:+.2f}) m/s",
        f"Angle: {angle_deg:+.1f}°",
        f"Angular velocity: {s.angular_velocity:+.2f} rad/s",
        f"Distance to platform: {s.distance_to_platform:.2f} m",
        f"Thrust L: {s.thrust[0]:.1f} N",
        f"Thrust R: {s.thrust[1]:.1f} N",
        f"Platform: x {s.platform_x:.1f} m, {s.platform_vx:+.1f} m/s",
    ]
    width, height = p.surface.get_size()
    line_h, pad = 22, 10
    panel_h = 4 * line_h + 2 * pad
    ground_v = float(plane.to_screen((0.0, s.ground_height))[1])
    top = min(max(ground_v + 14, 0), height - panel_h - 16)
    rect = (16, round(top), width - 32, panel_h)
    p.panel(rect, (255, 255, 248))
    col_w = (rect[2] - 2 * pad) // 3
    for i, text in enumerate(lines):  # three columns of four; the status bold, in colour
        at = (rect[0] + pad + i // 4 * col_w, rect[1] + pad + i % 4 * line_h)
        p.text(text, at, status_color if i == 1 else TEXT, 19, bold=i == 1)
    bar_x = rect[0] + pad + 2 * col_w + 120
    for i, thrust in enumerate(s.thrust):
        bar = (bar_x, rect[1] + pad + (i + 1) * line_h + 2, col_w - 130, 11)
        p.bar(bar, thrust / s.max_thrust, THRUST)
    fraction = s.battery / s.initial_battery
    fill = GOOD if fraction > 0.3 else (230, 150, 0) if fraction > 0.1 else BAD
    p.bar((rect[0] + pad + 175, rect[1] + pad + 2, col_w - 190, 11), fraction, fill)


def world(p: Painter, plane: PlaneView, s: LanderScene, poses, path, spawn=False, close_up=False):
    """The world back to front; a close-up has longer thrust bars and no distance label."""
    backdrop(p, plane, s, spawn)
    for x, y, angle in poses:
        for part in _drone_parts(s, x, y, angle):
            p.translucent_polygon(plane.to_screen(part), SHADE, 95)
    if len(path) >= 2:
        p.polyline(plane.to_screen(path), PATH, 1)
    platform(p, plane, s)
    sensor_line(p, plane, s, label=not close_up)
    drone(p, plane, s, 70 if close_up else THRUST_BAR_PX)


def backdrop(p: Painter, plane: PlaneView, s: LanderScene, spawn: bool) -> None:
    """Grey outside the world, a sky gradient (by altitude) inside it, the spawn zone (if
    asked), the ground and the world's dashed bounds."""
    p.surface.fill(OUTSIDE)
    corners = np.array([[0.0, s.world_height], [s.world_width, 0.0]])
    (u0, v_top), (u1, v_bottom) = plane.to_screen(corners)
    p.gradient(
        (round(u0), round(v_top), round(u1), round(v_bottom)), v_top, v_bottom, SKY_TOP, SKY_BOTTOM
    )
    r = s.spawn_half_range
    if spawn and r > 0:
        lo = plane.to_screen((s.spawn_center[0] - r, s.spawn_center[1] + r))
        hi = plane.to_screen((s.spawn_center[0] + r, s.spawn_center[1] - r))
        p.pg.draw.rect(p.surface, SPAWN, (*np.round(lo), *np.round(hi - lo)), 1)
        p.text("spawn zone", (lo[0] + 4, lo[1] + 3), SPAWN, 16)
    top_left = plane.to_screen((0.0, s.ground_height))
    bottom_right = plane.to_screen((s.world_width, 0.0))
    rect = (*top_left, *(bottom_right - top_left))
    p.pg.draw.rect(p.surface, GROUND, tuple(round(x) for x in rect))
    p.line(top_left, (bottom_right[0], top_left[1]), GROUND_EDGE, 4)
    w, h = s.world_width, s.world_height
    edges = plane.to_screen(np.array([[0, 0], [w, 0], [w, h], [0, h], [0, 0]], dtype=float))
    for a, b in zip(edges[:-1], edges[1:], strict=True):
        p.dashed_line(a, b, BOUNDS, 2, dash_px=8)


def platform(p: Painter, plane: PlaneView, s: LanderScene) -> None:
    """The platform, with an arrow under it when it moves."""
    half = s.platform_width / 2.0
    x0, x1 = s.platform_x - half, s.platform_x + half
    y0, y1 = s.ground_height, s.ground_height + s.platform_height
    box = plane.to_screen(np.array([[x0, y0], [x1, y0], [x1, y1], [x0, y1]]))
    p.polygon(box, PLATFORM, PLATFORM_EDGE, 2)
    p.line(box[3], box[2], PLATFORM_TOP, 3)
    if abs(s.platform_vx) > 1e-6:
        mid = plane.to_screen((s.platform_x, y0 - 0.6))
        length = math.copysign(min(30.0, 12 + 8 * abs(s.platform_vx)), s.platform_vx)
        p.arrow(mid, mid + np.array([length, 0]), PLATFORM_EDGE, 2, head_px=7)


def sensor_line(p: Painter, plane: PlaneView, s: LanderScene, label: bool) -> None:
    """The sensor line from the drone to the platform's top centre, with the distance as
    `label`."""
    a, b = plane.to_screen(s.position), plane.to_screen(s.platform_top)
    p.dashed_line(a, b, SENSOR, 2, dash_px=7)
    p.disc(b, 4, SENSOR)
    if label:
        mid = (a + b) / 2.0
        p.text(f"{s.distance_to_platform:.1f} m", (mid[0] + 8, mid[1]), SENSOR, 18, "midleft", True)


def drone(p: Painter, plane: PlaneView, s: LanderScene, full_px: float) -> None:
    """The drone, and over each motor, along the body's +y, its thrust bar `full_px` long at
    full thrust: grey = max thrust, red = this step's thrust."""
    frame, left, right = _drone_parts(s, s.position[0], s.position[1], s.angle)
    for part, color in ((frame, FRAME), (left, MOTOR), (right, MOTOR)):
        p.polygon(plane.to_screen(part), color, OUTLINE, 1)
    motor_x = (s.drone_width - s.drone_height) / 2.0
    up = rotate2d(np.array([[0.0, 1.0]]), s.angle)[0] * np.array([1.0, -1.0])  # screen v down
    for side, thrust in ((-1.0, s.thrust[0]), (1.0, s.thrust[1])):
        attach = rotate2d(np.array([[side * motor_x, s.drone_height / 2]]), s.angle)[0]
        start = plane.to_screen(attach + s.position)
        p.line(start, start + up * full_px, THRUST_TRACK, 3)
        fraction = min(max(thrust / s.max_thrust, 0.0), 1.0)
        if fraction > 0:
            p.line(start, start + up * full_px * fraction, THRUST, 3)


class LanderView(View):
    """Draws LanderScene frames: a window ("human") or (H, W, 3) uint8 arrays ("rgb_array"),
    with the episode's path and a shade every `shade_distance_m` travelled."""

    def __init__(
        self,
        render_mode: str,
        width: int = 800,
        height: int = 800,
        fps: float = 50.0,
        *,
        show_path: bool = True,
        show_shades: bool = True,
        shade_distance_m: float = 2.0,
        show_spawn_zone: bool = True,
        show_overlay: bool = True,
        show_close_up: bool = True,
    ) -> None:
        self.show_path, self.show_shades = show_path, show_shades
        self.show_spawn_zone, self.show_overlay = show_spawn_zone, show_overlay
        self.shade_distance_m = shade_distance_m
        self._shades: deque[tuple[float, float, float]] = deque(maxlen=500)  # x, y, angle
        super().__init__(render_mode, (width, height), "flyloop - Lander2D", fps, 5000)
        self._close_up: Painter | None = None
        cw, ch = CLOSE_UP_SIZE
        if show_close_up and width >= 3 * cw and height >= 3 * ch:  # else it has no room
            self._close_up = Painter(self._pg, self._surface.subsurface((20, 20, cw, ch)))

    def reset(self) -> None:
        """Forget the flight path and shades (an env calls this from reset())."""
        super().reset()
        self._shades.clear()

    def render(self, scene: LanderScene) -> np.ndarray | None:
        """Draw one frame: returns it in rgb_array mode, None in human mode."""
        if not self._drawable():
            return None  # the user closed the window: nothing to draw on any more
        if self._follow(scene.step, scene.position):
            self._shades.clear()
        # A shade at the first pose, then each time the drone is shade_distance_m past the
        # last one (the reference's shade_distance_m, docs/reference/lander2d.md).
        x, y = float(scene.position[0]), float(scene.position[1])
        last = self._shades[-1] if self._shades else None
        if last is None or np.hypot(x - last[0], y - last[1]) > self.shade_distance_m:
            self._shades.append((x, y, float(scene.angle)))
        s, p = scene, self._painter
        plane = fit_world(s, self.size)
        shade_poses = self._shades if self.show_shades else ()
        path_points = np.array(self.path) if self.show_path else ()
        world(p, plane, s, shade_poses, path_points, spawn=self.show_spawn_zone)
        zoom = CLOSE_UP_SCALE / plane.scale
        if self._close_up is not None and zoom >= 1.5:  # in a small world it adds nothing
            # The drone a little low in the close-up, so its thrust bars fit above it.
            (cw, ch), q = CLOSE_UP_SIZE, self._close_up
            center = s.position + (0.0, 0.12 * ch / CLOSE_UP_SCALE)
            u0, v0 = cw / 2.0 - center[0] * CLOSE_UP_SCALE, ch / 2.0 + center[1] * CLOSE_UP_SCALE
            world(q, PlaneView(CLOSE_UP_SCALE, u0, v0), s, shade_poses, path_points, close_up=True)
            q.pg.draw.rect(q.surface, (40, 40, 50), (0, 0, cw, ch), 2)
            q.text(f"close-up ×{zoom:.0f}", (8, 6), TEXT, 18, bold=True)
        wind_indicator(p, s)
        if self.show_overlay:
            overlay(p, plane, s)
        return self._present()
