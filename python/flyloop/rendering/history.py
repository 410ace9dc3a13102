"""What a view remembers across frames of one episode: the flight path and the shades.

A view is only handed the current step, so a step number lower than the last one seen means
a new episode began; rendering the same step twice records it once.
"""

from __future__ import annotations

from collections import deque

import numpy as np


class FlightPath:
    """Positions of the current episode, one per step, the oldest dropped past max_points."""

    def __init__(self, max_points: int = 5000) -> None:
        if max_points < 2:
            raise ValueError(f"max_points must be >= 2, got {max_points}")
        self._points: deque[np.ndarray] = deque(maxlen=max_points)
        self._last_step: int | None = None

    def update(self, step: int, position: np.ndarray) -> bool:
        """Record the position of `step`; True when this step started a new episode."""
        new_episode = self._last_step is not None and step < self._last_step
        if new_episode:
            self._points.clear()
        point = np.array(position, dtype=float)
        if self._last_step == step and self._points:
            self._points[-1] = point
        else:
            self._points.append(point)
        self._last_step = step
        return new_episode

    def clear(self) -> None:
        self._points.clear()
        self._last_step = None

    @property
    def points(self) -> np.ndarray:
        """(N, dims) positions, oldest first; (0, 0) when empty."""
        return np.array(self._points) if self._points else np.zeros((0, 0))


class Shades:
    """Poses where the drone left a shade: the first pose of the episode, then every time it
    is more than `spacing_m` away from the last shade (the reference's shade_distance_m,
    docs/reference/lander2d.md)."""

    def __init__(self, spacing_m: float = 2.0, max_shades: int = 500) -> None:
        if not spacing_m > 0:
            raise ValueError(f"shade spacing must be > 0 m, got {spacing_m}")
        self.spacing_m = float(spacing_m)
        self._poses: deque[tuple[float, float, float]] = deque(maxlen=max_shades)

    def update(self, position: np.ndarray, angle: float) -> None:
        x, y = float(position[0]), float(position[1])
        if self._poses:
            lx, ly, _ = self._poses[-1]
            if np.hypot(x - lx, y - ly) <= self.spacing_m:
                return
        self._poses.append((x, y, float(angle)))

    def clear(self) -> None:
        self._poses.clear()

    @property
    def poses(self) -> list[tuple[float, float, float]]:
        """(x m, y m, angle rad) of each shade, oldest first."""
        return list(self._poses)
