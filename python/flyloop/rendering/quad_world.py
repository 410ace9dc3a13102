"""The quadrotor's 3D world: ground grid and axes, bounds, target, waypoint, drone, vectors.

Drawn with a painter's algorithm: the ground and lines first, then solid things far to
near, the drone's hub last (it must stay visible: its pixels are what tests track).
"""

from __future__ import annotations

import math

import numpy as np

from .camera import OrbitCamera, clip_polygon_near
from .geometry import ROTOR_SPIN, rotation_matrix, rotor_positions_body
from .painter import Painter
from .scene import QuadScene

GROUND = (226, 230, 222)
GRID = (188, 192, 186)
GRID_MAJOR = (160, 165, 158)
AXIS_X = (220, 40, 40)
AXIS_Y = (30, 160, 60)
AXIS_Z = (40, 90, 230)
BOUNDS = (150, 160, 200)
BODY = (0, 100, 200)
BODY_HIGHLIGHT = (110, 175, 245)
ROTOR_CCW = (70, 200, 90)  # counter-clockwise (seen from above)
ROTOR_CW = (235, 90, 80)  # clockwise
ARM = (90, 90, 95)
NOSE = (35, 35, 40)
TARGET = (0, 170, 60)
TARGET_LINE = (140, 140, 140)
WAYPOINT = (150, 60, 200)
UP = (255, 150, 0)
VELOCITY = (230, 0, 220)
WIND = (200, 0, 0)
DROP = (128, 128, 128)
SHADOW = (40, 40, 40)
TRAIL = (60, 140, 220)

TARGET_RADIUS_M = 0.08
WAYPOINT_RADIUS_M = 0.06
UP_ARROW_M = 0.5  # length of the up vector
VELOCITY_SECONDS = 0.5  # the velocity arrow shows where the drone is in this many seconds
WIND_M_PER_MPS = 0.12  # wind arrow length per m/s of wind
MAX_ARROW_M = 2.0


def rotor_color(index: int) -> tuple[int, int, int]:
    return ROTOR_CCW if ROTOR_SPIN[index] < 0 else ROTOR_CW


class Projector:
    """A camera bound to a frame size: world points to pixels, near-plane clipped."""

    def __init__(self, camera: OrbitCamera, size: tuple[int, int]) -> None:
        self.camera = camera
        self.width, self.height = size

    def point(self, p: np.ndarray) -> tuple[np.ndarray, float] | None:
        cam = self.camera.to_camera(p)
        if cam[2] < self.camera.near:
            return None
        return self.camera.project_camera(cam, self.width, self.height), float(cam[2])

    def segment(self, a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, np.ndarray] | None:
        clipped = self.camera.clip_segment(np.asarray(a, float), np.asarray(b, float))
        if clipped is None:
            return None
        ends = self.camera.project_camera(np.stack(clipped), self.width, self.height)
        return ends[0], ends[1]

    def segments(self, a: np.ndarray, b: np.ndarray) -> list[tuple[np.ndarray, np.ndarray]]:
        """Many world segments a[i]-b[i] at once: the visible, near-clipped ones in pixels."""
        near = self.camera.near
        ca, cb = self.camera.to_camera(np.asarray(a, float)), self.camera.to_camera(b)
        da, db = ca[:, 2:3] - near, cb[:, 2:3] - near
        keep = ((da >= 0) | (db >= 0))[:, 0]
        with np.errstate(divide="ignore", invalid="ignore"):
            t = np.where(da - db != 0, da / (da - db), 0.0)
        ca2 = np.where(da < 0, ca + (cb - ca) * t, ca)
        cb2 = np.where(db < 0, cb + (ca - cb) * (db / np.where(db - da != 0, db - da, 1)), cb)
        pa = self.camera.project_camera(ca2[keep], self.width, self.height)
        pb = self.camera.project_camera(cb2[keep], self.width, self.height)
        return list(zip(pa, pb, strict=True))

    def polygon(self, points: np.ndarray) -> np.ndarray:
        cam = clip_polygon_near(self.camera.to_camera(points), self.camera.near)
        if len(cam) < 3:
            return np.zeros((0, 2))
        return self.camera.project_camera(cam, self.width, self.height)

    def radius(self, radius_m: float, depth: float) -> float:
        return self.camera.pixel_radius(radius_m, depth, self.height)


