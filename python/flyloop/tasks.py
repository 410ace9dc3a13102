"""What the adapter knows about each task: the one table that maps env arguments (the seeds'
names) onto the core's parameters, the info layout of the task frame, and the observation
and action bounds the core declares.

Nothing here computes a reward, a termination or an observation value: those come from the
core through the SITL's task frame. The bounds below mirror the core's `observation_bounds`
(core/src/tasks/flight.rs `base_bounds`/`wind_bound`, waypoints.rs, landing.rs) because the
SITL does not send them; tests check every observation stays inside them.
"""

from __future__ import annotations

import difflib
import math
import numbers
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from .errors import SitlParameterError

# ---- the core's parameter names and their MAVLink param_ids (`flyloop-sitl --list-params`) ----

QUADROTOR_PARAMS: dict[str, str] = {
    "mass": "mass",
    "arm_length": "arm_length",
    "inertia_xx": "inertia_xx",
    "inertia_yy": "inertia_yy",
    "inertia_zz": "inertia_zz",
    "gravity": "gravity",
    "thrust_coefficient": "thrust_coef",
    "motor_time_constant": "motor_time_const",
    "yaw_torque_coefficient": "yaw_torque_coef",
    "air_density": "air_density",
    "drag_area": "drag_area",
    "angular_damping_linear": "ang_damp_lin",
    "angular_damping_quadratic": "ang_damp_quad",
    "pendulum_coefficient": "pend_coef",
    "max_substep": "max_substep",
    "ground_enabled": "ground_enabled",
    "wind_enabled": "wind_enabled",
    "wind_speed_min": "wind_speed_min",
    "wind_speed_max": "wind_speed_max",
    "turbulence_theta": "turbulence_theta",
    "turbulence_sigma": "turbulence_sigma",
    "turbulence_vertical_ratio": "turb_vert_ratio",
}
FLIGHT_PARAMS: dict[str, str] = {
    "dt": "dt",
    "max_steps": "max_steps",
    "target_change_interval": "tgt_chg_intv",
    "space_side_length": "space_side_len",
    "start_height": "start_height",
    "start_attitude_range": "start_att_rng",
    "min_target_distance": "min_tgt_dist",
    "velocity_scale": "velocity_scale",
    "enable_crash_detection": "en_crash_det",
    "enable_out_of_bounds_detection": "en_oob_det",
    "crash_z_vel_threshold": "crash_z_vel_thr",
    "crash_tilt_threshold": "crash_tilt_thr",
}
WAYPOINT_PARAMS: dict[str, str] = {
    "max_num_waypoints": "max_num_wps",
    "waypoint_reach_threshold_m": "wp_reach_thr_m",
    "checkpoint_bonus": "checkpoint_bonus",
    "bonus_decay_rate_per_sec": "bonus_dcy_rt_p_s",
}
LANDER_PARAMS: dict[str, str] = {
    "gravity": "gravity",
    "world_width": "world_width",
    "world_height": "world_height",
    "ground_height": "ground_height",
    "ground_friction": "ground_friction",
    "drone_mass": "drone_mass",
    "drone_width": "drone_width",
    "drone_height": "drone_height",
    "drone_friction": "drone_friction",
    "max_thrust": "max_thrust",
    "thrust_noise_std": "thrust_noise_std",
    "initial_battery": "initial_battery",
    "battery_consumption_rate": "batt_cons_rt",
    "wind_enabled": "wind_enabled",
    "wind_speed": "wind_speed",
    "wind_force_coefficient": "wind_force_coef",
    "wind_direction_random": "wind_dir_rnd",
    "wind_direction": "wind_direction",
    "platform_width": "platform_width",
    "platform_height": "platform_height",
    "platform_friction": "plat_fric",
    "platform_start_x": "platform_start_x",
    "platform_random_start_x": "plat_rnd_start_x",
    "moving_platform": "moving_platform",
    "platform_speed": "platform_speed",
    "max_safe_landing_speed": "max_safe_lnd_spd",
    "max_safe_landing_angle": "max_safe_lnd_ang",
    "dt": "dt",
    "physics_substeps": "physics_substeps",
}
LANDING_PARAMS: dict[str, str] = {
    "max_steps": "max_steps",
    "initial_pos_random_range_m": "ini_pos_rnd_rng",
    "spawn_x": "spawn_x",
    "spawn_y": "spawn_y",
    "initial_angle_random_range_rad": "ini_ang_rnd_rng",
    "max_allowed_tilt_angle_rad": "max_alw_tilt_ang",
}

