"""LanderView: the Lander2D seen from the side, the whole world in one frame."""

from __future__ import annotations

import numpy as np

from . import lander_draw as draw
from .history import FlightPath, Shades
from .painter import Painter
from .plane import PlaneView
from .scene import LanderScene
from .screen import Screen, check_render_mode


class LanderView:
    """Draws LanderScene frames: a window ("human") or (H, W, 3) uint8 arrays ("rgb_array").

    Keeps the episode's flight path and shades (a shade every `shade_distance_m` travelled);
    both restart when a scene's step goes backwards (a new episode) or on `reset()`.
    pygame is imported by the constructor, not before.
    """

    metadata = {"render_modes": ["human", "rgb_array"], "render_fps": 50}

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
        self.render_mode = check_render_mode(render_mode)
        self.show_path = show_path
        self.show_shades = show_shades
        self.show_spawn_zone = show_spawn_zone
        self.show_overlay = show_overlay
        self._path = FlightPath()
        self._shades = Shades(shade_distance_m)
        self._screen = Screen(render_mode, (width, height), "flyloop - Lander2D", fps)
        self._painter = Painter(self._screen.pg, self._screen.surface)
        self._close_up: Painter | None = None
        if show_close_up:
            cw, ch = draw.CLOSE_UP_SIZE
            if width >= 3 * cw and height >= 3 * ch:  # a small frame has no room for it
                window = self._screen.surface.subsurface((20, 20, cw, ch))
                self._close_up = Painter(self._screen.pg, window)
        self._plane: PlaneView | None = None
        self._plane_key: tuple[float, float] | None = None
        self._closed = False

    @property
    def size(self) -> tuple[int, int]:
        """(width, height) in pixels."""
        return self._screen.size

    @property
    def is_open(self) -> bool:
        """False once closed, by close() or by the user closing the window."""
        return self._screen.is_open

    def world_to_screen(self, scene: LanderScene, points: np.ndarray) -> np.ndarray:
        """Pixels (u, v) where world points (..., 2) in metres are drawn for this scene."""
        return self._plane_for(scene).to_screen(points)

    def reset(self) -> None:
        """Forget the flight path and shades (an env calls this from reset())."""
        self._path.clear()
        self._shades.clear()

    def render(self, scene: LanderScene) -> np.ndarray | None:
        """Draw one frame: returns it in rgb_array mode, None in human mode."""
        if self._closed:
            raise RuntimeError("this LanderView is closed; create a new one to render again")
        if not isinstance(scene, LanderScene):
            raise TypeError(f"LanderView.render needs a LanderScene, got {type(scene).__name__}")
        self._screen.poll_events()
        if not self._screen.is_open:
            return None  # the user closed the window: nothing to draw on any more
        if self._path.update(scene.step, scene.position):
            self._shades.clear()
        self._shades.update(scene.position, scene.angle)
        self._draw(scene)
        return self._screen.present()

    def close(self) -> None:
        """Close the window (if any). Safe to call more than once."""
        self._closed = True
        self._screen.close()

    def _plane_for(self, scene: LanderScene) -> PlaneView:
        key = (scene.world_width, scene.world_height)
        if self._plane is None or self._plane_key != key:
            self._plane = PlaneView.fit_world(scene.world_width, scene.world_height, self.size)
            self._plane_key = key
        return self._plane

    def _draw(self, s: LanderScene) -> None:
        p, plane = self._painter, self._plane_for(s)
        shade_poses = self._shades.poses if self.show_shades else []
        path_points = self._path.points if self.show_path else np.zeros((0, 2))
        draw.world(p, plane, s, shade_poses, path_points, spawn=self.show_spawn_zone)
        zoom = draw.CLOSE_UP_SCALE / plane.scale
        if self._close_up is not None and zoom >= 1.5:  # in a small world it adds nothing
            draw.close_up(self._close_up, s, shade_poses, path_points, zoom)
        draw.wind_indicator(p, s)
        if self.show_overlay:
            draw.overlay(p, plane, s)
