"""flyloop: gymnasium environments over flyloop's MAVLink SITL.

Importing the package registers the envs with gymnasium:

    import gymnasium, flyloop
    env = gymnasium.make("flyloop/QuadHover-v0")          # or QuadWaypoints-v0, Lander2D-v0
    envs = gymnasium.make_vec("flyloop/QuadHover-v0", num_envs=16)  # one SITL, 16 vehicles

`flyloop.parallel_env("flyloop/Swap-v0", num_agents=4)` is a PettingZoo multi-agent env
(flyloop.multi_agent). `gymnasium.make("flyloop:flyloop/QuadHover-v0")` imports the package
itself. Rendering lives in `flyloop.rendering` (pygame is imported only when a view is made).
"""

from .errors import SitlError, SitlNotFoundError, SitlParameterError
from .multi_agent import MultiAgentVectorEnv, parallel_env
from .registration import register_envs
from .sitl_process import find_sitl_binary

__version__ = "0.1.0"

__all__ = [
    "MultiAgentVectorEnv",
    "SitlError",
    "SitlNotFoundError",
    "SitlParameterError",
    "find_sitl_binary",
    "parallel_env",
    "register_envs",
]

register_envs()
