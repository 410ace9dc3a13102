"""The quadrotor view (tasks Hover and Waypoints): its scene, the 3D world through an orbit
camera, the overlays and QuadrotorView; the core's frames (world
ENU, body FLU, quaternion [w, x, y, z]) and PX4's motor order. Painter's algorithm: ground
and lines, then solids far to near, the hub last (tests track its pixels)."""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass, field

import numpy as np

from .. import _native
from ..tasks import HOVER
from .camera import OrbitCamera, Projector
from .canvas import Painter, View

# The core's quad X (core/src/quadrotor/frame.rs, PX4's motor order): rotor i sits at
# (forward, left) * L/sqrt(2) in the body frame, spinning -1 counter-clockwise or +1 clockwise
# seen from above. The view's Frame.quad_x reads these signs (flyloop.view.scene).
_QUAD_X = _native.frames()["quad_x"]
ROTOR_POSITION_SIGNS = np.array([(math.copysign(1, x), math.copysign(1, y)) for x, y, _ in _QUAD_X])
ROTOR_SPIN = tuple(spin for _, _, spin in _QUAD_X)
GROUND, GRID, GRID_MAJOR, AXIS_X = (226, 230, 222), (188, 192, 186), (160, 165, 158), (220, 40, 40)
AXIS_Y, AXIS_Z, BOUNDS, BODY = (30, 160, 60), (40, 90, 230), (150, 160, 200), (0, 100, 200)
BODY_HIGHLIGHT, ROTOR_CCW, ROTOR_CW = (110, 175, 245), (70, 200, 90), (235, 90, 80)
ARM, NOSE, TARGET, TARGET_LINE = (90, 90, 95), (35, 35, 40), (0, 170, 60), (140, 140, 140)
WAYPOINT, UP, VELOCITY, WIND = (150, 60, 200), (255, 150, 0), (230, 0, 220), (200, 0, 0)
DROP, SHADOW, TRAIL = (128, 128, 128), (40, 40, 40), (60, 140, 220)
TEXT, PANEL, BAD, BACKGROUND_TOP = (20, 20, 30), (255, 255, 236), (200, 0, 0), (232, 238, 248)
BACKGROUND_BOTTOM = (246, 246, 250)


@dataclass(frozen=True)
class Rotors:
    """A frame's rotors as drawn: position (forward, left) in arm lengths, colour, name
    (compass sector: F, FL, L, RL, B, RR, R, FR) and spin name per rotor, in motor order."""

    positions: np.ndarray  # (n, 2)
    colors: tuple
    names: tuple[str, ...]
    spins: tuple[str, ...]


@functools.cache
def frame_rotors(frame: str) -> Rotors:
    """The drawing of the core's shipped frame `frame` (its rotor table, `_native.frames()`)."""
    table = _native.frames()[frame]
    sectors = ("F", "FL", "L", "RL", "B", "RR", "R", "FR")
    return Rotors(
        np.array([(x, y) for x, y, _ in table]),
        tuple(ROTOR_CCW if spin < 0 else ROTOR_CW for _, _, spin in table),
        tuple(sectors[round(math.degrees(math.atan2(y, x)) % 360 / 45) % 8] for x, y, _ in table),
        tuple("CCW" if spin < 0 else "CW" for _, _, spin in table),
    )


AXES = ((AXIS_X, "x E"), (AXIS_Y, "y N"), (AXIS_Z, "z"))
TARGET_RADIUS_M, WAYPOINT_RADIUS_M, UP_ARROW_M, MAX_ARROW_M = 0.08, 0.06, 0.5, 2.0
VELOCITY_SECONDS = 0.5  # the velocity arrow shows where the drone is in this many seconds
WIND_M_PER_MPS = 0.12  # wind arrow length per m/s of wind
_CORE = HOVER.defaults  # what a scene shows when not told


def rotation_matrix(q_wxyz: np.ndarray) -> np.ndarray:
    """The 3x3 matrix of a unit quaternion [w, x, y, z]: world = R @ body."""
    w, x, y, z = q_wxyz
    row_x = [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)]
    row_y = [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)]
    row_z = [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]
    return np.array([row_x, row_y, row_z])


