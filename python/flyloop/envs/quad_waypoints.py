"""flyloop/QuadWaypoints-v0: fly a quadrotor through a sequence of waypoints."""

from __future__ import annotations

from ..tasks import WAYPOINTS
from .quad_hover import QuadHoverEnv


class QuadWaypointsEnv(QuadHoverEnv):
    """Fly a quadrotor through a sequence of waypoints as fast as possible (seed 001's
    ``SequentialWaypointEnv``, docs/reference/quadrotor.md).

    ``gymnasium.make("flyloop/QuadWaypoints-v0")``. Frames, units, motors (``frame``: n
    rotors), action space, starting state and errors are those of ``QuadHoverEnv``.

    ## Observation space

    ``Box(low, high, (29 + 2n,), float32)`` (37 on a quad): values 0 … 24+2n are QuadHover's
    with the *current* waypoint as the target (position bound ±2·√3·space_side_length =
    ±10.39 m), then (indices for the quad; + 2 per rotor beyond four)

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

    QuadHover's, plus the waypoint parameters (listed below).

    ## Version history

    - v0: first version (checkpoint bonus paid, crash flags kept in info, seeded resets).
    """

    SPEC = WAYPOINTS
