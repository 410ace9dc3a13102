"""What the adapter knows about each task: the one table that maps env arguments (the seeds'
names) onto the core's parameters. Everything else — parameter names, MAVLink param_ids,
defaults, ranges, units and descriptions, the info layout, the control period and the
observation and action bounds — is read from the core through the extension
(`flyloop._native.describe`), for both backends.

Nothing here computes a reward, a termination or an observation value: those come from the
core, in-process (backend="native") or through the SITL's task frame (backend="sitl").
"""

from __future__ import annotations

import difflib
import functools
import math
import numbers
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from . import _native
from .errors import SitlParameterError

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


def _action_interface(arg: str, v: Any) -> tuple[bool]:
    if v not in ("motors", "rates"):
        raise ValueError(f"{arg} must be 'motors' or 'rates', got {v!r}")
    return (v == "rates",)


NOISE_KEYS = ("position", "velocity", "attitude", "rates")


def _observation_noise(arg: str, v: Any) -> tuple[float, ...]:
    # None: no noise; a mapping: standard deviations by quantity (missing ones 0).
    if v is None:
        return (0.0,) * len(NOISE_KEYS)
    if not isinstance(v, Mapping):
        raise TypeError(f"{arg} must be None or a dict over {NOISE_KEYS}, got {v!r}")
    unknown = set(v) - set(NOISE_KEYS)
    if unknown:
        raise ValueError(f"{arg}: unknown keys {sorted(unknown)}; known: {list(NOISE_KEYS)}")
    return tuple(as_float(f"{arg}[{k!r}]", v.get(k, 0.0)) for k in NOISE_KEYS)


# A config key "randomize.<name>" holds the range (low, high) of core parameter <name>: the
# native extension reads it so, and to_toml writes it into the SITL's [randomize] table.
RANGE_PREFIX = "randomize."


def randomize_entries(arg: str, v: Any) -> dict[str, tuple[float, float]]:
    """`randomize={name: (low, high)}` as config entries; None or {} = off."""
    if v is None:
        return {}
    if not isinstance(v, Mapping):
        raise TypeError(f"{arg} must be None or a dict {{parameter: (low, high)}}, got {v!r}")
    out = {}
    for name, pair in v.items():
        if not isinstance(name, str):
            raise TypeError(f"{arg}: parameter names are strings, got {name!r}")
        out[RANGE_PREFIX + name] = as_interval(f"{arg}[{name!r}]", pair)
    return out


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
    _arg(
        "action_interface",
        "rates_action",
        _action_interface,
        "'motors' (4 motor commands) or 'rates' (thrust + body rates through PX4's rate loop)",
    ),
    _arg(
        "action_latency",
        "action_latency",
        _one(as_float),
        "rates interface: delay from an action to the rate loop, s",
    ),
    _arg(
        "observation_noise",
        tuple("obs_noise_" + k for k in NOISE_KEYS),
        _observation_noise,
        "rates interface: observation noise std by quantity (position m, velocity m/s, "
        "attitude rad, rates rad/s)",
    ),
    _arg(
        "randomize",
        (),
        randomize_entries,
        "domain randomisation: {core parameter: (low, high)} drawn per episode from its seed",
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
        "half side of the spawn square around (spawn_x, spawn_y), m; 0 = fixed start",
    ),
    _arg("spawn_x", "spawn_x", _one(as_float), "centre of the spawn square, x, m"),
    _arg("spawn_y", "spawn_y", _one(as_float), "centre of the spawn square, y, m"),
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


# ---- the core's description of a task ----

REAL, INTEGER, FLAG, VECTOR = "real", "integer", "flag", "vector"


@functools.cache
def _default_description(task: str) -> dict[str, Any]:
    return _native.describe(task)