@dataclass(eq=False)
class QuadScene:
    """One frame of the quadrotor: plain per-step data in the core's frames and units."""

    time_s: float  # episode time, s
    step: int  # steps since reset
    position: np.ndarray  # (3,) m, world ENU
    velocity: np.ndarray  # (3,) m/s, world ENU
    quaternion: np.ndarray  # (4,) [w, x, y, z], body FLU -> world ENU; normalised here
    motors: np.ndarray = field(default_factory=lambda: np.zeros(4))  # (n,) states, [0, 1]
    wind: np.ndarray = field(default_factory=lambda: np.zeros(3))  # (3,) m/s, world ENU
    target: np.ndarray | None = None  # (3,) m, world ENU: the current target / waypoint
    next_waypoint: np.ndarray | None = None  # (3,) m, the waypoint after the target
    reward: float | None = None  # reward of the last step
    episode_return: float | None = None  # sum of rewards since reset
    bounds_half_size: float = _CORE["space_side_length"] / 2.0  # m: x, y in [-h, h], z in [0, 2h]
    arm_length: float = _CORE["arm_length"]  # m, centre to rotor
    waypoints_reached: int | None = None  # Waypoints task only
    status: str = ""  # e.g. "crashed", "out of bounds"; empty while flying
    frame: str = "quad_x"  # the core's shipped frame: its rotors are drawn, one per motor

    def __post_init__(self) -> None:
        for name in ("position", "velocity", "wind", "target", "next_waypoint"):
            if getattr(self, name) is not None:
                setattr(self, name, np.array(getattr(self, name), float).ravel())
        q = np.array(self.quaternion, float).ravel()
        self.quaternion = q / float(np.linalg.norm(q))
        # Lagged motor states may overshoot by rounding; the bars show [0, 1].
        self.motors = np.clip(np.array(self.motors, float).ravel(), 0.0, 1.0)
        self.time_s, self.step = float(self.time_s), int(self.step)
        if self.waypoints_reached is not None:
            self.waypoints_reached = int(self.waypoints_reached)


def _line(p: Painter, pr: Projector, a, b, color, width: int = 1, dashed=False) -> None:
    seg = pr.segment(a, b)
    if seg is not None and dashed:
        p.dashed_line(seg[0], seg[1], color, width, dash_px=5)
    elif seg is not None:
        p.line(seg[0], seg[1], color, width)


def _arrow(p: Painter, pr: Projector, start, vector, color, width: int = 3) -> None:
    seg = pr.segment(start, np.asarray(start) + vector)
    if seg is not None and float(np.hypot(*(seg[1] - seg[0]))) > 2.0:
        p.arrow(seg[0], seg[1], color, width)


def _circle_points(center: np.ndarray, radius: float, axes: np.ndarray, n: int = 20) -> np.ndarray:
    t = np.linspace(0.0, 2 * math.pi, n, endpoint=False)
    return center + radius * (np.outer(np.cos(t), axes[0]) + np.outer(np.sin(t), axes[1]))


def shadow(p: Painter, pr: Projector, position: np.ndarray, radius: float) -> None:
    """A soft dark disc on the ground under a point, and a dashed drop line to it."""
    foot = np.array([position[0], position[1], 0.0])
    if position[2] > 0:
        _line(p, pr, position, foot, DROP, 1, dashed=True)
    ring = pr.polygon(_circle_points(foot, radius, np.eye(3)[:2]))
    if len(ring):
        p.translucent_polygon(ring, SHADOW, 60)


def target(p: Painter, pr: Projector, scene: QuadScene) -> None:
    """The target sphere with a 3-axis crosshair, its line from the drone."""
    if scene.target is None:
        return
    _line(p, pr, scene.position, scene.target, TARGET_LINE, 1)
    for axis in np.eye(3) * 0.2:
        _line(p, pr, scene.target - axis, scene.target + axis, TARGET, 2)
    hit = pr.point(scene.target)
    if hit is not None:
        r = max(3.0, pr.radius(TARGET_RADIUS_M, hit[1]))
        p.disc(hit[0], r, TARGET)
        p.disc(hit[0] - r * 0.3, max(1.0, r * 0.3), tuple(min(255, c + 70) for c in TARGET))