# Core defaults the adapter needs to declare bounds and draw scenes (docs/parameters.md).
CORE_DEFAULTS: dict[str, float] = {
    "wind_enabled": True,
    "wind_speed_max": 5.0,
    "turbulence_theta": 0.5,
    "turbulence_sigma": 1.0,
    "arm_length": 0.1,
    "space_side_length": 3.0,
    "max_steps": 1000,
    "dt": 0.01,
    "moving_platform": False,
}


# ---- argument conversion: seed names and Python values -> core names and numbers ----


def _is_bool(v: Any) -> bool:
    return isinstance(v, (bool, np.bool_))


def as_bool(arg: str, v: Any) -> bool:
    if not _is_bool(v):
        raise TypeError(f"{arg} must be True or False, got {v!r}")
    return bool(v)


def as_int(arg: str, v: Any) -> int:
    if _is_bool(v) or not isinstance(v, numbers.Integral):
        if isinstance(v, numbers.Real) and not _is_bool(v) and float(v).is_integer():
            return int(v)
        raise TypeError(f"{arg} must be an integer, got {v!r}")
    return int(v)


def as_float(arg: str, v: Any) -> float:
    if _is_bool(v) or not isinstance(v, numbers.Real):
        raise TypeError(f"{arg} must be a number, got {v!r}")
    x = float(v)
    if not math.isfinite(x):
        raise ValueError(f"{arg} must be a finite number, got {v!r}")
    return x


def as_interval(arg: str, v: Any) -> tuple[float, float]:
    try:
        lo, hi = v
    except (TypeError, ValueError):
        raise TypeError(f"{arg} must be a pair (min, max), got {v!r}") from None
    lo, hi = as_float(f"{arg}[0]", lo), as_float(f"{arg}[1]", hi)
    if lo > hi:
        raise ValueError(f"{arg} = {v!r}: min must not exceed max")
    return lo, hi


@dataclass(frozen=True)
class Argument:
    """One env argument: its name, the core parameters it sets, and how."""

    name: str
    core: tuple[str, ...]
    convert: Callable[[str, Any], tuple]
    doc: str


def _one(kind: Callable[[str, Any], Any]) -> Callable[[str, Any], tuple]:
    return lambda arg, v: (kind(arg, v),)


def _optional_interval(arg: str, v: Any) -> tuple[int]:
    return (0,) if v is None else (as_int(arg, v),)


def _wind_direction(arg: str, v: Any) -> tuple[bool, float]:
    # None: drawn per episode; a number: fixed (radians from +x toward +y).
    return (True, 0.0) if v is None else (False, as_float(arg, v))


def _arg(name: str, core: str | tuple[str, ...], convert, doc: str) -> Argument:
    core = (core,) if isinstance(core, str) else core
    return Argument(name, core, convert, doc)


