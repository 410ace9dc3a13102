"""Where a view draws: an off-screen surface ("rgb_array") or a window ("human").

pygame is imported here, on first use, so `import flyloop.rendering` stays free of it.
"""

from __future__ import annotations

import os
import sys
from typing import Any

import numpy as np

RENDER_MODES = ("human", "rgb_array")

# pygame drives one window per process; a second human view would silently steal it.
_window_owner: Screen | None = None


def _has_display() -> bool:
    if sys.platform in ("win32", "darwin"):
        return True
    return bool(os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY"))


def import_pygame(render_mode: str) -> Any:
    """pygame, with SDL told to draw off-screen when there is no display for rgb_array."""
    if render_mode == "rgb_array" and not _has_display():
        os.environ.setdefault("SDL_VIDEODRIVER", "dummy")
    os.environ.setdefault("PYGAME_HIDE_SUPPORT_PROMPT", "1")
    import pygame

    return pygame


def check_render_mode(render_mode: object) -> str:
    if render_mode not in RENDER_MODES:
        raise ValueError(
            f"render_mode must be one of {RENDER_MODES}, got {render_mode!r} "
            "(with render_mode None an env needs no view at all)"
        )
    return str(render_mode)


class Screen:
    """A pygame surface of `size` pixels, shown in a window in human mode."""

    def __init__(self, render_mode: str, size: tuple[int, int], caption: str, fps: float) -> None:
        global _window_owner
        self.render_mode = check_render_mode(render_mode)
        width, height = int(size[0]), int(size[1])
        if width < 64 or height < 64:
            raise ValueError(f"the frame must be at least 64 x 64 pixels, got {width} x {height}")
        if fps < 0:
            raise ValueError(f"fps must be >= 0 (0 = as fast as possible), got {fps}")
        self.size = (width, height)
        self.fps = float(fps)
        self.pg = import_pygame(self.render_mode)
        self.pg.font.init()
        self.clock = None
        if self.render_mode == "human":
            if _window_owner is not None and _window_owner.is_open:
                raise RuntimeError(
                    "another human-mode view already owns the pygame window of this process; "
                    "close it first (pygame shows one window per process)"
                )
            try:
                self.pg.display.init()
                self.surface = self.pg.display.set_mode(self.size)
            except self.pg.error as exc:
                raise RuntimeError(
                    f"render_mode='human' needs a display ({exc}); run under a desktop or "
                    "xvfb-run, or use render_mode='rgb_array' headless"
                ) from exc
            self.pg.display.set_caption(caption)
            self.clock = self.pg.time.Clock()
            _window_owner = self
        else:
            self.surface = self.pg.Surface(self.size)
        self.is_open = True

    def poll_events(self) -> list[Any]:
        """This frame's window events (human mode); the window closes on QUIT or Escape."""
        if self.render_mode != "human" or not self.is_open:
            return []
        events = self.pg.event.get()
        for event in events:
            is_escape = event.type == self.pg.KEYDOWN and event.key == self.pg.K_ESCAPE
            if event.type == self.pg.QUIT or is_escape:
                self.close()
                break
        return events

    def present(self) -> np.ndarray | None:
        """Show the frame (human, paced to fps) or return it as (H, W, 3) uint8."""
        if self.render_mode == "human":
            self.pg.display.flip()
            if self.clock is not None and self.fps > 0:
                self.clock.tick(self.fps)
            return None
        # One copy, already row-major (H, W, 3); the frame never aliases the surface.
        width, height = self.size
        data = self.pg.image.tobytes(self.surface, "RGB")
        return np.frombuffer(data, dtype=np.uint8).reshape(height, width, 3).copy()

    def close(self) -> None:
        """Close the window (human mode). Safe to call more than once."""
        global _window_owner
        if not self.is_open:
            return
        self.is_open = False
        if self.render_mode == "human":
            self.pg.display.quit()
            if _window_owner is self:
                _window_owner = None