def next_waypoint(p: Painter, pr: Projector, scene: QuadScene) -> None:
    if scene.next_waypoint is None:
        return
    if scene.target is not None:
        _line(p, pr, scene.target, scene.next_waypoint, WAYPOINT, 1, dashed=True)
    hit = pr.point(scene.next_waypoint)
    if hit is not None:
        r = max(4.0, pr.radius(WAYPOINT_RADIUS_M, hit[1]))
        p.ring(hit[0], r, WAYPOINT, 3)
        p.text("next", hit[0] + np.array([r + 4, -r - 4]), WAYPOINT, 17, "bottomleft")


def drone(p: Painter, pr: Projector, scene: QuadScene, scale: float) -> None:
    """Arms, spin-coloured rotor discs, nose, vectors, hub on top; `scale` times its size."""
    rot = rotation_matrix(scene.quaternion)
    pos = scene.position
    arm = scene.arm_length * scale
    drawn = frame_rotors(scene.frame)
    rotors = pos + np.c_[drawn.positions * arm, np.zeros(len(drawn.positions))] @ rot.T
    rotor_radius = 0.38 * arm
    disc_axes = rot.T[:2]  # body x and y in world coordinates
    cam = pr.camera
    order = np.argsort(-cam.to_camera(rotors)[:, 2])  # far first
    for i in order:
        _line(p, pr, pos, rotors[i], ARM, 4)
        poly = pr.polygon(_circle_points(rotors[i], rotor_radius, disc_axes))
        if len(poly):
            color = drawn.colors[i]
            p.translucent_polygon(poly, color, 150)
            p.polyline(np.vstack([poly, poly[:1]]), tuple(int(c * 0.6) for c in color), 2)
        level = pr.polygon(_circle_points(rotors[i], rotor_radius * scene.motors[i], disc_axes))
        if len(level) and scene.motors[i] > 0.02:
            p.translucent_polygon(level, drawn.colors[i], 170)
    _arrow(p, pr, pos, rot[:, 2] * UP_ARROW_M, UP, 3)
    for vec, m_per_unit, color, width in (
        (scene.velocity, VELOCITY_SECONDS, VELOCITY, 3),
        (scene.wind, WIND_M_PER_MPS, WIND, 2),
    ):
        size = float(np.linalg.norm(vec))
        if size > 0.05:
            _arrow(p, pr, pos, vec / size * min(size * m_per_unit, MAX_ARROW_M), color, width)
    _line(p, pr, pos, pos + rot[:, 0] * arm * 0.8, NOSE, 4)
    hub = pr.point(pos)
    if hub is not None:
        r = max(4.0, pr.radius(0.22 * arm, hub[1]))
        p.disc(hub[0], r, BODY, (0, 50, 110), 1)
        p.disc(hub[0] - r * 0.28, max(1.0, r * 0.32), BODY_HIGHLIGHT)


