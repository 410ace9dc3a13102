"""flyloop/QuadHover-v0: fly a quadrotor to a target and hold it."""

from __future__ import annotations

import numpy as np

from ..tasks import HOVER, observation_slices, parameter_values
from .base import FlyloopEnv


class QuadHoverEnv(FlyloopEnv):
    """Fly a quadrotor to a target point and hold it there (seed 001's ``DroneEnv``, the
    reference environment described in docs/reference/quadrotor.md).

    ``gymnasium.make("flyloop/QuadHover-v0")`` (after ``import flyloop``). The physics,
    observation, reward and termination are computed by flyloop's Rust core inside the
    ``flyloop-sitl`` process this env starts; the env exchanges one MAVLink datagram with it
    per step (lockstep, no wall clock).

    ## Frames and units

    World ENU (x east, y north, z up, gravity along −z), body FLU (x forward, y left, z up),
    quaternions ``[w, x, y, z]`` rotating body → world. Metres, seconds, radians (tilt
    thresholds in degrees, as in the seed). Motors follow PX4's quad-X: 0 front-right (CCW),
    1 rear-left (CCW), 2 front-left (CW), 3 rear-right (CW); thrust per motor 10 N · m² for
    motor state m ∈ [0, 1]; hover at m ≈ 0.495 with the default mass of 1 kg.

    ``frame`` picks another of the core's rotor tables: ``"quad_plus"``, ``"hexa_x"`` (six
    motors in PX4's 6001 order, hover at m ≈ 0.404 at 1 kg) or ``"octo_x"`` (eight, PX4's
    8001 order); n below is its rotor count (4 on the quads).

    ## Action space

    ``Box(0, 1, (n,), float32)``: commanded motor states, in motor order above. Values outside
    [0, 1] are clipped by the core; a non-finite value raises ``ValueError``. The motors follow
    the command with a first-order lag (τ = 0.08 s).

    ## Observation space

    ``Box(low, high, (25 + 2n,), float32)`` (33 on a quad, 37 on a hexa, 41 on an octo);
    every value is clipped into its bound by the core:

    | index | value | unit | bound |
    |---|---|---|---|
    | 0–2 | target − position | m | ±√3·space_side_length (±5.196) |
    | 3–5 | velocity | m/s | ±40 |
    | 6–8 | linear acceleration (total force / mass, gravity included) | m/s² | ±50 |
    | 9–12 | attitude quaternion w, x, y, z (w ≥ 0) | 1 | ±1 |
    | 13–15 | body rates | rad/s | ±10 |
    | 16–18 | angular acceleration | rad/s² | ±100 |
    | 19–21 | body z axis in the world ("normal") | 1 | ±1 |
    | 22–24 | wind velocity | m/s | ±(wind max + 5 σ/√(2θ)) (±10 by default; ±1 without wind) |
    | 25 … 24+n | motor states | 1 | [0, 1] |
    | 25+n … 24+2n | motor commands in effect | 1 | [0, 1] |

    ## Reward

    With d = ‖target − position‖ and d̂ the unit vector toward the target:
    ``r_pos = exp(−d)``, ``r_vel = tanh((v · d̂) / velocity_scale)``,
    ``reward = r_pos + 0.5 · (1 − r_pos) · r_vel`` — 1 on the target, in (−0.5, 1].

    ## Starting state

    Position (0, 0, start_height = 1.5 m), roll, pitch and yaw each uniform in
    ±start_attitude_range (0.1 rad), at rest, motors at the hover state. Target: x, y uniform
    in ±space_side_length/2, z in [0, space_side_length], at least min_target_distance (1 m)
    from the start. Everything is drawn from the episode's seed.

    ## Episode end

    Terminated on a crash (``enable_crash_detection``: height ≤ 0, vertical velocity below
    ``crash_z_vel_threshold``, or |roll| or |pitch| above ``crash_tilt_threshold`` degrees) or
    out of bounds (``enable_out_of_bounds_detection``: d > √3·space_side_length). Truncated when
    the step count reaches ``max_steps``. With ``target_change_interval`` N a new target is
    drawn every N steps (it appears in the observation of that step).

    ## Info

    ``distance_to_target`` (m), ``position`` (3, m), ``target_position`` (3, m),
    ``step_count``, ``episode_time`` (s), ``distance_progress`` (initial − current distance,
    m), ``crashed``, ``out_of_bounds`` — in reset() and every step(). Values travel as
    float32.

    ## Arguments

    The task arguments (listed below with the core's defaults, units and descriptions, and in
    ``inspect.signature(QuadHoverEnv)``) are the core's parameters of the task under their own
    names, except the seed's ``use_wind`` (core ``wind_enabled``), ``wind_strength_range``
    ((``wind_speed_min``, ``wind_speed_max``): per-episode mean wind speed drawn in this range,
    plus Ornstein–Uhlenbeck turbulence), ``target_change_interval`` (None: never),
    ``action_interface``, ``observation_noise`` and ``randomize``. The env's own:

    - ``model_params=None``: other physical parameters of the quadrotor by their core name,
      e.g. ``{"mass": 1.2, "pendulum_coefficient": 0.03}`` (docs/parameters.md).
    - ``render_mode=None``: ``"human"`` (a pygame window) or ``"rgb_array"``.
    - ``sitl_path=None``: the flyloop-sitl binary (see ``flyloop.find_sitl_binary``).
    - ``sitl_address=None``: ``"host:port"`` of a running SITL to use instead of starting one
      (parameters are then set over MAVLink as float32); ``vehicle=1``: its system id there.
    - ``timeout=5.0``: seconds to wait for any SITL reply before raising ``SitlError``.
    - ``backend="sitl"``: ``"native"`` runs the same core task in this process through the
      extension ``flyloop._native`` instead (no SITL, no sockets; same observations bit for
      bit, same rewards, flags and info); ``sitl_path`` and ``sitl_address`` are then refused.

    Out-of-range values are refused by the core's parameter table: ``SitlParameterError``
    (a ``ValueError``) naming the argument and its bound; wrong types raise ``TypeError``.

    ## Errors

    A SITL that exits, is killed or stays silent for ``timeout`` seconds raises
    ``flyloop.SitlError`` (exit code and last stderr lines in the message) — never a hang.
    ``close()`` stops the SITL; one forgotten is stopped when the env is garbage-collected
    or Python exits.

    ## Version history

    - v0: first version. Differs from the seed on purpose: correct rigid-body physics (body
      rates, rotor geometry), observations declared with bounds they respect, seeded
      reproducible resets, the pendulum torque off by default, the time limit as truncation.
    """

    SPEC = HOVER

    def _make_view(self, render_mode: str):
        from ..rendering import QuadrotorView

        return QuadrotorView(render_mode, fps=self.metadata["render_fps"])

    def _scene(self, obs, info, reward):
        from ..rendering import QuadScene

        obs = np.asarray(obs, dtype=float)
        at, values = observation_slices(self.core), parameter_values(self.core)

        def part(name, otherwise):
            # The rates interface observes neither attitude nor motors: drawn level, at 0.
            return obs[at[name]] if name in at else otherwise

        crashed, out = info.get("crashed"), info.get("out_of_bounds")
        return QuadScene(
            time_s=info["episode_time"],
            step=info["step_count"],
            position=info["position"],
            velocity=obs[at["velocity"]],
            quaternion=part("quaternion", (1.0, 0.0, 0.0, 0.0)),
            wind=part("wind", np.zeros(3)),
            motors=part("motor_states", np.zeros(self.core["rotors"])),
            target=info.get("target_position"),
            next_waypoint=info.get("next_waypoint_pos"),
            reward=reward,
            episode_return=self._episode_return,
            bounds_half_size=float(values["space_side_length"]) / 2.0,
            arm_length=float(values["arm_length"]),
            waypoints_reached=info.get("waypoints_reached"),
            status="crashed" if crashed else "out of bounds" if out else "",
            frame=self.core["frame"],
        )
