"""Scenes from what an env already has after each step: the observation and the info dict of
the task frame (names as the core's tasks emit them; `flyloop-sitl --describe-frame` lists
them). No extra request to the SITL is needed to draw a frame.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from .scene import LanderScene, QuadScene

# Observation slices of the Hover and Waypoints tasks (docs/reference/quadrotor.md).
_VELOCITY, _QUATERNION, _RATES = slice(3, 6), slice(9, 13), slice(13, 16)
_WIND, _MOTORS = slice(22, 25), slice(25, 29)
_LANDER_OUTCOMES = (
    ("lost_control", "lost control"),
    ("out_of_bounds", "out of bounds"),
    ("battery_empty", "battery empty"),
    ("time_limit", "time limit reached"),
)


def _required(info: Mapping[str, Any], name: str) -> Any:
    try:
        return info[name]
    except KeyError as exc:
        raise KeyError(f"info has no {name!r}: got {sorted(info)}") from exc


def quad_scene(
    observation: Any,
    info: Mapping[str, Any],
    *,
    reward: float | None = None,
    episode_return: float | None = None,
    bounds_half_size: float = 1.5,
    arm_length: float = 0.1,
) -> QuadScene:
    """A QuadScene from a Hover/Waypoints observation (33 or 37 values) and its info."""
    obs = np.asarray(observation, dtype=float).reshape(-1)
    if obs.size < 29:
        raise ValueError(f"a quadrotor observation has 33 or 37 values, got {obs.size}")
    status = ""
    if info.get("crashed"):
        status = "crashed"
    elif info.get("out_of_bounds"):
        status = "out of bounds"
    reached = info.get("waypoints_reached")
    return QuadScene(
        time_s=float(_required(info, "episode_time")),
        step=int(_required(info, "step_count")),
        position=_required(info, "position"),
        velocity=obs[_VELOCITY],
        quaternion=obs[_QUATERNION],
        body_rates=obs[_RATES],
        wind=obs[_WIND],
        motors=obs[_MOTORS],
        target=info.get("target_position"),
        next_waypoint=info.get("next_waypoint_pos"),
        reward=reward,
        episode_return=episode_return,
        bounds_half_size=bounds_half_size,
        arm_length=arm_length,
        waypoints_reached=None if reached is None else int(reached),
        status=status,
    )


def lander_scene(
    info: Mapping[str, Any],
    observation: Any = None,
    *,
    dt: float = 0.02,
    reward: float | None = None,
    episode_return: float | None = None,
    max_steps: int | None = None,
    params: Mapping[str, Any] | None = None,
) -> LanderScene:
    """A LanderScene from a Landing info dict (and its observation, whose 12th value gives a
    moving platform's velocity). `params` holds the model and task parameters
    the scene also draws (world_width, ground_height, platform_width, max_thrust,
    initial_battery, wind_speed, wind_enabled, spawn_x, spawn_y, initial_pos_random_range_m,
    ...); names as Lander2dParams / LandingParams, defaults as theirs."""
    p = dict(params or {})
    step = int(_required(info, "step"))
    outcome = next((text for key, text in _LANDER_OUTCOMES if info.get(key)), "")
    platform = _required(info, "platform_position")
    world = {
        name: float(p[name])
        for name in (
            "world_width",
            "world_height",
            "ground_height",
            "platform_width",
            "platform_height",
            "drone_width",
            "drone_height",
            "max_thrust",
            "initial_battery",
        )
        if name in p
    }
    wind_on = bool(p.get("wind_enabled", True))
    return LanderScene(
        time_s=step * dt,
        step=step,
        position=_required(info, "position"),
        velocity=_required(info, "velocity"),
        angle=float(_required(info, "angle")),
        angular_velocity=float(_required(info, "angular_velocity")),
        thrust=_required(info, "thrust"),
        battery=float(_required(info, "battery")),
        platform_x=float(platform[0]),
        platform_vx=_platform_vx(observation, p),
        wind_force=info.get("wind_force", (0.0, 0.0)),
        wind_speed=float(p.get("wind_speed", 5.0)) if wind_on else 0.0,
        landed=bool(info.get("landed", False)),
        crashed=bool(info.get("crashed", False)),
        outcome=outcome,
        max_steps=max_steps,
        reward=reward,
        episode_return=episode_return,
        spawn_center=(float(p.get("spawn_x", 25.0)), float(p.get("spawn_y", 40.0))),
        spawn_half_range=float(p.get("initial_pos_random_range_m", 5.0)),
        **world,
    )


def _platform_vx(observation: Any, params: Mapping[str, Any]) -> float:
    """Observation value 11 is platform vx / platform_speed (moving platform only)."""
    if observation is None:
        return 0.0
    obs = np.asarray(observation, dtype=float).reshape(-1)
    if obs.size < 12:
        return 0.0
    return float(obs[11]) * float(params.get("platform_speed", 1.5))