def world(p: Painter, pr: Projector, scene: QuadScene, trail: np.ndarray, scale: float) -> None:
    """The whole 3D scene, back to front."""
    # The ground and its grid on 0.5 m lines, wide enough for the target box and a margin.
    g = math.ceil((scene.bounds_half_size * 2.0 + 1.0) * 2.0) / 2.0
    poly = pr.polygon(np.array([[-g, -g, 0.0], [g, -g, 0.0], [g, g, 0.0], [-g, g, 0.0]]))
    if len(poly):
        p.polygon(poly, GROUND)
    ticks = np.arange(-g, g + 1e-9, 0.5)
    n = len(ticks)
    zeros, lo, hi = np.zeros(n), np.full(n, -g), np.full(n, g)
    starts = np.concatenate([np.stack([ticks, lo, zeros], 1), np.stack([lo, ticks, zeros], 1)])
    ends = np.concatenate([np.stack([ticks, hi, zeros], 1), np.stack([hi, ticks, zeros], 1)])
    major = np.concatenate([np.arange(n) % 2 == 0] * 2)
    for is_major in (False, True):  # minor lines first, the metre lines over them
        pick = major == is_major
        for a, b in pr.segments(starts[pick], ends[pick]):
            p.line(a, b, GRID_MAJOR if is_major else GRID, 1)
    for axis, (color, label) in zip(np.eye(3), AXES, strict=True):
        _arrow(p, pr, np.zeros(3), axis, color, 2)
        tip = pr.point(axis * 1.15)
        if tip is not None:
            p.text(label, tip[0], color, 18, "center", bold=True)
    # The target box's wireframe: x, y in [-h, h], z in [0, 2h].
    h = scene.bounds_half_size
    corners = [np.array([x, y, z]) for z in (0.0, 2 * h) for x in (-h, h) for y in (-h, h)]
    for i, a in enumerate(corners):
        for b in corners[i + 1 :]:
            if np.count_nonzero(np.abs(a - b) > 1e-9) == 1:  # an edge, not a diagonal
                _line(p, pr, a, b, BOUNDS, 1, dashed=True)
    for point, radius in ((scene.target, 0.1), (scene.next_waypoint, 0.07)):
        if point is not None:
            shadow(p, pr, point, radius)
    shadow(p, pr, scene.position, 0.7 * scene.arm_length * scale)
    if len(trail) >= 2:
        for a, b in pr.segments(trail[:-1], trail[1:]):
            p.line(a, b, TRAIL, 2)
    solids = [
        (scene.target, lambda: target(p, pr, scene)),
        (scene.next_waypoint, lambda: next_waypoint(p, pr, scene)),
        (scene.position, lambda: drone(p, pr, scene, scale)),
    ]
    depth = [math.inf if at is None else -float(pr.camera.to_camera(at)[2]) for at, _ in solids]
    for i in np.argsort(depth, kind="stable"):  # far first
        solids[i][1]()


def info_lines(scene: QuadScene) -> list[tuple[str, tuple[int, int, int]]]:
    """The info panel's text: time, step, distance, height, speed, wind, attitude, reward."""
    w, x, y, z = scene.quaternion  # to roll, pitch, yaw (intrinsic Z-Y-X)
    roll = math.degrees(math.atan2(2 * (w * x + y * z), 1 - 2 * (x * x + y * y)))
    pitch = math.degrees(math.asin(max(-1.0, min(1.0, 2 * (w * y - z * x)))))
    yaw = math.degrees(math.atan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z)))
    distance = (
        "-" if scene.target is None else f"{np.linalg.norm(scene.target - scene.position):.2f} m"
    )
    reward = "-" if scene.reward is None else f"{scene.reward:+.3f}"
    speed, wind = np.linalg.norm(scene.velocity), np.linalg.norm(scene.wind)
    lines = [
        (f"Time {scene.time_s:.2f} s    Step {scene.step}", TEXT),
        (f"Distance {distance}    Height {scene.position[2]:.2f} m", TEXT),
        (f"Speed {speed:.2f} m/s    Wind {wind:.2f} m/s", TEXT),
        (f"Roll {roll:+.1f}°  Pitch {pitch:+.1f}°  Yaw {yaw:+.1f}°", TEXT),
    ]
    if scene.episode_return is not None:
        reward += f"    Return {scene.episode_return:.2f}"
    lines.append((f"Reward {reward}", TEXT))
    if scene.waypoints_reached is not None:
        lines.append((f"Waypoints reached {scene.waypoints_reached}", TEXT))
    if scene.status:
        lines.append((scene.status[:1].upper() + scene.status[1:], BAD))
    return lines


def info_panel(p: Painter, scene: QuadScene) -> None:
    lines = info_lines(scene)
    line_h = 24
    width = max(p.font(21).size(t)[0] for t, _ in lines) + 28
    p.panel((12, 12, width, len(lines) * line_h + 18), PANEL)
    for i, (text, color) in enumerate(lines):
        p.text(text, (26, 22 + i * line_h), color, 21, bold=(color == BAD))


