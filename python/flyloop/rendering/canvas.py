"""What both views draw with: View (the frame, off-screen or a window, and the episode's path)
and Painter (2D primitives in float pixels, clamped to a range pygame accepts: a blown-up
state would give huge integers)."""

from __future__ import annotations

import os
import sys
from collections import deque
from collections.abc import Sequence
from typing import Any

import numpy as np

RENDER_MODES = ("human", "rgb_array")
Color = tuple[int, int, int]
Point = Sequence[float]
_LIMIT = 30_000.0
# DejaVu Sans renders crisper than pygame's bundled font at HUD sizes; this factor makes a
# requested size look about as large in both, so layouts hold whichever one is found.
_DEJAVU_SCALE = 0.68
_font_files: dict[bool, str | None] = {}
# pygame drives one window per process; a second human view would silently steal it.
_window_owner: View | None = None
# SDL_VIDEODRIVER=dummy set by an rgb_array view (not by the user): a human view drops it.
_dummy_driver_ours = False
# SDL's drivers that draw nowhere: pygame falls back to them when there is no display.
_HEADLESS_DRIVERS = ("offscreen", "dummy")
NO_DISPLAY = (
    "render_mode='human' needs a display to open its window, and this process has none "
    "({why}). Run it on a desktop, under a virtual display (`xvfb-run -a python ...`), or "
    "use render_mode='rgb_array' to get the frames as arrays (e.g. to save a video with "
    "flyloop.rendering.record_episode)."
)


def _has_display() -> bool:
    return sys.platform in ("win32", "darwin") or bool(
        os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")
    )


def _open_window(pg: Any, size: tuple[int, int]) -> Any:
    """The window's surface, or RuntimeError saying what to do: pygame itself opens an
    invisible off-screen window when there is no display, and raises nothing."""
    global _dummy_driver_ours
    if _dummy_driver_ours and os.environ.get("SDL_VIDEODRIVER") == "dummy":
        del os.environ["SDL_VIDEODRIVER"]
        _dummy_driver_ours = False
    asked = os.environ.get("SDL_VIDEODRIVER")  # the user's choice of driver stands
    if not asked and not _has_display():
        raise RuntimeError(NO_DISPLAY.format(why="DISPLAY and WAYLAND_DISPLAY are not set"))
    try:
        pg.display.init()
        surface = pg.display.set_mode(size)
    except pg.error as exc:
        raise RuntimeError(NO_DISPLAY.format(why=f"SDL: {exc}")) from exc
    driver = pg.display.get_driver()
    if driver in _HEADLESS_DRIVERS and driver != asked:
        pg.display.quit()
        why = f"SDL fell back to its {driver!r} driver"
        if not asked and os.environ.get("DISPLAY"):
            # SDL tried X11 and moved on without a word: ask for X11 itself once, which either
            # opens the window or says why it cannot.
            return _open_x11(pg, size, why)
        raise RuntimeError(NO_DISPLAY.format(why=why))
    return surface


def _open_x11(pg: Any, size: tuple[int, int], why: str) -> Any:
    """The window on DISPLAY through SDL's X11 driver, or RuntimeError with SDL's reason."""
    os.environ["SDL_VIDEODRIVER"] = "x11"
    try:
        pg.display.init()
        return pg.display.set_mode(size)
    except pg.error as exc:
        display = os.environ.get("DISPLAY")
        raise RuntimeError(NO_DISPLAY.format(why=f"{why}; X11 on {display}: {exc}")) from exc
    finally:
        del os.environ["SDL_VIDEODRIVER"]


def _px(point: Point) -> tuple[int, int]:
    x = min(max(float(point[0]), -_LIMIT), _LIMIT)
    y = min(max(float(point[1]), -_LIMIT), _LIMIT)
    return round(x), round(y)


