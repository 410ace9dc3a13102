"""Window input for the 3D camera: mouse drag orbits, wheel zooms, W/A/S/D move along the
ground, Q/E move down/up, R resets. Held keys are tracked from KEYDOWN/KEYUP events (not
pygame.key.get_pressed) so the same events drive it in a test as from a person."""

from __future__ import annotations

from typing import Any

from .camera import OrbitCamera

DEGREES_PER_PIXEL = 0.3
MOVE_FRACTION = 0.012  # per frame, of the camera distance
ZOOM_STEP = 0.9
MIN_DISTANCE, MAX_DISTANCE = 0.5, 200.0


class CameraControls:
    def __init__(self, pg: Any, camera: OrbitCamera) -> None:
        self.pg = pg
        self.camera = camera
        self._dragging = False
        self._held: set[int] = set()
        self._moves = {
            pg.K_w: (1, 0, 0),
            pg.K_s: (-1, 0, 0),
            pg.K_d: (0, 1, 0),
            pg.K_a: (0, -1, 0),
            pg.K_e: (0, 0, 1),
            pg.K_q: (0, 0, -1),
        }

    def handle(self, events: list[Any]) -> None:
        """Apply this frame's events, then one frame of movement for each key held or pressed
        in this frame (a tap shorter than a frame still moves once)."""
        pg = self.pg
        tapped: set[int] = set()
        for event in events:
            if event.type == pg.MOUSEBUTTONDOWN and event.button == 1:
                self._dragging = True
            elif event.type == pg.MOUSEBUTTONUP and event.button == 1:
                self._dragging = False
            elif event.type == pg.MOUSEMOTION and self._dragging:
                dx, dy = event.rel
                # Dragging right turns the world right; dragging down looks from higher up.
                self.camera.orbit(-dx * DEGREES_PER_PIXEL, dy * DEGREES_PER_PIXEL)
            elif event.type == pg.MOUSEWHEEL:
                distance = self.camera.distance * ZOOM_STEP ** float(event.y)
                self.camera.distance = min(max(distance, MIN_DISTANCE), MAX_DISTANCE)
            elif event.type == pg.KEYDOWN:
                if event.key == pg.K_r:
                    self.camera.reset()
                elif event.key in self._moves:
                    self._held.add(event.key)
                    tapped.add(event.key)
            elif event.type == pg.KEYUP:
                self._held.discard(event.key)
            elif event.type == pg.WINDOWFOCUSLOST:
                self._held.clear()
                self._dragging = False
        step = MOVE_FRACTION * self.camera.distance
        for key in self._held | tapped:
            forward, right, up = self._moves[key]
            self.camera.move(forward * step, right * step, up * step)
