"""What the vector env needs beside the backend: the task arguments with the single env's
defaults, and the batched info dict built from a (N, values) float32 array in the task
frame's info layout."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from .faults import INFO_KEYS, active_faults, add_fault_list
from .tasks import FLAG, INTEGER, REAL, TaskSpec, task_arguments

# Single-env arguments a vector env accepts and ignores (they only change drawing).
RENDER_ARGUMENTS = {"render_path", "render_shade", "shade_distance_m"}


def vector_task_arguments(spec: TaskSpec, arguments: Mapping[str, Any]) -> dict[str, Any]:
    """The task arguments of a vector env, as the single env's (the core's defaults, then
    `arguments`), so both make the same episodes."""
    given = {k: v for k, v in arguments.items() if k not in RENDER_ARGUMENTS}
    return task_arguments(spec, given, f"the {spec.env_id} vector env")


class InfoColumns:
    """Builds the batched info dict from the info values of N envs (one row each)."""

    def __init__(self, layout: Sequence[Sequence[Any]], start: int, num_envs: int) -> None:
        self.fields = []
        at = start
        for name, kind, count in layout:
            self.fields.append((name, kind, at, at + count))
            at += count
        # Every env has every key every step: one read-only all-True mask per key, handed out
        # each step instead of a fresh copy.
        self.masks = {f"_{name}": np.ones(num_envs, bool) for name, _, _ in layout}
        for mask in self.masks.values():
            mask.flags.writeable = False

    def infos(self, values: np.ndarray) -> dict[str, Any]:
        """Every key as an array over the envs: reals float64, flags bool, integers int64,
        vectors (N, k) float64; plus gymnasium's `_key` masks (all True)."""
        infos: dict[str, Any] = {}
        for name, kind, a, b in self.fields:
            if kind == REAL:
                infos[name] = values[:, a].astype(np.float64)
            elif kind == FLAG:
                infos[name] = values[:, a] != 0.0
            elif kind == INTEGER:
                infos[name] = values[:, a].astype(np.int64)
            else:
                infos[name] = values[:, a:b].astype(np.float64)
        infos.update(self.masks)
        if "fault_kind" in infos:
            # Per env, the faults in effect (a list of dicts, see flyloop.faults).
            per_env = np.empty(len(values), dtype=object)
            per_env[:] = [
                active_faults({k: infos[k][i] for k in INFO_KEYS}) for i in range(len(values))
            ]
            infos["faults"] = per_env
            infos["_faults"] = np.ones(len(values), bool)
        return infos

    def dicts(self, values: np.ndarray) -> list[dict[str, Any]]:
        """One info dict per row, as the single env's info: reals float, integers int, flags
        bool, vectors float64 arrays (stable-baselines3's per-env infos)."""
        columns: list[list[Any]] = []
        every = values.T.tolist()  # one pass from float32 to Python floats
        for _, kind, a, b in self.fields:
            if kind == REAL:
                columns.append(every[a])
            elif kind == FLAG:
                columns.append([v != 0.0 for v in every[a]])
            elif kind == INTEGER:
                columns.append([int(v) for v in every[a]])
            else:
                columns.append(list(values[:, a:b].astype(np.float64)))
        names = [name for name, _, _, _ in self.fields]
        if not names:
            return [{} for _ in range(len(values))]
        out = [dict(zip(names, row, strict=True)) for row in zip(*columns, strict=True)]
        return [add_fault_list(d) for d in out]