FLIGHT_ARGUMENTS: list[Argument] = [
    _arg("max_steps", "max_steps", _one(as_int), "steps until the episode is truncated"),
    _arg("dt", "dt", _one(as_float), "control period, s"),
    _arg(
        "target_change_interval",
        "target_change_interval",
        _optional_interval,
        "steps between new targets; None = never",
    ),
    _arg(
        "wind_strength_range",
        ("wind_speed_min", "wind_speed_max"),
        as_interval,
        "(min, max) of the per-episode mean wind speed, m/s",
    ),
    _arg("use_wind", "wind_enabled", _one(as_bool), "wind (mean + turbulence) blows"),
    _arg(
        "enable_crash_detection",
        "enable_crash_detection",
        _one(as_bool),
        "terminate on a crash",
    ),
    _arg(
        "enable_out_of_bounds_detection",
        "enable_out_of_bounds_detection",
        _one(as_bool),
        "terminate when too far from the target",
    ),
    _arg(
        "crash_z_vel_threshold",
        "crash_z_vel_threshold",
        _one(as_float),
        "crash below this vertical velocity, m/s",
    ),
    _arg(
        "crash_tilt_threshold",
        "crash_tilt_threshold",
        _one(as_float),
        "crash beyond this |roll| or |pitch|, degrees",
    ),
    _arg(
        "space_side_length",
        "space_side_length",
        _one(as_float),
        "side of the target cube, m",
    ),
    _arg("start_height", "start_height", _one(as_float), "start height, m"),
    _arg(
        "start_attitude_range",
        "start_attitude_range",
        _one(as_float),
        "start roll/pitch/yaw uniform in +-this, rad",
    ),
    _arg(
        "min_target_distance",
        "min_target_distance",
        _one(as_float),
        "a new target is at least this far away, m",
    ),
    _arg(
        "velocity_scale",
        "velocity_scale",
        _one(as_float),
        "speed scale of the velocity reward, m/s",
    ),
]
WAYPOINT_ARGUMENTS: list[Argument] = [
    _arg("max_num_waypoints", "max_num_waypoints", _one(as_int), "waypoints per episode"),
    _arg(
        "waypoint_reach_threshold_m",
        "waypoint_reach_threshold_m",
        _one(as_float),
        "a waypoint is reached within this distance, m",
    ),
    _arg("checkpoint_bonus", "checkpoint_bonus", _one(as_float), "reward for a waypoint"),
    _arg(
        "bonus_decay_rate_per_sec",
        "bonus_decay_rate_per_sec",
        _one(as_float),
        "bonus lost per second since the last waypoint",
    ),
]
LANDING_ARGUMENTS: list[Argument] = [
    _arg("max_steps", "max_steps", _one(as_int), "steps until the episode is truncated"),
    _arg("dt", "dt", _one(as_float), "control period, s"),
    _arg("moving_platform", "moving_platform", _one(as_bool), "the platform moves along x"),
    _arg("platform_speed", "platform_speed", _one(as_float), "platform speed, m/s"),
    _arg(
        "initial_pos_random_range_m",
        "initial_pos_random_range_m",
        _one(as_float),
        "half side of the spawn square around (25, 40), m; 0 = fixed start",
    ),
    _arg(
        "initial_angle_random_range_rad",
        "initial_angle_random_range_rad",
        _one(as_float),
        "spawn angle uniform in +-this, rad",
    ),
    _arg("use_wind", "wind_enabled", _one(as_bool), "the episode's constant wind blows"),
    _arg("wind_speed", "wind_speed", _one(as_float), "wind speed, m/s"),
    _arg(
        "wind_direction",
        ("wind_direction_random", "wind_direction"),
        _wind_direction,
        "None = uniform per episode, else fixed, rad from +x toward +y",
    ),
    _arg(
        "platform_random_start_x",
        "platform_random_start_x",
        _one(as_bool),
        "platform start x drawn inside its travel range",
    ),
    _arg("thrust_noise_std", "thrust_noise_std", _one(as_float), "thrust noise per motor, N"),
    _arg(
        "max_safe_landing_speed",
        "max_safe_landing_speed",
        _one(as_float),
        "largest touchdown speed of a landing, m/s",
    ),
    _arg(
        "max_safe_landing_angle",
        "max_safe_landing_angle",
        _one(as_float),
        "largest |angle| of a landing, rad",
    ),
    _arg(
        "max_allowed_tilt_angle_rad",
        "max_allowed_tilt_angle_rad",
        _one(as_float),
        "|angle| beyond which control is lost, rad",
    ),
]


# ---- info layout of the task frame (docs/protocol.md, `flyloop-sitl --describe-frame`) ----

REAL, INTEGER, FLAG, VECTOR = "real", "integer", "flag", "vector"