class Painter:
    def __init__(self, pg: Any, surface: Any) -> None:
        self.pg, self.surface = pg, surface
        self._fonts: dict[tuple[int, bool], Any] = {}

    def font(self, size: int, bold: bool = False) -> Any:
        """A font whose capitals are about size * 0.45 px tall (pygame's default font scale)."""
        if (size, bold) not in self._fonts:
            if bold not in _font_files:
                try:
                    _font_files[bold] = self.pg.font.match_font("dejavusans", bold=bold)
                except Exception:  # font discovery shells out to fc-list; failure = bundled font
                    _font_files[bold] = None
            if _font_files[bold] is None:
                font = self.pg.font.Font(None, size)  # pygame's bundled font
                font.set_bold(bold)
            else:
                font = self.pg.font.Font(_font_files[bold], round(size * _DEJAVU_SCALE))
            self._fonts[size, bold] = font
        return self._fonts[size, bold]

    def gradient(self, box: tuple[int, int, int, int], v_top, v_bottom, top, bottom) -> None:
        """Fill box (left, top, right, bottom; clipped to the frame) in 4 px bands, shading
        from colour `top` at row v_top to `bottom` at row v_bottom."""
        (width, height), (left, y0, right, y1) = self.surface.get_size(), box
        left, y0, right, y1 = max(0, left), max(0, y0), min(width, right), min(height, y1)
        for v in range(y0, y1, 4):
            t = (v - v_top) / max(1.0, v_bottom - v_top)
            color = tuple(round(a + (b - a) * t) for a, b in zip(top, bottom, strict=True))
            self.pg.draw.rect(self.surface, color, (left, v, right - left, min(4, y1 - v)))

    def line(self, a: Point, b: Point, color: Color, width: int = 1) -> None:
        if width <= 1:
            self.pg.draw.aaline(self.surface, color, _px(a), _px(b))
        else:
            self.pg.draw.line(self.surface, color, _px(a), _px(b), width)

    def polyline(self, points: np.ndarray, color: Color, width: int = 1) -> None:
        pts = [_px(p) for p in points]
        if width <= 1:
            self.pg.draw.aalines(self.surface, color, False, pts)
        else:
            self.pg.draw.lines(self.surface, color, False, pts, width)

    def dashed_line(self, a: Point, b: Point, color: Color, width: int, dash_px: float) -> None:
        a_, b_ = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
        length = float(np.hypot(*(b_ - a_)))
        if length < 1e-6:
            return
        n = max(1, int(length / (2 * dash_px)))  # dash j covers t in [j / n, (j + 0.5) / n]
        # Only the dashes near the frame: a far-off state's line would ask for billions.
        t0, t1 = 0.0, 1.0
        for axis, side in enumerate(self.surface.get_size()):
            lo, hi, d = -16 - a_[axis], side + 16 - a_[axis], b_[axis] - a_[axis]
            if d == 0 and not lo <= 0 <= hi:
                return
            if d != 0:
                t0, t1 = max(t0, min(lo / d, hi / d)), min(t1, max(lo / d, hi / d))
        if t0 > t1:
            return
        first, last = max(0, int(t0 * n) - 1), min(n, int(t1 * n) + 2)
        # Rounded in one go: a long dashed line has hundreds of dashes.
        ends = a_ + np.outer(np.arange(2 * first, 2 * last) / (2 * n), b_ - a_)
        ends = np.clip(ends, -_LIMIT, _LIMIT).round().astype(int).tolist()
        for i in range(0, len(ends), 2):  # already pixels: line()'s clamping would be slow
            if width <= 1:
                self.pg.draw.aaline(self.surface, color, ends[i], ends[i + 1])
            else:
                self.pg.draw.line(self.surface, color, ends[i], ends[i + 1], width)

    def arrow(self, start: Point, end: Point, color: Color, width: int, head_px=11.0) -> None:
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

    def disc(self, center: Point, radius: float, color: Color, outline=None, width=1) -> None:
        c, r = _px(center), max(1, round(radius))
        self.pg.draw.circle(self.surface, color, c, r)
        if outline is not None:
            self.pg.draw.circle(self.surface, outline, c, r, width)

    def ring(self, center: Point, radius: float, color: Color, width: int) -> None:
        self.pg.draw.circle(self.surface, color, _px(center), max(1, round(radius)), width)

    def polygon(self, points: Sequence[Point], color: Color, outline=None, width=1) -> None:
        pts = [_px(p) for p in points]
        self.pg.draw.polygon(self.surface, color, pts)
        if outline is not None:
            self.pg.draw.polygon(self.surface, outline, pts, width)

    def translucent_polygon(self, points: Sequence[Point], color: Color, alpha: int) -> None:
        pts = np.array([_px(p) for p in points])
        # Only the polygon's part of the frame (and a margin where pygame's clipping leaves
        # marks): a vertex far off screen (a turned camera's shadow) would ask for gigabytes.
        lo = np.maximum(pts.min(axis=0), -8)
        size = np.minimum(pts.max(axis=0), np.array(self.surface.get_size()) + 8) - lo + 1
        if np.any(size <= 0):
            return
        layer = self.pg.Surface((int(size[0]), int(size[1])), self.pg.SRCALPHA)
        self.pg.draw.polygon(layer, (*color, alpha), [tuple(p - lo) for p in pts])
        self.surface.blit(layer, (int(lo[0]), int(lo[1])))

    def panel(self, rect: tuple[int, int, int, int], fill: Color) -> None:
        x, y, w, h = rect
        layer = self.pg.Surface((w, h), self.pg.SRCALPHA)
        self.pg.draw.rect(layer, (*fill, 215), (0, 0, w, h), border_radius=6)
        self.surface.blit(layer, (x, y))
        self.pg.draw.rect(self.surface, (60, 60, 70), rect, 1, border_radius=6)

    def text(self, s: str, at: Point, color: Color, size: int, anchor="topleft", bold=False):
        """Draw s with its `anchor` (a pygame Rect attribute) at `at`."""
        image = self.font(size, bold).render(s, True, color)
        self.surface.blit(image, image.get_rect(**{anchor: _px(at)}))

    def bar(self, rect: tuple[int, int, int, int], fraction: float, color: Color) -> None:
        fraction = min(max(fraction, 0.0), 1.0)
        self.pg.draw.rect(self.surface, (210, 210, 210), rect)
        filled = (rect[0], rect[1], round(rect[2] * fraction), rect[3])
        self.pg.draw.rect(self.surface, color, filled)
        self.pg.draw.rect(self.surface, (10, 10, 20), rect, 1)


