"""flyloop/Lander2D-v0 and -v1: land a 2D two-motor drone on a (possibly moving) platform.
v0 keeps the seed's reward, v1 pays for landing."""

from __future__ import annotations

from typing import Any

from ..tasks import LANDING, LANDING_V1, observation_slices, parameter_values
from .base import FlyloopEnv

# Endings other than landed and crashed, as the view's text panel names them.
OUTCOMES = (
    ("lost_control", "lost control"),
    ("out_of_bounds", "out of bounds"),
    ("battery_empty", "battery empty"),
    ("time_limit", "time limit reached"),
)
# The model's sizes the view draws.
WORLD = (
    "world_width world_height ground_height platform_width platform_height drone_width "
    "drone_height max_thrust initial_battery"
).split()


class Lander2DEnv(FlyloopEnv):
    """Land a 2D drone with two motors on a platform (seed 000's ``Drone2dEnv``, the
    reference environment described in docs/reference/lander2d.md).

    ``gymnasium.make("flyloop/Lander2D-v0")`` (after ``import flyloop``). The physics
    (rapier2d), observation, reward and outcome are computed by flyloop's Rust core inside
    the ``flyloop-sitl`` process this env starts, one MAVLink datagram per step.

    ## Frames and units

    A vertical plane: x to the right in (0, 50) m, y up in (0, 50) m, gravity 9.81 m/s² along
    −y, ground at y = 10 m. Angles counter-clockwise, wrapped to (−π, π]. The drone: 1.5 kg,
    1.0 m wide (frame box and two motor boxes, one rigid body). Platform 5 m × 0.5 m centred at
    x = 25 m, top at y = 10.5 m.

    ## Action space

    ``Box(-1, 1, (2,), float32)``: left and right motor; a maps to thrust T = (a + 1)/2 · 15 N,
    times (1 + seeded Gaussian noise of σ = ``thrust_noise_std``/15 N = 10 %), clipped to
    [0, 15] N, along the body's +y at x = ∓0.4 m: a stopped motor (a = −1) gives exactly zero
    thrust. Values outside [−1, 1] are clipped by the core; a non-finite value raises
    ``ValueError``.

    ## Observation space

    ``Box(low, high, (11,) or (12,), float32)``, each value clipped to [−1, 1] (battery and
    distance to [0, 1]):

    | index | value |
    |---|---|
    | 0, 1 | x/25 − 1, y/25 − 1 |
    | 2, 3 | vx/15, vy/15 (m/s) |
    | 4, 5 | angle/π, angular velocity/10 (rad/s) |
    | 6 | battery / 100 |
    | 7, 8 | err_x/25, err_y/25: drone → platform top centre (m) |
    | 9 | (atan2(err_y, err_x) − angle)/π: bearing of the platform from the body |
    | 10 | distance to the platform / 50 |
    | 11 | platform vx / platform_speed (only with ``moving_platform=True``) |

    ## Reward (the seed's, exactly)

    Per step on the observation values n: ``2·exp(−0.1·n10) − 0.1·(n2² + n3²) − 0.2·|n4| −
    0.1·|n5|``, +5 on a step touching the platform. The first terminal condition adds: landed
    +100 if calm (‖(n2, n3)‖ < 0.1 and |n5| < 0.1) else +20; crashed −50; lost control −50;
    battery empty −50; out of bounds −50; time limit −10.

    This reward does not teach landing: it pays ≈ 2 per step for being near the pad, ≈ 2,000
    over a 1,000-step episode, against +100 for a landing that ends the episode early. Hovering
    beside the pad until the time limit is its optimum, and PPO finds it (0 % landings).
    ``flyloop/Lander2D-v1`` (:class:`Lander2DLandingEnv`) is the same env with a reward under
    which landing pays; v0 stays for reproducing the seed's results.

    ## Starting state

    Spawn at (``spawn_x``, ``spawn_y``) = (25, 40) ± ``initial_pos_random_range_m`` in x and
    y (kept inside the world and above the platform), angle uniform in
    ±``initial_angle_random_range_rad``, at rest, battery full. Wind: a constant force of
    wind_speed · 0.5 · 1.0 m (2.5 N) in a direction uniform in [0, 2π) per episode (or
    ``wind_direction``). A moving platform starts in a random direction. All drawn from the
    episode's seed.

    ## Episode end

    Terminated when landed (first platform contact slower than ``max_safe_landing_speed``
    1.5 m/s and within ``max_safe_landing_angle`` 0.2 rad), crashed (ground contact or a hard
    platform contact), lost control (|angle| > ``max_allowed_tilt_angle_rad``, π/2), battery
    empty, or out of the world. Truncated at exactly ``max_steps`` steps.

    ## Info

    ``position`` (2, m), ``velocity`` (2, m/s), ``angle`` (rad), ``angular_velocity`` (rad/s),
    ``battery``, ``thrust`` (2, N), ``wind_force`` (2, N), ``platform_position`` (2, m: top
    centre), ``distance`` (m), ``landed``, ``crashed``, ``lost_control``, ``out_of_bounds``,
    ``battery_empty``, ``time_limit``, ``platform_contact``, ``touchdown_speed`` (m/s),
    ``step``. Values travel as float32.

    ## Arguments

    The physics runs on its own fixed grid, core parameter ``physics_step`` (default 0.02 s,
    one physics step per env step; set it through ``model_params``): rapier steps, thrust
    noise and battery drain once per grid step, so every ``dt`` that is a multiple of it gives
    the same bits at the shared times (``model_params={"physics_step": 0.005}`` with
    ``dt=0.01`` or ``0.02``); a ``dt`` that is not ends each step in a shortened physics step
    (docs/reference/lander2d.md).

    The task arguments (listed below with the core's defaults, units and descriptions) are the
    core's parameters under their own names, except the seed's ``use_wind`` (core
    ``wind_enabled``) and ``wind_direction`` (None = random per episode, else radians from +x
    toward +y). A spawn is kept inside the world and at least a drone width above the
    platform; ``initial_pos_random_range_m=0`` is a fixed start at (spawn_x, spawn_y). The
    env's own:

    - ``model_params=None``: other Lander2D parameters by core name (``drone_mass``,
      ``max_thrust``, ``initial_battery``, ``world_width``, ...; docs/parameters.md).
    - ``render_mode=None`` / ``"human"`` / ``"rgb_array"``; ``render_path=True``,
      ``render_shade=True``, ``shade_distance_m=2.0`` (the seed's drawing options).
    - ``sitl_path``, ``sitl_address``, ``vehicle``, ``timeout``, ``backend``: as
      ``QuadHoverEnv``.

    ## Errors

    As ``QuadHoverEnv``: ``SitlParameterError`` for refused arguments, ``SitlError`` for a
    SITL that exits or stays silent for ``timeout`` seconds.

    ## Version history

    - v0: first version. Differs from the seed on purpose: a rigid drone by construction, a
      pad landing no longer also counts as a ground crash, the time limit fires at exactly
      ``max_steps`` and is a truncation, wind can be switched off, seeded resets.
    - v0, physics fix (issue 13): the thrust noise scales with the commanded thrust (σ 10 % of
      it, the seed's 1.5 N at full thrust) instead of adding 1.5 N at every level. In the seed
      a stopped motor (a = −1) still pushed ≈ 0.6 N on average, up to ~4 N, and drained the
      battery; now it gives zero thrust and drains nothing. The reward *formula* is the
      seed's, bit for bit (same function of the same observation; a core test checks it on
      every step), but the dynamics it is computed on are the fixed ones, so returns of the
      same seeds and actions differ from before the fix. The id stays v0 because its contract
      — the seed's reward — is unchanged, and a physics bug is not behaviour worth keeping.
    """

    SPEC = LANDING

    def __init__(
        self,
        *,
        render_path: bool = True,
        render_shade: bool = True,
        shade_distance_m: float = 2.0,
        **arguments: Any,
    ) -> None:
        self._render_options = dict(
            show_path=bool(render_path),
            show_shades=bool(render_shade),
            shade_distance_m=float(shade_distance_m),
        )
        super().__init__(**arguments)

    def _make_view(self, render_mode: str):
        from ..rendering import LanderView

        return LanderView(render_mode, fps=self.metadata["render_fps"], **self._render_options)

    def _scene(self, obs, info, reward):
        from ..rendering import LanderScene

        p, at, step = parameter_values(self.core), observation_slices(self.core), int(info["step"])
        # A moving platform's velocity is observed as a fraction of platform_speed.
        moving = "platform_velocity" in at
        return LanderScene(
            time_s=step * self.dt,
            step=step,
            position=info["position"],
            velocity=info["velocity"],
            angle=float(info["angle"]),
            angular_velocity=float(info["angular_velocity"]),
            thrust=info["thrust"],
            battery=float(info["battery"]),
            platform_x=float(info["platform_position"][0]),
            platform_vx=float(obs[at["platform_velocity"]][0]) * float(p["platform_speed"])
            if moving
            else 0.0,
            wind_force=info["wind_force"],
            wind_speed=float(p["wind_speed"]) if p["wind_enabled"] else 0.0,
            landed=bool(info["landed"]),
            crashed=bool(info["crashed"]),
            outcome=next((text for key, text in OUTCOMES if info[key]), ""),
            max_steps=int(p["max_steps"]),
            reward=reward,
            episode_return=self._episode_return,
            spawn_center=(float(p["spawn_x"]), float(p["spawn_y"])),
            spawn_half_range=float(p["initial_pos_random_range_m"]),
            **{name: float(p[name]) for name in WORLD},
        )