FLIGHT_INFO: list[tuple[str, str, int]] = [
    ("distance_to_target", REAL, 1),
    ("position", VECTOR, 3),
    ("target_position", VECTOR, 3),
    ("step_count", INTEGER, 1),
    ("episode_time", REAL, 1),
    ("distance_progress", REAL, 1),
    ("crashed", FLAG, 1),
    ("out_of_bounds", FLAG, 1),
]
WAYPOINT_INFO = FLIGHT_INFO + [
    ("waypoints_reached", INTEGER, 1),
    ("current_waypoint_pos", VECTOR, 3),
    ("next_waypoint_pos", VECTOR, 3),
    ("steps_since_checkpoint", REAL, 1),
]
LANDING_INFO: list[tuple[str, str, int]] = [
    ("position", VECTOR, 2),
    ("velocity", VECTOR, 2),
    ("angle", REAL, 1),
    ("angular_velocity", REAL, 1),
    ("battery", REAL, 1),
    ("thrust", VECTOR, 2),
    ("wind_force", VECTOR, 2),
    ("platform_position", VECTOR, 2),
    ("distance", REAL, 1),
    ("landed", FLAG, 1),
    ("crashed", FLAG, 1),
    ("lost_control", FLAG, 1),
    ("out_of_bounds", FLAG, 1),
    ("battery_empty", FLAG, 1),
    ("time_limit", FLAG, 1),
    ("platform_contact", FLAG, 1),
    ("touchdown_speed", REAL, 1),
    ("step", INTEGER, 1),
]


@dataclass(frozen=True)
class TaskSpec:
    """A task as the adapter sees it."""

    name: str  # the SITL's --task and the frame's DEBUG_FLOAT_ARRAY name
    env_id: str
    arguments: tuple[Argument, ...]
    model_params: Mapping[str, str]  # core name -> param_id of the model's set
    task_params: Mapping[str, str]  # core name -> param_id of the task's sets
    info: tuple[tuple[str, str, int], ...]
    action_low: float
    action_high: float
    action_size: int

    @property
    def param_ids(self) -> dict[str, str]:
        return {**self.model_params, **self.task_params}

    def info_size(self) -> int:
        return sum(n for _, _, n in self.info)


HOVER = TaskSpec(
    "hover",
    "flyloop/QuadHover-v0",
    tuple(FLIGHT_ARGUMENTS),
    QUADROTOR_PARAMS,
    FLIGHT_PARAMS,
    tuple(FLIGHT_INFO),
    0.0,
    1.0,
    4,
)
WAYPOINTS = TaskSpec(
    "waypoints",
    "flyloop/QuadWaypoints-v0",
    tuple(FLIGHT_ARGUMENTS + WAYPOINT_ARGUMENTS),
    QUADROTOR_PARAMS,
    {**FLIGHT_PARAMS, **WAYPOINT_PARAMS},
    tuple(WAYPOINT_INFO),
    0.0,
    1.0,
    4,
)
LANDING = TaskSpec(
    "landing",
    "flyloop/Lander2D-v0",
    tuple(LANDING_ARGUMENTS),
    {k: v for k, v in LANDER_PARAMS.items()},
    LANDING_PARAMS,
    tuple(LANDING_INFO),
    -1.0,
    1.0,
    2,
)
TASKS = {t.name: t for t in (HOVER, WAYPOINTS, LANDING)}