class View:
    """The frame (a window in human mode), its Painter, closing and the episode's `path`: one
    position per step, the oldest dropped past `path_steps`. Imports pygame, not before."""

    def __init__(
        self, render_mode: str, size: tuple[int, int], caption: str, fps: float, path_steps: int
    ) -> None:
        global _window_owner, _dummy_driver_ours
        self.path: deque[np.ndarray] = deque(maxlen=path_steps)
        self._last_step: int | None = None
        if render_mode not in RENDER_MODES:
            raise ValueError(f"render_mode must be one of {RENDER_MODES}, got {render_mode!r}")
        self.render_mode, self.size, self.fps = render_mode, (int(size[0]), int(size[1])), fps
        if render_mode == "rgb_array" and not _has_display():  # SDL draws off-screen
            if "SDL_VIDEODRIVER" not in os.environ:
                os.environ["SDL_VIDEODRIVER"] = "dummy"
                _dummy_driver_ours = True
        os.environ.setdefault("PYGAME_HIDE_SUPPORT_PROMPT", "1")
        import pygame as pg

        self._pg = pg
        pg.font.init()
        if render_mode == "human":
            if _window_owner is not None:
                raise RuntimeError(
                    "another human-mode view already owns the pygame window of this process; "
                    "close it first (pygame shows one window per process)"
                )
            self._surface = _open_window(pg, self.size)
            pg.display.set_caption(caption)
            self._clock = pg.time.Clock()
            _window_owner = self
        else:
            self._surface = pg.Surface(self.size)
        self._painter = Painter(pg, self._surface)
        # is_open turns False also when the user closes the window; _closed only by close().
        self.is_open, self._closed = True, False

    def reset(self) -> None:
        """Forget the episode's history (an env calls this from reset())."""
        self.path.clear()
        self._last_step = None

    def _follow(self, step: int, position: np.ndarray) -> bool:
        """Record the position of `step` (replaced if seen); True when it began an episode: a
        view sees only the current step, so a lower step number than the last means a new one."""
        new_episode = self._last_step is not None and step < self._last_step
        if new_episode:
            self.path.clear()
        elif self._last_step == step and self.path:
            self.path.pop()
        self.path.append(np.array(position, dtype=float))
        self._last_step = step
        return new_episode

    def _drawable(self) -> bool:
        """Whether to draw this frame: False once the user closed the window (QUIT, Escape)."""
        if self._closed:
            raise RuntimeError(f"this {type(self).__name__} is closed; create a new one to render")
        if self.render_mode == "human" and self.is_open:
            pg = self._pg
            for event in pg.event.get():
                if event.type == pg.QUIT or (event.type == pg.KEYDOWN and event.key == pg.K_ESCAPE):
                    self._shut()
        return self.is_open

    def _present(self) -> np.ndarray | None:
        """Show the frame (human, paced to fps) or return it as (H, W, 3) uint8."""
        if self.render_mode == "human":
            self._pg.display.flip()
            if self.fps > 0:
                self._clock.tick(self.fps)
            return None
        # One copy, already row-major (H, W, 3); the frame never aliases the surface.
        data = self._pg.image.tobytes(self._surface, "RGB")
        return np.frombuffer(data, dtype=np.uint8).reshape(self.size[1], self.size[0], 3).copy()

    def _shut(self) -> None:
        global _window_owner
        if self.is_open and self.render_mode == "human":
            self._pg.display.quit()
            _window_owner = None  # an open human view is the owner: no second one can open
        self.is_open = False

    def close(self) -> None:
        """Close the window (if any). Safe to call more than once."""
        self._closed = True
        self._shut()
