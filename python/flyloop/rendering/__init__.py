"""Rendering for flyloop's envs: pygame views fed with plain per-step scene data.

    from flyloop.rendering import QuadrotorView, QuadScene
    view = QuadrotorView("rgb_array")          # or "human" for a window
    frame = view.render(QuadScene(...))        # (720, 960, 3) uint8; None in human mode
    view.close()

Importing this package does not import pygame: each view's constructor does.
"""

from .camera import OrbitCamera
from .from_task import lander_scene, quad_scene
from .lander_view import LanderView
from .quadrotor_view import QuadrotorView
from .recording import FrameRecorder, Recording, record_episode, save_video
from .scene import LanderScene, QuadScene

__all__ = [
    "FrameRecorder",
    "LanderScene",
    "LanderView",
    "OrbitCamera",
    "QuadScene",
    "QuadrotorView",
    "Recording",
    "lander_scene",
    "quad_scene",
    "record_episode",
    "save_video",
]
