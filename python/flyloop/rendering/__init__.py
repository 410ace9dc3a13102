"""Rendering for flyloop's envs: pygame views of per-step scenes, and saving frames.

    view = QuadrotorView("rgb_array")    # or "human" for a window
    frame = view.render(QuadScene(...))  # (720, 960, 3) uint8; None in human mode

One file per view (quadrotor.py, lander.py), the 3D camera (camera.py), what both draw
with (canvas.py), recording.py. pygame is imported by a view's constructor, not here."""

from .camera import OrbitCamera
from .lander import LanderScene, LanderView
from .quadrotor import QuadrotorView, QuadScene
from .recording import Recording, record_episode, save_video

__all__ = [
    "LanderScene",
    "LanderView",
    "OrbitCamera",
    "QuadScene",
    "QuadrotorView",
    "Recording",
    "record_episode",
    "save_video",
]
