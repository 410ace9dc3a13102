"""Metres to pixels for the 2D lander view (x right, y up -> u right, v down). Pure numpy."""

from __future__ import annotations

import numpy as np


class PlaneView:
    """A uniform scale (px per metre) and the pixel (u0, v0) where world (0, 0) lands."""

    def __init__(self, scale: float, u0: float, v0: float) -> None:
        if not scale > 0:
            raise ValueError(f"scale must be > 0 px/m, got {scale}")
        self.scale, self.u0, self.v0 = float(scale), float(u0), float(v0)

    @classmethod
    def fit_world(
        cls, world_width: float, world_height: float, size: tuple[int, int], margin_px: int = 12
    ) -> PlaneView:
        """The world box (0, 0)-(W, H), centred, filling the frame less margin_px per side."""
        width, height = size
        usable_w, usable_h = width - 2 * margin_px, height - 2 * margin_px
        if usable_w <= 0 or usable_h <= 0 or world_width <= 0 or world_height <= 0:
            raise ValueError(
                f"cannot fit a {world_width} x {world_height} m world in {width} x {height} px"
            )
        scale = min(usable_w / world_width, usable_h / world_height)
        return cls(
            scale, (width - world_width * scale) / 2.0, (height + world_height * scale) / 2.0
        )

    @classmethod
    def centred_on(cls, center: np.ndarray, scale: float, size: tuple[int, int]) -> PlaneView:
        """World point `center` at the middle of a frame of `size` pixels."""
        return cls(scale, size[0] / 2.0 - center[0] * scale, size[1] / 2.0 + center[1] * scale)

    def to_screen(self, points: np.ndarray) -> np.ndarray:
        p = np.asarray(points, dtype=float)
        return np.stack([self.u0 + p[..., 0] * self.scale, self.v0 - p[..., 1] * self.scale], -1)

    def to_world(self, pixels: np.ndarray) -> np.ndarray:
        q = np.asarray(pixels, dtype=float)
        return np.stack(
            [(q[..., 0] - self.u0) / self.scale, (self.v0 - q[..., 1]) / self.scale], -1
        )