def _line(p: Painter, pr: Projector, a, b, color, width: int = 1) -> None:
    seg = pr.segment(a, b)
    if seg is not None:
        p.line(seg[0], seg[1], color, width)


def _dashed(p: Painter, pr: Projector, a, b, color, width: int = 1) -> None:
    seg = pr.segment(a, b)
    if seg is not None:
        p.dashed_line(seg[0], seg[1], color, width, dash_px=5)


def _arrow(p: Painter, pr: Projector, start, vector, color, width: int = 3) -> None:
    seg = pr.segment(start, np.asarray(start) + vector)
    if seg is not None and float(np.hypot(*(seg[1] - seg[0]))) > 2.0:
        p.arrow(seg[0], seg[1], color, width)


def _circle_points(center: np.ndarray, radius: float, axes: np.ndarray, n: int = 20) -> np.ndarray:
    t = np.linspace(0.0, 2 * math.pi, n, endpoint=False)
    return center + radius * (np.outer(np.cos(t), axes[0]) + np.outer(np.sin(t), axes[1]))


def grid_extent(scene: QuadScene) -> float:
    """Half side of the drawn ground grid, m: the target box and a margin, on 0.5 m lines."""
    return math.ceil((scene.bounds_half_size * 2.0 + 1.0) * 2.0) / 2.0


def ground(p: Painter, pr: Projector, scene: QuadScene) -> None:
    g = grid_extent(scene)
    square = np.array([[-g, -g, 0.0], [g, -g, 0.0], [g, g, 0.0], [-g, g, 0.0]])
    poly = pr.polygon(square)
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


def axes(p: Painter, pr: Projector, scene: QuadScene) -> None:
    """World axes from the origin, 1 m long, labelled."""
    origin = np.zeros(3)
    for axis, color, label in (
        ((1.0, 0, 0), AXIS_X, "x E"),
        ((0, 1.0, 0), AXIS_Y, "y N"),
        ((0, 0, 1.0), AXIS_Z, "z"),
    ):
        _arrow(p, pr, origin, np.array(axis), color, 2)
        tip = pr.point(np.array(axis) * 1.15)
        if tip is not None:
            p.text(label, tip[0], color, 18, "center", bold=True)


def bounds(p: Painter, pr: Projector, scene: QuadScene) -> None:
    """Wireframe of the target box: x, y in [-h, h], z in [0, 2h]."""
    h = scene.bounds_half_size
    corners = [np.array([x, y, z]) for z in (0.0, 2 * h) for x in (-h, h) for y in (-h, h)]
    for i, a in enumerate(corners):
        for b in corners[i + 1 :]:
            if np.count_nonzero(np.abs(a - b) > 1e-9) == 1:  # an edge, not a diagonal
                _dashed(p, pr, a, b, BOUNDS, 1)


def shadow(p: Painter, pr: Projector, position: np.ndarray, radius: float) -> None:
    """A soft dark disc on the ground under a point, and a dashed drop line to it."""
    foot = np.array([position[0], position[1], 0.0])
    if position[2] > 0:
        _dashed(p, pr, position, foot, DROP, 1)
    ring = pr.polygon(_circle_points(foot, radius, np.eye(3)[:2]))
    if len(ring):
        p.translucent_polygon(ring, SHADOW, 60)


def trail(p: Painter, pr: Projector, points: np.ndarray) -> None:
    if len(points) < 2:
        return
    for a, b in pr.segments(points[:-1], points[1:]):
        p.line(a, b, TRAIL, 2)


def target(p: Painter, pr: Projector, scene: QuadScene) -> None:
    """The target sphere with a 3-axis crosshair, its line from the drone."""
    if scene.target is None:
        return
    _line(p, pr, scene.position, scene.target, TARGET_LINE, 1)
    for axis in np.eye(3) * 0.2:
        _line(p, pr, scene.target - axis, scene.target + axis, TARGET, 2)
    _sphere(p, pr, scene.target, TARGET_RADIUS_M, TARGET)