@dataclass(frozen=True)
class TaskSpec:
    """A task as the adapter sees it: its env arguments; the rest comes from the core."""

    name: str  # the core's task name: the SITL's --task and the frame's DEBUG_FLOAT_ARRAY name
    env_id: str
    arguments: tuple[Argument, ...]
    # Core parameters the env id fixes, not the caller: (name, value) pairs, e.g.
    # Lander2D-v1's reward_version. resolve_config adds them to every config.
    fixed: tuple[tuple[str, float], ...] = ()

    @property
    def parameters(self) -> tuple[dict[str, Any], ...]:
        """The core's parameter table of the task: dicts with name, id (MAVLink param_id),
        group, kind, unit, min, max, default, description."""
        return tuple(_default_description(self.name)["parameters"])

    @property
    def param_ids(self) -> dict[str, str]:
        """Core name -> MAVLink param_id, for every parameter of the task."""
        return {p["name"]: p["id"] for p in self.parameters}

    @property
    def model_params(self) -> dict[str, str]:
        """Core name -> param_id of the model's parameters (what `model_params` may set)."""
        return {p["name"]: p["id"] for p in self.parameters if p["group"].startswith("model")}

    @property
    def defaults(self) -> dict[str, float]:
        """Core name -> default value."""
        return {p["name"]: p["default"] for p in self.parameters}

    @property
    def info(self) -> tuple[tuple[str, str, int], ...]:
        """The info layout: (name, kind, number of values) in the task frame's order."""
        return tuple(tuple(e) for e in _default_description(self.name)["info"])

    def info_size(self) -> int:
        return sum(n for _, _, n in self.info)

    def describe(self, config: Mapping[str, Any]) -> dict[str, Any]:
        """The core's description of the task built from `config` (core name -> value):
        observation and action bounds, dt, info layout, parameters with their `value`.
        A value the core refuses raises SitlParameterError naming the env argument."""
        values = {
            k: (tuple(map(float, v)) if k.startswith(RANGE_PREFIX) else float(v))
            for k, v in config.items()
        }
        try:
            return _native.describe(self.name, values)
        except ValueError as exc:
            raise parameter_error(self, str(exc)) from None


HOVER = TaskSpec("hover", "flyloop/QuadHover-v0", tuple(FLIGHT_ARGUMENTS))
WAYPOINTS = TaskSpec(
    "waypoints", "flyloop/QuadWaypoints-v0", tuple(FLIGHT_ARGUMENTS + WAYPOINT_ARGUMENTS)
)
# The seed's reward (reward_version 0) and the landing reward (1): one task, two env ids.
LANDING = TaskSpec(
    "landing", "flyloop/Lander2D-v0", tuple(LANDING_ARGUMENTS), (("reward_version", 0),)
)
LANDING_V1 = TaskSpec(
    "landing", "flyloop/Lander2D-v1", tuple(LANDING_ARGUMENTS), (("reward_version", 1),)
)
TASKS = {t.name: t for t in (HOVER, WAYPOINTS, LANDING)}


def parameter_values(description: Mapping[str, Any]) -> dict[str, float]:
    """Core name -> value in effect, from a `TaskSpec.describe` result."""
    return {p["name"]: p["value"] for p in description["parameters"]}


def resolve_config(
    spec: TaskSpec, arguments: Mapping[str, Any], model_params: Mapping[str, Any] | None
) -> dict[str, bool | int | float]:
    """The core parameters (name -> value) for the env arguments and extra model parameters.
    Types are checked here; ranges and relations are checked by the core when the SITL
    starts (errors name the env argument, see `argument_for`)."""
    config: dict[str, bool | int | float] = dict(spec.fixed)
    by_name = {a.name: a for a in spec.arguments}
    for name, value in arguments.items():
        arg = by_name[name]
        if name == "randomize":
            config.update(randomize_entries(name, value))
            continue
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
    if "randomisation" in lead:
        where = "randomize"
    return SitlParameterError(f"{spec.env_id}: {where} refused by the core: {lead}")


def to_toml(config: Mapping[str, Any]) -> str:
    """The SITL's --config file: a flat TOML table, and the randomisation ranges in its
    [randomize] table."""
    lines = []
    ranges = [
        f"{k[len(RANGE_PREFIX) :]} = [{float(lo)!r}, {float(hi)!r}]"
        for k, (lo, hi) in ((k, v) for k, v in config.items() if k.startswith(RANGE_PREFIX))
    ]
    for name, v in config.items():
        if name.startswith(RANGE_PREFIX):
            continue
        if isinstance(v, bool):
            text = "true" if v else "false"
        elif isinstance(v, int):
            text = str(v)
        else:
            text = repr(float(v))
        lines.append(f"{name} = {text}")
    if ranges:
        lines += ["", "[randomize]", *ranges]
    return "\n".join(lines) + "\n"