class Lander2DLandingEnv(Lander2DEnv):
    """``flyloop/Lander2D-v1``: Lander2D with a reward that pays for landing.

    Everything — arguments, spaces, physics, starts, episode ends, info, rendering, both
    backends — is :class:`Lander2DEnv`'s (``flyloop/Lander2D-v0``); only the reward differs
    (core parameter ``reward_version`` = 1, core/src/tasks/landing_reward.rs).

    ## Reward

    Potential-based shaping (Ng, Harada & Russell 1999; as gymnasium's LunarLander) plus a
    control cost and terminal rewards::

        Φ(s) = −(4·d + 10·v_rel + 50·|angle| + 10·|ω|)
        r    = Φ(s′) − Φ(s) − 0.05·((a_left + 1)/2 + (a_right + 1)/2)/2 + terminal

    with d the distance (m) from the drone's centre to the platform's top centre, v_rel the
    speed (m/s) relative to the platform, angle (rad) wrapped, ω (rad/s). Terminal: landed
    +100; crashed, lost control, battery empty, out of the world −100 each; the time limit
    (truncation at ``max_steps``) −100 too: not landing is a failure.

    The shaping sums to Φ(end) − Φ(start) over an episode, so it cannot pay for hovering:
    from a spawn ≈ 30 m away, landing earns ≈ +200, hovering near the pad until the time limit
    ≈ −15, a crash ≈ −100 + what the approach earned. A core test checks with two scripted
    pilots over 40 seeds that every safe landing beats every hover by more than 100.

    Success is ``info["landed"]``. Scripted baseline: examples/lander_pilot.py.

    ## Version history

    - v1 (issue 13): the landing reward above; v0's physics (including v0's physics fix:
      thrust noise proportional to thrust, a stopped motor gives zero thrust and drains
      nothing).
    """

    SPEC = LANDING_V1
