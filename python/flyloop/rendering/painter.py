"""2D drawing primitives over a pygame surface: lines, arrows, discs, text, panels.

Takes the pygame module from the caller (see screen.import_pygame) so that importing this
file never imports pygame. Coordinates are float pixels; they are clamped to a safe range
because pygame rejects the huge integers a far-away or blown-up state would produce.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np

Color = tuple[int, int, int]
_LIMIT = 30_000.0
# DejaVu Sans renders crisper than pygame's bundled font at HUD sizes; this factor makes a
# requested size look about as large in both, so layouts hold whichever one is found.
_DEJAVU_SCALE = 0.68
_font_files: dict[bool, str | None] = {}


def _font_file(pg: Any, bold: bool) -> str | None:
    if bold not in _font_files:
        try:
            found = pg.font.match_font("dejavusans", bold=bold)
        except Exception:  # font discovery shells out to fc-list; any failure = bundled font
            found = None
        _font_files[bold] = found
    return _font_files[bold]


def _px(point: Sequence[float]) -> tuple[int, int]:
    x = min(max(float(point[0]), -_LIMIT), _LIMIT)
    y = min(max(float(point[1]), -_LIMIT), _LIMIT)
    return round(x), round(y)


class Painter:
    def __init__(self, pg: Any, surface: Any) -> None:
        self.pg = pg
        self.surface = surface
        self._fonts: dict[tuple[int, bool], Any] = {}
        self._gradient: tuple[tuple, Any] | None = None

    def font(self, size: int, bold: bool = False) -> Any:
        """A font whose capitals are about size * 0.45 px tall (pygame's default font scale)."""
        key = (size, bold)
        if key not in self._fonts:
            path = _font_file(self.pg, bold)
            if path is None:
                font = self.pg.font.Font(None, size)  # pygame's bundled font
                font.set_bold(bold)
            else:
                font = self.pg.font.Font(path, round(size * _DEJAVU_SCALE))
            self._fonts[key] = font
        return self._fonts[key]

    def fill(self, color: Color) -> None:
        self.surface.fill(color)

    def vertical_gradient(self, top: Color, bottom: Color) -> None:
        """Fill with a top-to-bottom gradient (drawn once per size and colours, then blitted)."""
        size = self.surface.get_size()
        key = (size, top, bottom)
        if self._gradient is None or self._gradient[0] != key:
            layer = self.pg.Surface(size)
            width, height = size
            for y in range(0, height, 4):
                t = y / max(1, height - 1)
                color = tuple(round(a + (b - a) * t) for a, b in zip(top, bottom, strict=True))
                self.pg.draw.rect(layer, color, (0, y, width, 4))
            self._gradient = (key, layer)
        self.surface.blit(self._gradient[1], (0, 0))

    def line(self, a: Sequence[float], b: Sequence[float], color: Color, width: int = 1) -> None:
        if width <= 1:
            self.pg.draw.aaline(self.surface, color, _px(a), _px(b))
        else:
            self.pg.draw.line(self.surface, color, _px(a), _px(b), width)

    def polyline(self, points: np.ndarray, color: Color, width: int = 1) -> None:
        if len(points) < 2:
            return
        pts = [_px(p) for p in points]
        if width <= 1:
            self.pg.draw.aalines(self.surface, color, False, pts)
        else:
            self.pg.draw.lines(self.surface, color, False, pts, width)

    def dashed_line(
        self,
        a: Sequence[float],
        b: Sequence[float],
        color: Color,
        width: int = 1,
        dash_px: float = 6.0,
    ) -> None:
        a_, b_ = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
        length = float(np.hypot(*(b_ - a_)))
        if length < 1e-6:
            return
        n = max(1, int(length / (2 * dash_px)))
        t = np.arange(2 * n) / (2 * n)
        ends = np.clip(a_ + np.outer(t, b_ - a_), -_LIMIT, _LIMIT).round().astype(int).tolist()
        draw = self.pg.draw
        for i in range(0, 2 * n, 2):
            if width <= 1:
                draw.aaline(self.surface, color, ends[i], ends[i + 1])
            else:
                draw.line(self.surface, color, ends[i], ends[i + 1], width)

    def arrow(
        self,
        start: Sequence[float],
        end: Sequence[float],
        color: Color,
        width: int = 3,
        head_px: float = 11.0,
    ) -> None:
        """A line from start to end with a filled triangular head at end."""
        s, e = np.asarray(start, dtype=float), np.asarray(end, dtype=float)
        d = e - s
        length = float(np.hypot(*d))
        if length < 1e-6:
            return
        u = d / length
        head = min(head_px, 0.6 * length)
        base = e - u * head
        self.line(s, base + u * 1.0, color, width)
        n = np.array([-u[1], u[0]]) * head * 0.5
        self.polygon([e, base + n, base - n], color)

    def disc(
        self,
        center: Sequence[float],
        radius: float,
        color: Color,
        outline: Color | None = None,
        outline_width: int = 1,
    ) -> None:
        c, r = _px(center), max(1, round(radius))
        self.pg.draw.circle(self.surface, color, c, r)
        if outline is not None:
            self.pg.draw.circle(self.surface, outline, c, r, outline_width)

    def ring(self, center: Sequence[float], radius: float, color: Color, width: int = 2) -> None:
        self.pg.draw.circle(self.surface, color, _px(center), max(1, round(radius)), width)

    def polygon(
        self,
        points: Sequence[Sequence[float]],
        color: Color,
        outline: Color | None = None,
        outline_width: int = 1,
    ) -> None:
        pts = [_px(p) for p in points]
        self.pg.draw.polygon(self.surface, color, pts)
        if outline is not None:
            self.pg.draw.polygon(self.surface, outline, pts, outline_width)

    def translucent_polygon(
        self, points: Sequence[Sequence[float]], color: Color, alpha: int
    ) -> None:
        """A polygon blended over what is drawn (shades of past poses)."""
        pts = np.array([_px(p) for p in points])
        lo = pts.min(axis=0)
        size = pts.max(axis=0) - lo + 1
        layer = self.pg.Surface((int(size[0]), int(size[1])), self.pg.SRCALPHA)
        self.pg.draw.polygon(layer, (*color, alpha), [tuple(p - lo) for p in pts])
        self.surface.blit(layer, (int(lo[0]), int(lo[1])))

    def panel(
        self,
        rect: tuple[int, int, int, int],
        fill: Color,
        alpha: int = 215,
        border: Color = (60, 60, 70),
    ) -> None:
        """A translucent rounded box for HUD text."""
        x, y, w, h = rect
        layer = self.pg.Surface((w, h), self.pg.SRCALPHA)
        self.pg.draw.rect(layer, (*fill, alpha), (0, 0, w, h), border_radius=6)
        self.surface.blit(layer, (x, y))
        self.pg.draw.rect(self.surface, border, rect, 1, border_radius=6)

    def text(
        self,
        text: str,
        pos: Sequence[float],
        color: Color,
        size: int = 20,
        anchor: str = "topleft",
        bold: bool = False,
    ) -> tuple[int, int]:
        """Draw text with its `anchor` (a pygame Rect attribute) at pos; returns its size."""
        image = self.font(size, bold).render(text, True, color)
        rect = image.get_rect(**{anchor: _px(pos)})
        self.surface.blit(image, rect)
        return rect.width, rect.height

    def text_size(self, text: str, size: int = 20, bold: bool = False) -> tuple[int, int]:
        return self.font(size, bold).size(text)


def rotate2d(points: np.ndarray, angle: float) -> np.ndarray:
    """Rotate (N, 2) points counter-clockwise by angle radians."""
    c, s = math.cos(angle), math.sin(angle)
    return np.asarray(points, dtype=float) @ np.array([[c, s], [-s, c]])
