"""Rendering for flyloop's envs: pygame views fed with plain per-step scene data.

    from flyloop.rendering import QuadrotorView, QuadScene
    view = QuadrotorView("rgb_array")          # or "human" for a window
    frame = view.render(QuadScene(...))        # (720, 960, 3) uint8; None in human mode
    view.close()

One file per view (quadrotor.py, lander.py: scene, drawing, view), the 3D camera
(camera.py), what both draw with (canvas.py) and saving frames (recording.py). Importing
this package does not import pygame: each view's constructor does.
"""

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
