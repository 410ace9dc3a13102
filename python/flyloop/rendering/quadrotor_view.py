"""QuadrotorView: the quadrotor in a 3D perspective view with an interactive camera."""

from __future__ import annotations

import numpy as np

from . import quad_hud as hud
from . import quad_world as qw
from .camera import OrbitCamera
from .camera_controls import CameraControls
from .history import FlightPath
from .painter import Painter
from .scene import QuadScene
from .screen import Screen, check_render_mode

BACKGROUND_TOP = (232, 238, 248)
BACKGROUND_BOTTOM = (246, 246, 250)


def default_camera(bounds_half_size: float) -> OrbitCamera:
    """Looking at the middle of the target box from the south-west, above, the box in view."""
    h = bounds_half_size
    return OrbitCamera(look_at=np.array([0.0, 0.0, 0.8 * h]), distance=4.2 * h)


class QuadrotorView:
    """Draws QuadScene frames: a window ("human") or (H, W, 3) uint8 arrays ("rgb_array").

    In a window: drag with the left mouse button to orbit, wheel to zoom, W/A/S/D to move
    along the ground, Q/E down/up, R to reset the camera, Esc or the close box to close.
    The vehicle is drawn `drone_scale` times its real size (a 0.1 m arm would be a few
    pixels); its centre is at its true position. The trail keeps the last `trail_steps`
    positions of the episode and restarts when the step number goes backwards or on reset().
    pygame is imported by the constructor, not before.
    """

    metadata = {"render_modes": ["human", "rgb_array"], "render_fps": 50}

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
        self.render_mode = check_render_mode(render_mode)
        if not drone_scale > 0:
            raise ValueError(f"drone_scale must be > 0, got {drone_scale}")
        self.drone_scale = float(drone_scale)
        self.hud = hud
        self._camera = camera
        self._trail = FlightPath(max(2, trail_steps))
        self._screen = Screen(render_mode, (width, height), "flyloop - Quadrotor 3D", fps)
        self._painter = Painter(self._screen.pg, self._screen.surface)
        self._controls: CameraControls | None = None
        self._closed = False

    @property
    def size(self) -> tuple[int, int]:
        """(width, height) in pixels."""
        return self._screen.size

    @property
    def is_open(self) -> bool:
        """False once closed, by close() or by the user closing the window."""
        return self._screen.is_open

    @property
    def camera(self) -> OrbitCamera | None:
        """The camera (created at the first render from the scene's bounds if not given)."""
        return self._camera

    def world_to_screen(self, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Pixels (..., 2) of world points (..., 3) and whether each is in front of the camera."""
        if self._camera is None:
            raise RuntimeError("the camera is set up by the first render (or pass camera=...)")
        return self._camera.project(points, *self.size)

    def reset(self) -> None:
        """Forget the trail (an env calls this from reset())."""
        self._trail.clear()

    def render(self, scene: QuadScene) -> np.ndarray | None:
        """Draw one frame: returns it in rgb_array mode, None in human mode."""
        if self._closed:
            raise RuntimeError("this QuadrotorView is closed; create a new one to render again")
        if not isinstance(scene, QuadScene):
            raise TypeError(f"QuadrotorView.render needs a QuadScene, got {type(scene).__name__}")
        if self._camera is None:
            self._camera = default_camera(scene.bounds_half_size)
        if self._controls is None:
            self._controls = CameraControls(self._screen.pg, self._camera)
        self._controls.handle(self._screen.poll_events())
        if not self._screen.is_open:
            return None  # the user closed the window
        self._trail.update(scene.step, scene.position)
        self._draw(scene)
        return self._screen.present()

    def close(self) -> None:
        """Close the window (if any). Safe to call more than once."""
        self._closed = True
        self._screen.close()

    def _draw(self, scene: QuadScene) -> None:
        p = self._painter
        p.vertical_gradient(BACKGROUND_TOP, BACKGROUND_BOTTOM)
        projector = qw.Projector(self._camera, self.size)
        trail = self._trail.points
        qw.world(p, projector, scene, trail if len(trail) else np.zeros((0, 3)), self.drone_scale)
        if self.hud:
            hud.info_panel(p, scene)
            hud.motor_bars(p, scene)
            hud.axis_gizmo(p, self._camera)
            hud.wind_dial(p, scene, self._camera)
            hud.legend(p)
            if self.render_mode == "human":
                hud.controls_hint(p)
