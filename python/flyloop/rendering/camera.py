"""The quadrotor view's 3D camera, pure numpy: an orbit camera and a Projector (the camera
bound to a frame size, near-plane clipped). ``azimuth_deg``: the compass direction looked
toward (0 = north/+y, 90 = east/+x); ``elevation_deg``: down from the horizon; ``fov_deg``:
vertical. Camera space: x right, y up, z depth; pixels from the top-left, v down."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

MAX_ELEVATION_DEG = 89.0  # short of straight up or down, where the view would flip


@dataclass(eq=False)
class OrbitCamera:
    """A perspective camera orbiting `look_at` at `distance` metres; angles in degrees."""

    look_at: np.ndarray = field(default_factory=lambda: np.array([0.0, 0.0, 1.0]))
    distance: float = 6.5
    azimuth_deg: float = 35.0
    elevation_deg: float = 28.0
    fov_deg: float = 55.0
    near: float = 0.05

    def __post_init__(self) -> None:
        self.look_at = np.asarray(self.look_at, dtype=float).reshape(3)
        self.elevation_deg = _clamp_elevation(self.elevation_deg)
        self._cache_key: tuple | None = None  # the pose _view last computed

    def basis(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Unit vectors (right, up, forward) of the camera in world coordinates."""
        return tuple(self._view()[0].copy())

    def to_camera(self, points: np.ndarray) -> np.ndarray:
        """World points (..., 3) to camera coordinates (..., 3): right, up, depth."""
        rows, position = self._view()
        return (np.asarray(points, dtype=float) - position) @ rows.T

    def _view(self) -> tuple[np.ndarray, np.ndarray]:
        """(rows right/up/forward, position), cached: a frame projects thousands of points."""
        key = (self.azimuth_deg, self.elevation_deg, self.distance, *self.look_at.tolist())
        if self._cache_key != key:
            az, el = math.radians(self.azimuth_deg), math.radians(self.elevation_deg)
            sa, ca, se, ce = math.sin(az), math.cos(az), math.sin(el), math.cos(el)
            # Rows right, up (= right x forward), forward.
            rows = np.array([(ca, -sa, 0.0), (sa * se, ca * se, ce), (sa * ce, ca * ce, -se)])
            self._cache = (rows, self.look_at - rows[2] * self.distance)
            self._cache_key = key
        return self._cache

    def project(self, points: np.ndarray, width: int, height: int) -> tuple[np.ndarray, np.ndarray]:
        """World points (..., 3) to (pixels (..., 2), visible (...)): visible = in front of near."""
        cam = self.to_camera(points)
        return Projector(self, (width, height)).pixels(cam), cam[..., 2] >= self.near

    def orbit(self, d_azimuth_deg: float, d_elevation_deg: float) -> None:
        """Turn around the look-at point; elevation stays short of straight up/down."""
        self.azimuth_deg = (self.azimuth_deg + d_azimuth_deg) % 360.0
        self.elevation_deg = _clamp_elevation(self.elevation_deg + d_elevation_deg)


def _clamp_elevation(value: float) -> float:
    return max(-MAX_ELEVATION_DEG, min(MAX_ELEVATION_DEG, float(value)))


class Projector:
    """A camera bound to a frame size: world points to pixels, near-plane clipped."""

    def __init__(self, camera: OrbitCamera, size: tuple[int, int]) -> None:
        self.camera = camera
        self.width, self.height = size
        # Pixels per unit of (lateral offset / depth).
        self.focal = (self.height / 2.0) / math.tan(math.radians(camera.fov_deg) / 2.0)

    def pixels(self, cam: np.ndarray) -> np.ndarray:
        """Camera points (..., 3) to screen pixels (..., 2); depth is floored at near."""
        depth = np.maximum(cam[..., 2], self.camera.near)
        u = self.width / 2.0 + self.focal * cam[..., 0] / depth
        v = self.height / 2.0 - self.focal * cam[..., 1] / depth
        return np.stack([u, v], axis=-1)

    def point(self, p: np.ndarray) -> tuple[np.ndarray, float] | None:
        cam = self.camera.to_camera(p)
        return None if cam[2] < self.camera.near else (self.pixels(cam), float(cam[2]))

    def segment(self, a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, np.ndarray] | None:
        """One segment's pixels, near-clipped, or None (scalar steps: faster than segments)."""
        ca, cb = self.camera.to_camera(np.stack([np.asarray(a, float), np.asarray(b, float)]))
        da, db = ca[2] - self.camera.near, cb[2] - self.camera.near
        if da < 0 and db < 0:
            return None
        if da < 0:
            ca = ca + (cb - ca) * (da / (da - db))
        elif db < 0:
            cb = cb + (ca - cb) * (db / (db - da))
        return tuple(self.pixels(np.stack([ca, cb])))

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
        return list(zip(self.pixels(ca2[keep]), self.pixels(cb2[keep]), strict=True))

    def polygon(self, points: np.ndarray) -> np.ndarray:
        """A convex world polygon's pixels, cut where it crosses the near plane (Sutherland-
        Hodgman against one plane); (0, 2) when fewer than 3 corners are left."""
        cam, near, out = self.camera.to_camera(points), self.camera.near, []
        for i in range(len(cam)):
            a, b = cam[i - 1], cam[i]
            da, db = a[2] - near, b[2] - near
            if db >= 0:
                if da < 0:
                    out.append(a + (b - a) * (da / (da - db)))
                out.append(b)
            elif da >= 0:
                out.append(a + (b - a) * (da / (da - db)))
        return self.pixels(np.array(out)) if len(out) >= 3 else np.zeros((0, 2))

    def radius(self, radius_m: float, depth: float) -> float:
        """On-screen radius in pixels of a sphere of radius_m at this depth."""
        return self.focal * radius_m / max(depth, self.camera.near)