def resolve_config(
    spec: TaskSpec, arguments: Mapping[str, Any], model_params: Mapping[str, Any] | None
) -> dict[str, bool | int | float]:
    """The core parameters (name -> value) for the env arguments and extra model parameters.
    Types are checked here; ranges and relations are checked by the core when the SITL
    starts (errors name the env argument, see `argument_for`)."""
    config: dict[str, bool | int | float] = {}
    by_name = {a.name: a for a in spec.arguments}
    for name, value in arguments.items():
        arg = by_name[name]
        for core, v in zip(arg.core, arg.convert(name, value), strict=True):
            config[core] = v
    extra = dict(model_params or {})
    for name, value in extra.items():
        if name not in spec.model_params:
            close = difflib.get_close_matches(str(name), list(spec.model_params), n=1)
            hint = f" (did you mean {close[0]!r}?)" if close else ""
            raise ValueError(
                f"model_params: {name!r} is not a parameter of the {spec.name} model{hint}; "
                f"known: {', '.join(sorted(spec.model_params))}"
            )
        if name in config:
            owner = argument_for(spec, name)
            raise ValueError(
                f"model_params: {name!r} is already set by the argument {owner!r}; set it there"
            )
        if isinstance(value, (bool, np.bool_)):
            config[name] = bool(value)
        else:
            config[name] = as_float(f"model_params[{name!r}]", value)
    return config


def argument_for(spec: TaskSpec, core_name: str) -> str:
    """The env argument that sets core parameter `core_name` (else model_params[...])."""
    for a in spec.arguments:
        if core_name in a.core:
            if len(a.core) > 1:
                return f"{a.name} (core parameter {core_name})"
            return a.name
    return f"model_params[{core_name!r}]"


def parameter_error(spec: TaskSpec, message: str) -> SitlParameterError:
    """A core parameter error as an error about the env argument it came from."""
    names = [n for n in spec.param_ids if f"`{n}`" in message]
    lead = message
    for prefix in ("flyloop-sitl: error: ",):
        if prefix in lead:
            lead = lead.split(prefix, 1)[1]
    if ": parameter" in lead and lead.startswith("config file"):
        lead = lead.split(": ", 1)[1]
    where = ", ".join(argument_for(spec, n) for n in names) or "an argument"
    return SitlParameterError(f"{spec.env_id}: {where} refused by the core: {lead}")


def to_toml(config: Mapping[str, bool | int | float]) -> str:
    """A flat TOML table (the SITL's --config file)."""
    lines = []
    for name, v in config.items():
        if isinstance(v, bool):
            text = "true" if v else "false"
        elif isinstance(v, int):
            text = str(v)
        else:
            text = repr(float(v))
        lines.append(f"{name} = {text}")
    return "\n".join(lines) + "\n"


# ---- bounds the core declares (see the module docstring) ----


def _value(config: Mapping[str, Any], name: str) -> Any:
    return config.get(name, CORE_DEFAULTS[name])


def wind_bound(config: Mapping[str, Any]) -> float:
    """core::tasks::flight::wind_bound."""
    if not _value(config, "wind_enabled"):
        return 1.0
    theta = max(float(_value(config, "turbulence_theta")), 0.05)
    stationary = float(_value(config, "turbulence_sigma")) / math.sqrt(2.0 * theta)
    return max(float(_value(config, "wind_speed_max")) + 5.0 * stationary, 1.0)


def observation_bounds(spec: TaskSpec, config: Mapping[str, Any]) -> tuple[np.ndarray, np.ndarray]:
    """Per-value inclusive bounds of the observation (float32), as the core declares them."""
    if spec is LANDING:
        n = 12 if _value(config, "moving_platform") else 11
        low = np.full(n, -1.0, np.float32)
        low[[6, 10]] = 0.0
        return low, np.ones(n, np.float32)
    side = float(_value(config, "space_side_length"))
    position = math.sqrt(3.0) * side * (2.0 if spec is WAYPOINTS else 1.0)
    wind = wind_bound(config)
    groups = [
        (3, position),
        (3, 40.0),
        (3, 50.0),
        (4, 1.0),
        (3, 10.0),
        (3, 100.0),
        (3, 1.0),
        (3, wind),
    ]
    low = [-b for n, b in groups for _ in range(n)] + [0.0] * 8
    high = [b for n, b in groups for _ in range(n)] + [1.0] * 8
    if spec is WAYPOINTS:
        max_time = float(_value(config, "max_steps")) * float(_value(config, "dt"))
        low += [-position] * 3 + [0.0]
        high += [position] * 3 + [max_time]
    return np.array(low, np.float64).astype(np.float32), np.array(high, np.float64).astype(
        np.float32
    )
