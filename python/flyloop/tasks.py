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
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from . import _native
from .errors import SitlParameterError
from .faults import FAULTS_KEY, mentions_fault, plan_text

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
    """One env argument: its name, the core parameters it sets and how (`convert`: the
    Python value -> one value per core parameter), its default (`default_of`: the core's
    defaults -> the Python default), its type and what it means."""

    name: str
    core: tuple[str, ...]
    convert: Callable[[str, Any], tuple]
    default_of: Callable[[Mapping[str, float]], Any]
    annotation: Any
    doc: str

    def default(self, core_defaults: Mapping[str, float]) -> Any:
        return self.default_of(core_defaults)


def _one(kind: Callable[[str, Any], Any]) -> Callable[[str, Any], tuple]:
    return lambda arg, v: (kind(arg, v),)


# A core value kind -> the env argument's check and Python type.
_KINDS = {"integer": (as_int, int), "real": (as_float, float), "boolean": (as_bool, bool)}


def own_argument(row: Mapping[str, Any]) -> Argument:
    """The env argument that is core parameter `row` under its own name: type, default and
    description are the core's."""
    name = row["name"]
    check, python_type = _KINDS[row["kind"]]
    unit = f" ({row['unit']})" if row["unit"] else ""
    return Argument(
        name,
        (name,),
        _one(check),
        lambda d: python_type(d[name]),
        python_type,
        row["description"] + unit,
    )


def _renamed(name, core, convert, default_of, annotation, doc) -> Argument:
    core = (core,) if isinstance(core, str) else core
    return Argument(name, core, convert, default_of, annotation, doc)


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


# The config key naming the flight tasks' rotor table (a shipped frame of the core's): the
# native extension reads it so, and to_toml writes it as the SITL's [frame] table.
FRAME_KEY = "frame"
DEFAULT_FRAME = "quad_x"


def _frame_names() -> tuple[str, ...]:
    return tuple(_native.frames())


def frame_entry(arg: str, v: Any) -> dict[str, str]:
    """`frame="hexa_x"` as a config entry; an unknown name raises ValueError listing the
    core's shipped frames."""
    names = _frame_names()
    if not isinstance(v, str):
        raise TypeError(f"{arg} must be a frame name, one of {list(names)}, got {v!r}")
    if v not in names:
        raise ValueError(f"{arg} must be one of {list(names)}, got {v!r}")
    return {FRAME_KEY: v}


# The seeds' arguments whose name or form differs from the core's parameters, mapped by
# hand; every other argument is a core parameter under its own name (`own_argument`).
_USE_WIND = _renamed(
    "use_wind", "wind_enabled", _one(as_bool), lambda d: bool(d["wind_enabled"]), bool,
    "the wind blows",
)  # fmt: skip
FLIGHT_RENAMED = (
    _renamed(
        "target_change_interval", "target_change_interval", _optional_interval,
        lambda d: int(d["target_change_interval"]) or None, int | None,
        "steps between new targets; None = never",
    ),
    _renamed(
        "wind_strength_range", ("wind_speed_min", "wind_speed_max"), as_interval,
        lambda d: (float(d["wind_speed_min"]), float(d["wind_speed_max"])),
        tuple[float, float], "(min, max) of the per-episode mean wind speed (m/s)",
    ),
    _USE_WIND,
    _renamed(
        "action_interface", "rates_action", _action_interface,
        lambda d: "rates" if d["rates_action"] else "motors", str,
        "'motors' (4 motor commands) or 'rates' (thrust + body rates through PX4's rate loop)",
    ),
    _renamed(
        "observation_noise", tuple("obs_noise_" + k for k in NOISE_KEYS), _observation_noise,
        lambda d: {k: d["obs_noise_" + k] for k in NOISE_KEYS if d["obs_noise_" + k]} or None,
        Mapping[str, float] | None,
        "rates interface: observation noise std by quantity (position m, velocity m/s, "
        "attitude rad, rates rad/s); None = none",
    ),
    _renamed(
        "randomize", (), randomize_entries, lambda d: None,
        Mapping[str, tuple[float, float]] | None,
        "domain randomisation: {core parameter: (low, high)} drawn per episode from its seed",
    ),
    _renamed(
        "faults", (), lambda a, v: (), lambda d: None, Sequence[Mapping[str, Any]] | None,
        "faults (docs/faults.md): dicts with kind, motor (1 = first, 0 = all) or sensor, "
        "parameters, one trigger (at, above_height, after_takeoff, at_waypoint), duration",
    ),
    _renamed(
        "fault_randomization", (), lambda a, v: (), lambda d: None,
        Mapping[str, Any] | Sequence[Mapping[str, Any]] | None,
        "faults drawn per episode from its seed: kinds, probability, at, motor, sensors, "
        "duration and (low, high) ranges of the kinds' parameters",
    ),
    _renamed(
        "frame", (), frame_entry, lambda d: DEFAULT_FRAME, str,
        "the multirotor's rotor table: 'quad_x', 'quad_plus', 'hexa_x' or 'octo_x' (the "
        "motor interface takes one command per rotor)",
    ),
)  # fmt: skip
LANDING_RENAMED = (
    _USE_WIND,
    _renamed(
        "wind_direction", ("wind_direction_random", "wind_direction"), _wind_direction,
        lambda d: None if d["wind_direction_random"] else float(d["wind_direction"]),
        float | None, "None = uniform per episode, else fixed, rad from +x toward +y",
    ),
)  # fmt: skip
# Lander2D's model parameters that the seed made env arguments (the rest: model_params).
LANDING_MODEL_ARGUMENTS = (
    "dt",
    "moving_platform",
    "platform_speed",
    "wind_speed",
    "platform_random_start_x",
    "thrust_noise_std",
    "max_safe_landing_speed",
    "max_safe_landing_angle",
)