def motor_bars(p: Painter, scene: QuadScene) -> None:
    """Bottom-right: one bar per motor (PX4 order), labelled with position and spin colour."""
    width, height = p.surface.get_size()
    drawn = frame_rotors(scene.frame)
    n = len(scene.motors)
    bar_w, bar_h, gap = 26, 120, 20
    x0 = width - n * (bar_w + gap) - 14
    y0 = height - bar_h - 50
    p.panel((x0 - 12, y0 - 34, n * (bar_w + gap) + 8, bar_h + 76), PANEL)
    for i, level in enumerate(scene.motors):
        x = x0 + i * (bar_w + gap)
        fill = round(bar_h * float(level))
        p.pg.draw.rect(p.surface, (215, 215, 215), (x, y0, bar_w, bar_h))
        color = (255, round(230 * (1 - float(level))), 0)
        p.pg.draw.rect(p.surface, color, (x, y0 + bar_h - fill, bar_w, fill))
        p.pg.draw.rect(p.surface, (0, 0, 0), (x, y0, bar_w, bar_h), 1)
        p.text(f"{round(float(level) * 100)}%", (x + bar_w / 2, y0 - 6), TEXT, 17, "midbottom")
        p.disc((x + bar_w / 2, y0 - 26), 5, drawn.colors[i])
        p.text(f"M{i} {drawn.names[i]}", (x + bar_w / 2, y0 + bar_h + 4), TEXT, 17, "midtop")
        p.text(drawn.spins[i], (x + bar_w / 2, y0 + bar_h + 20), TEXT, 15, "midtop")


LEGEND = (
    ("Drone body", BODY, "disc"),
    ("CCW rotor", ROTOR_CCW, "disc"),
    ("CW rotor", ROTOR_CW, "disc"),
    ("Nose (front)", NOSE, "line"),
    ("Target", TARGET, "disc"),
    ("Next waypoint", WAYPOINT, "ring"),
    ("Up vector", UP, "line"),
    ("Velocity", VELOCITY, "line"),
    ("Wind", WIND, "line"),
    ("Trail", TRAIL, "line"),
)


def legend(p: Painter) -> None:
    """Top right: what each colour means."""
    width = p.surface.get_width()
    line_h = 20
    x, y = width - 168, 20
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


class QuadrotorView(View):
    """Draws QuadScene frames: a window ("human", Esc closes it) or (H, W, 3) uint8 arrays
    ("rgb_array"), through `camera` (from the south-west unless given: to orbit, zoom and
    scrub, watch the env in the Rerun view, flyloop.view.Watch). The vehicle is drawn
    `drone_scale` times its size (a 0.1 m arm stays visible); the trail keeps the episode's
    last `trail_steps` positions."""

    def __init__(
        self,
        render_mode: str,
        width: int = 960,
        height: int = 720,
        fps: float = 50.0,
        *,
        camera: OrbitCamera | None = None,
        drone_scale: float = 4.0,
        trail_steps: int = 400,
        hud: bool = True,
    ) -> None:
        self.drone_scale, self.hud, self.camera = float(drone_scale), hud, camera
        title = "flyloop - Quadrotor 3D"
        super().__init__(render_mode, (width, height), title, fps, max(2, trail_steps))

    def render(self, scene: QuadScene) -> np.ndarray | None:
        """Draw one frame: returns it in rgb_array mode, None in human mode."""
        if not self._drawable():
            return None  # the user closed the window
        if self.camera is None:
            # Looking at the middle of the target box from the south-west, the box in view.
            h = scene.bounds_half_size
            self.camera = OrbitCamera(look_at=np.array([0.0, 0.0, 0.8 * h]), distance=4.2 * h)
        self._follow(scene.step, scene.position)
        p = self._painter
        width, height = self.size
        p.gradient((0, 0, width, height), 0, height - 1, BACKGROUND_TOP, BACKGROUND_BOTTOM)
        trail = np.array(self.path)
        world(p, Projector(self.camera, self.size), scene, trail, self.drone_scale)
        if self.hud:
            info_panel(p, scene)
            motor_bars(p, scene)
            legend(p)
        return self._present()
