"""Faults from Python: the env arguments `faults=[...]` and `fault_randomization={...}` written
as the TOML tables the core reads (`[[faults]]`, `[[fault_randomization]]`: the SITL's config
file holds the same text, the native backend hands it to the core), and the info's
`faults` list built from the core's per-slot info values. The catalogue (kinds, parameters,
units, bounds) is the core's: `catalogue()`; docs/faults.md describes it."""

from __future__ import annotations

import functools
import json
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from . import _native

# The config key that holds the fault plan's TOML text.
FAULTS_KEY = "faults"
INFO_KEYS = ("fault_kind", "fault_target", "fault_time", "fault_active")


@functools.cache
def catalogue() -> tuple[tuple[dict[str, Any], ...], tuple[str, ...]]:
    """The core's fault kinds (dicts: name, target, effect, fields) and sensor names."""
    kinds, sensors = _native.fault_catalogue()
    return tuple(kinds), tuple(sensors)


def _toml_value(where: str, v: Any) -> str:
    if isinstance(v, (bool, np.bool_)):
        return "true" if v else "false"
    if isinstance(v, (int, np.integer)):
        return str(int(v))
    if isinstance(v, (float, np.floating)):
        x = float(v)
        if not np.isfinite(x):
            raise ValueError(f"{where} must be a finite number, got {x}")
        return repr(x)
    if isinstance(v, str):
        return json.dumps(v)  # a TOML basic string
    if isinstance(v, Sequence):
        return "[" + ", ".join(_toml_value(f"{where}[{i}]", x) for i, x in enumerate(v)) + "]"
    raise TypeError(f"{where} must be a number, a string or a list of them, got {v!r}")


def _tables(arg: str, header: str, entries: Any) -> list[str]:
    if entries is None:
        return []
    if isinstance(entries, Mapping):
        entries = [entries]
    if not isinstance(entries, Sequence) or isinstance(entries, str):
        raise TypeError(f"{arg} must be None, a dict or a list of dicts, got {entries!r}")
    lines = []
    for i, entry in enumerate(entries):
        if not isinstance(entry, Mapping):
            raise TypeError(f"{arg}[{i}] must be a dict, got {entry!r}")
        lines.append(f"[[{header}]]")
        for key, value in entry.items():
            if not isinstance(key, str):
                raise TypeError(f"{arg}[{i}]: keys are strings, got {key!r}")
            lines.append(f"{key} = {_toml_value(f'{arg}[{i}][{key!r}]', value)}")
    return lines


def plan_text(faults: Any, fault_randomization: Any) -> str | None:
    """The TOML text of `faults` (dicts: kind, motor or sensor, parameters, one trigger,
    duration) and `fault_randomization` (dicts: kinds, probability, at, motor, sensors,
    duration and [low, high] parameter ranges); None when both are empty. The core checks
    every value and names the one it refuses."""
    lines = _tables("faults", "faults", faults)
    lines += _tables("fault_randomization", "fault_randomization", fault_randomization)
    _refuse_link(faults)
    return "\n".join(lines) + "\n" if lines else None


def _refuse_link(faults: Any) -> None:
    """Refuses `link_loss` / `link_delay`: they act on flyloop-sitl's own links (its lockstep
    link, PX4's, ArduPilot's), which the in-process backend does not have, so the gym would
    fly different bits by backend."""
    entries = [faults] if isinstance(faults, Mapping) else list(faults or [])
    for i, entry in enumerate(entries):
        kind = entry.get("kind") if isinstance(entry, Mapping) else None
        if isinstance(kind, str) and kind.startswith("link_"):
            raise ValueError(
                f"faults[{i}]: kind {kind!r} acts on a link of flyloop-sitl (its --config "
                "[[faults]] in task, PX4 or ArduPilot mode); the gym has no link for it"
            )


def _label(kind: float, target: float) -> str:
    kinds, sensors = catalogue()
    row = kinds[int(kind)]
    if row["target"] == "motor":
        return f"{row['name']}:{int(target)}"
    if row["target"] == "sensor":
        return f"{row['name']}:{sensors[int(target)]}"
    return row["name"]


def active_faults(info: Mapping[str, Any]) -> list[dict[str, Any]]:
    """The faults in effect, from one env's info: dicts with `fault` (kind, with the motor
    or sensor: `motor_effectiveness:2`, `sensor_off:gps`) and `time` (s, when it fired)."""
    if "fault_kind" not in info:
        return []
    kind, target, time, active = (np.asarray(info[k]) for k in INFO_KEYS)
    return [
        {"fault": _label(kind[i], target[i]), "time": float(time[i])}
        for i in range(len(kind))
        if active[i] != 0.0 and kind[i] >= 0.0
    ]


def add_fault_list(info: dict[str, Any]) -> dict[str, Any]:
    """Adds `info["faults"]` (see `active_faults`) when the task has faults."""
    if "fault_kind" in info:
        info["faults"] = active_faults(info)
    return info


TRIGGER_KEYS = ("at", "above_height", "after_takeoff", "at_waypoint", "duration")


def mentions_fault(message: str) -> bool:
    """Whether a core error is about the fault plan (it names a fault key or the plan)."""
    kinds, _ = catalogue()
    keys = {f["name"] for k in kinds for f in k["fields"]}
    keys |= {"motor", "sensor", "kind", "kinds", "probability", *TRIGGER_KEYS}
    return "fault" in message or any(f"`{k}`" in message for k in keys)
