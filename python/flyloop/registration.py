"""Registering the envs with gymnasium (done by `import flyloop`)."""

from __future__ import annotations

import gymnasium

ENVS = {
    "flyloop/QuadHover-v0": ("flyloop.envs:QuadHoverEnv", "flyloop.vector:quad_hover_vector"),
    "flyloop/QuadWaypoints-v0": (
        "flyloop.envs:QuadWaypointsEnv",
        "flyloop.vector:quad_waypoints_vector",
    ),
    "flyloop/Lander2D-v0": ("flyloop.envs:Lander2DEnv", "flyloop.vector:lander2d_vector"),
    "flyloop/Lander2D-v1": (
        "flyloop.envs:Lander2DLandingEnv",
        "flyloop.vector:lander2d_landing_vector",
    ),
}


def register_envs() -> None:
    """Registers the env ids (idempotent). Each takes `backend="sitl"` (default) or
    `"native"`, in `gymnasium.make` and in `gymnasium.make_vec(...,
    vectorization_mode="vector_entry_point")`. No TimeLimit wrapper: the core truncates at
    `max_steps` itself; the env checker is left on (gymnasium's default)."""
    for env_id, (entry, vector_entry) in ENVS.items():
        if env_id in gymnasium.registry:
            continue
        gymnasium.register(
            id=env_id,
            entry_point=entry,
            vector_entry_point=vector_entry,
            max_episode_steps=None,
        )