# ---- the core's description of a task ----

REAL, INTEGER, FLAG, VECTOR = "real", "integer", "flag", "vector"


@functools.cache
def _default_description(task: str) -> dict[str, Any]:
    return _native.describe(task)


@dataclass(frozen=True)
class TaskSpec:
    """A task as the adapter sees it: which core parameters are env arguments; everything
    else comes from the core."""

    name: str  # the core's task name: the SITL's --task and the frame's DEBUG_FLOAT_ARRAY name
    env_id: str
    # Env arguments mapped by hand (the seeds' names and forms).
    renamed: tuple[Argument, ...]
    # Model parameters that are env arguments too (the task's own parameters all are).
    model_arguments: tuple[str, ...] = ()
    # Core parameters the env id fixes, not the caller: (name, value) pairs, e.g.
    # Lander2D-v1's reward_version. resolve_config adds them to every config.
    fixed: tuple[tuple[str, float], ...] = ()

    @functools.cached_property
    def arguments(self) -> tuple[Argument, ...]:
        """The env's task arguments in the core table's order: each task parameter and each
        of `model_arguments` under its own name, except those a `renamed` argument sets
        (placed at its first core parameter) and the `fixed` ones."""
        first = {a.core[0]: a for a in self.renamed if a.core}
        covered = {c for a in self.renamed for c in a.core} | {n for n, _ in self.fixed}
        out = []
        # The task's own parameters first, then the model's (a stable sort keeps the table's
        # order within each).
        rows = sorted(self.parameters, key=lambda r: r["group"].startswith("model"))
        for row in rows:
            name = row["name"]
            if name in first:
                out.append(first[name])
            elif name not in covered and (
                not row["group"].startswith("model") or name in self.model_arguments
            ):
                out.append(own_argument(row))
        return (*out, *(a for a in self.renamed if not a.core))

    def argument_defaults(self) -> dict[str, Any]:
        """Env argument -> its default, from the core's defaults."""
        defaults = self.defaults
        return {a.name: a.default(defaults) for a in self.arguments}

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
            k: (
                v
                if k in (FAULTS_KEY, FRAME_KEY)
                else tuple(map(float, v))
                if k.startswith(RANGE_PREFIX)
                else float(v)
            )
            for k, v in config.items()
        }
        try:
            return _native.describe(self.name, values)
        except ValueError as exc:
            raise parameter_error(self, str(exc)) from None


HOVER = TaskSpec("hover", "flyloop/QuadHover-v0", FLIGHT_RENAMED)
WAYPOINTS = TaskSpec("waypoints", "flyloop/QuadWaypoints-v0", FLIGHT_RENAMED)
# The seed's reward (reward_version 0) and the landing reward (1): one task, two env ids.
LANDING = TaskSpec(
    "landing", "flyloop/Lander2D-v0", LANDING_RENAMED, LANDING_MODEL_ARGUMENTS,
    (("reward_version", 0),),
)  # fmt: skip
LANDING_V1 = TaskSpec(
    "landing", "flyloop/Lander2D-v1", LANDING_RENAMED, LANDING_MODEL_ARGUMENTS,
    (("reward_version", 1),),
)  # fmt: skip
TASKS = {t.name: t for t in (HOVER, WAYPOINTS, LANDING)}


def task_arguments(spec: TaskSpec, arguments: Mapping[str, Any], who: str) -> dict[str, Any]:
    """Every task argument of `spec`: its default from the core unless `arguments` gives it.
    A name that is not a task argument raises TypeError naming `who`."""
    defaults = spec.argument_defaults()
    unknown = set(arguments) - set(defaults)
    if unknown:
        raise TypeError(
            f"{who} got unexpected arguments {sorted(unknown)}; task arguments: {sorted(defaults)}"
        )
    return {**defaults, **arguments}


def observation_slices(description: Mapping[str, Any]) -> dict[str, slice]:
    """Group name -> its slice of the observation, from a `describe` result's layout."""
    out, at = {}, 0
    for name, count in description["observation"]:
        out[name] = slice(at, at + count)
        at += count
    return out


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
        if name in ("faults", "fault_randomization"):
            continue
        if name == FRAME_KEY:
            # The quad X is the core's default: its config stays as it was before frames.
            entry = frame_entry(name, value)
            if value != DEFAULT_FRAME:
                config.update(entry)
            continue
        for core, v in zip(arg.core, arg.convert(name, value), strict=True):
            config[core] = v
    text = plan_text(arguments.get("faults"), arguments.get("fault_randomization"))
    if text is not None:
        config[FAULTS_KEY] = text
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
    elif not names and mentions_fault(lead):
        where = "faults / fault_randomization"
    return SitlParameterError(f"{spec.env_id}: {where} refused by the core: {lead}")


def to_toml(config: Mapping[str, Any]) -> str:
    """The SITL's --config file: a flat TOML table, the randomisation ranges in its
    [randomize] table and the frame in its [frame] table."""
    lines = []
    ranges = [
        f"{k[len(RANGE_PREFIX) :]} = [{float(lo)!r}, {float(hi)!r}]"
        for k, (lo, hi) in ((k, v) for k, v in config.items() if k.startswith(RANGE_PREFIX))
    ]
    for name, v in config.items():
        if name.startswith(RANGE_PREFIX) or name in (FAULTS_KEY, FRAME_KEY):
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
    if FAULTS_KEY in config:
        lines += ["", config[FAULTS_KEY]]
    if FRAME_KEY in config:
        lines += ["", f"[{FRAME_KEY}]", f'name = "{config[FRAME_KEY]}"']
    return "\n".join(lines) + "\n"
