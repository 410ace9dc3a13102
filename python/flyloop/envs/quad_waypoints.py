"""flyloop/QuadWaypoints-v0: fly a quadrotor through a sequence of waypoints."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from ..tasks import WAYPOINTS
from .quad_hover import QuadHoverEnv


class QuadWaypointsEnv(QuadHoverEnv):
    """Fly a quadrotor through a sequence of waypoints as fast as possible (seed 001's
    ``SequentialWaypointEnv``, docs/reference/quadrotor.md).

    ``gymnasium.make("flyloop/QuadWaypoints-v0")``. Frames, units, motors, action space,
    starting state and errors are those of ``QuadHoverEnv``.

    ## Observation space

    ``Box(low, high, (37,), float32)``: values 0–32 are QuadHover's with the *current*
    waypoint as the target (position bound ±2·√3·space_side_length = ±10.39 m), then

    | index | value | unit | bound |
    |---|---|---|---|
    | 33–35 | next waypoint − position | m | ±2·√3·space_side_length |
    | 36 | time since the last waypoint was reached | s | [0, max_steps · dt] |

    ## Waypoints

    ``max_num_waypoints`` (15) points drawn from the episode's seed in the target cube, each
    at least min_target_distance from the previous one. A waypoint is reached within
    ``waypoint_reach_threshold_m`` (0.1 m); the next one becomes current.

    ## Reward

    On the step that reaches the current waypoint:
    ``max(checkpoint_bonus − bonus_decay_rate_per_sec · t_since_checkpoint, 1)``
    (the seed computed this bonus but never paid it; flyloop pays it). Otherwise
    ``tanh((v · d̂) / velocity_scale)`` toward the current waypoint. A positive reward gets
    ``+ 0.5 · mean(motor states)``.

    ## Episode end

    Terminated on a crash (as QuadHover) or beyond 2·√3·space_side_length (10.39 m) from the
    current waypoint. Truncated at ``max_steps`` or when every waypoint is reached.

    ## Info

    QuadHover's keys (about the current waypoint, ``crashed`` and ``out_of_bounds`` kept) plus
    ``waypoints_reached``, ``current_waypoint_pos`` (3, m), ``next_waypoint_pos`` (3, m),
    ``steps_since_checkpoint`` (seconds since the last waypoint, the seed's name).

    ## Arguments

    QuadHover's, plus ``max_num_waypoints=15``, ``waypoint_reach_threshold_m=0.1``,
    ``checkpoint_bonus=10.0``, ``bonus_decay_rate_per_sec=2.0``.

    ## Version history

    - v0: first version (checkpoint bonus paid, crash flags kept in info, seeded resets).
    """

    SPEC = WAYPOINTS

    def __init__(
        self,
        max_num_waypoints: int = 15,
        waypoint_reach_threshold_m: float = 0.1,
        checkpoint_bonus: float = 10.0,
        bonus_decay_rate_per_sec: float = 2.0,
        *,
        max_steps: int = 1000,
        dt: float = 0.01,
        target_change_interval: int | None = None,
        wind_strength_range: tuple[float, float] = (0.0, 5.0),
        use_wind: bool = True,
        render_mode: str | None = None,
        enable_crash_detection: bool = True,
        enable_out_of_bounds_detection: bool = True,
        crash_z_vel_threshold: float = -20.0,
        crash_tilt_threshold: float = 80.0,
        space_side_length: float = 3.0,
        start_height: float = 1.5,
        start_attitude_range: float = 0.1,
        min_target_distance: float = 1.0,
        velocity_scale: float = 3.0,
        model_params: Mapping[str, Any] | None = None,
        sitl_path: str | None = None,
        sitl_address: Any = None,
        vehicle: int = 1,
        timeout: float = 5.0,
        backend: str = "sitl",
        **flight_arguments: Any,
    ) -> None:
        super().__init__(
            max_steps=max_steps,
            dt=dt,
            target_change_interval=target_change_interval,
            wind_strength_range=wind_strength_range,
            use_wind=use_wind,
            render_mode=render_mode,
            enable_crash_detection=enable_crash_detection,
            enable_out_of_bounds_detection=enable_out_of_bounds_detection,
            crash_z_vel_threshold=crash_z_vel_threshold,
            crash_tilt_threshold=crash_tilt_threshold,
            space_side_length=space_side_length,
            start_height=start_height,
            start_attitude_range=start_attitude_range,
            min_target_distance=min_target_distance,
            velocity_scale=velocity_scale,
            model_params=model_params,
            sitl_path=sitl_path,
            sitl_address=sitl_address,
            vehicle=vehicle,
            timeout=timeout,
            backend=backend,
            max_num_waypoints=max_num_waypoints,
            waypoint_reach_threshold_m=waypoint_reach_threshold_m,
            checkpoint_bonus=checkpoint_bonus,
            bonus_decay_rate_per_sec=bonus_decay_rate_per_sec,
            **flight_arguments,
        )