def next_waypoint(p: Painter, pr: Projector, scene: QuadScene) -> None:
    if scene.next_waypoint is None:
        return
    if scene.target is not None:
        _dashed(p, pr, scene.target, scene.next_waypoint, WAYPOINT, 1)
    hit = pr.point(scene.next_waypoint)
    if hit is not None:
        r = max(4.0, pr.radius(WAYPOINT_RADIUS_M, hit[1]))
        p.ring(hit[0], r, WAYPOINT, 3)
        p.text("next", hit[0] + np.array([r + 4, -r - 4]), WAYPOINT, 17, "bottomleft")


def _sphere(p: Painter, pr: Projector, center: np.ndarray, radius_m: float, color) -> None:
    hit = pr.point(center)
    if hit is None:
        return
    r = max(3.0, pr.radius(radius_m, hit[1]))
    p.disc(hit[0], r, color)
    light = tuple(min(255, c + 70) for c in color)
    p.disc(hit[0] - r * 0.3, max(1.0, r * 0.3), light)


def drone(p: Painter, pr: Projector, scene: QuadScene, scale: float) -> None:
    """Arms, rotor discs (coloured by spin, in the body plane), nose, vectors, hub on top.

    Drawn `scale` times the real size so a 0.1 m arm stays visible in a metres-wide box.
    """
    rot = rotation_matrix(scene.quaternion)
    pos = scene.position
    arm = scene.arm_length * scale
    rotors = pos + rotor_positions_body(arm) @ rot.T
    rotor_radius = 0.38 * arm
    disc_axes = rot.T[:2]  # body x and y in world coordinates
    cam = pr.camera
    order = np.argsort(-cam.to_camera(rotors)[:, 2])  # far first
    for i in order:
        _line(p, pr, pos, rotors[i], ARM, 4)
        poly = pr.polygon(_circle_points(rotors[i], rotor_radius, disc_axes))
        if len(poly):
            color = rotor_color(int(i))
            p.translucent_polygon(poly, color, 150)
            p.polyline(np.vstack([poly, poly[:1]]), tuple(int(c * 0.6) for c in color), 2)
        level = pr.polygon(_circle_points(rotors[i], rotor_radius * scene.motors[i], disc_axes))
        if len(level) and scene.motors[i] > 0.02:
            p.translucent_polygon(level, rotor_color(int(i)), 170)
    _arrow(p, pr, pos, rot[:, 2] * UP_ARROW_M, UP, 3)
    speed = float(np.linalg.norm(scene.velocity))
    if speed > 0.05:
        length = min(speed * VELOCITY_SECONDS, MAX_ARROW_M)
        _arrow(p, pr, pos, scene.velocity / speed * length, VELOCITY, 3)
    wind = float(np.linalg.norm(scene.wind))
    if wind > 0.05:
        length = min(wind * WIND_M_PER_MPS, MAX_ARROW_M)
        _arrow(p, pr, pos, scene.wind / wind * length, WIND, 2)
    _line(p, pr, pos, pos + rot[:, 0] * arm * 0.8, NOSE, 4)
    hub = pr.point(pos)
    if hub is not None:
        r = max(4.0, pr.radius(0.22 * arm, hub[1]))
        p.disc(hub[0], r, BODY, (0, 50, 110), 1)
        p.disc(hub[0] - r * 0.28, max(1.0, r * 0.32), BODY_HIGHLIGHT)


def world(
    p: Painter,
    pr: Projector,
    scene: QuadScene,
    trail_points: np.ndarray,
    drone_scale: float,
) -> None:
    """The whole 3D scene, back to front."""
    ground(p, pr, scene)
    axes(p, pr, scene)
    bounds(p, pr, scene)
    for point, radius in ((scene.target, 0.1), (scene.next_waypoint, 0.07)):
        if point is not None:
            shadow(p, pr, point, radius)
    shadow(p, pr, scene.position, 0.7 * scene.arm_length * drone_scale)
    trail(p, pr, trail_points)
    solids = [(lambda: target(p, pr, scene), scene.target)]
    solids.append((lambda: next_waypoint(p, pr, scene), scene.next_waypoint))
    solids.append((lambda: drone(p, pr, scene, drone_scale), scene.position))
    depth = [-float(pr.camera.to_camera(at)[2]) if at is not None else math.inf for _, at in solids]
    for i in np.argsort(depth, kind="stable"):
        solids[i][0]()
