"""The flyloop gymnasium envs."""

from .base import FlyloopEnv
from .lander2d import Lander2DEnv, Lander2DLandingEnv
from .quad_hover import QuadHoverEnv
from .quad_waypoints import QuadWaypointsEnv

__all__ = ["FlyloopEnv", "Lander2DEnv", "Lander2DLandingEnv", "QuadHoverEnv", "QuadWaypointsEnv"]
