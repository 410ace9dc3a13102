"""The backend seam: where the core's task runs, chosen once by `make_backend` and used alike
by the single env (row 0) and the vector env (every row).

A backend runs `num_envs` instances of one task built from a config (core name -> value):

- `reset_one(seed)` -> (obs, info) and `step_one(action)` -> (obs, reward, terminated,
  truncated, info): the single env's path (instance 0, info as a dict);
- `run(actions, resetting, seeds, out)`: every instance at once, rows in `resetting` reset
  with their `seeds` (their action ignored, reward and flags 0), the rest stepped; results go
  into the arrays of `out` (an `Outputs`);
- `close()` (idempotent), `sitl_process` (None in-process);
- native only: `reset_rows(resetting, seeds, out)`, the rows in `resetting` reset alone
  (stable-baselines3's autoreset within the step, flyloop.sb3).

`NativeBackend` runs the core in this process (flyloop._native.Batch); `SitlBackend`
(flyloop.sitl_backend) runs it in a flyloop-sitl process, one datagram per exchange.
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from . import _native
from .tasks import TaskSpec

BACKENDS = ("sitl", "native")


def check_backend(backend: Any, sitl_path: Any, sitl_address: Any = None) -> str:
    """`backend` checked; the SITL's own arguments are refused with the native backend."""
    if backend not in BACKENDS:
        raise ValueError(f"backend must be 'sitl' or 'native', got {backend!r}")
    if backend == "native":
        for name, value in (("sitl_path", sitl_path), ("sitl_address", sitl_address)):
            if value is not None:
                raise ValueError(f"{name} applies to backend='sitl' only, got {value!r}")
    return backend


def default_threads() -> int:
    """The CPUs this process may run on."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # not Linux
        return os.cpu_count() or 1


@dataclass
class Outputs:
    """The arrays `run` writes, allocated once by the vector env."""

    obs: np.ndarray  # (N, n_obs) float32
    info: np.ndarray  # (N, info values) float32, the task frame's info layout
    rewards: np.ndarray  # (N,) float64
    terminated: np.ndarray  # (N,) bool
    truncated: np.ndarray  # (N,) bool

    @classmethod
    def zeros(cls, num_envs: int, n_obs: int, n_info: int) -> Outputs:
        n = num_envs
        return cls(
            np.zeros((n, n_obs), np.float32),
            np.zeros((n, n_info), np.float32),
            np.zeros(n, np.float64),
            np.zeros(n, bool),
            np.zeros(n, bool),
        )


class NativeBackend:
    """The core in this process: `num_envs` instances stepped over `num_threads` threads."""

    name = "native"
    sitl_process = None

    def __init__(self, spec: TaskSpec, config: Mapping[str, Any], num_envs: int, num_threads):
        self._batch = _native.Batch(spec.name, config, num_envs, num_threads)
        self.num_threads = self._batch.num_threads

    def _open(self):
        if self._batch is None or self._batch.closed:
            raise RuntimeError("this env is closed; make a new one to go on")
        return self._batch

    def reset_one(self, seed: int):
        return self._open().reset_one(seed)

    def step_one(self, action: np.ndarray):
        # The core refuses NaN / ±inf with ValueError and changes nothing, like the SITL.
        return self._open().step_one(action)

    def run(self, actions: np.ndarray, resetting: np.ndarray, seeds: np.ndarray, out: Outputs):
        self._open().step(
            actions, resetting, seeds, out.obs, out.info, out.rewards, out.terminated,
            out.truncated,
        )  # fmt: skip

    def reset_rows(self, resetting: np.ndarray, seeds: np.ndarray, out: Outputs):
        """Only the rows in `resetting` start a new episode (the others are untouched)."""
        self._open().reset_rows(resetting, seeds, out.obs, out.info)
        out.rewards[resetting] = 0.0
        out.terminated[resetting] = False
        out.truncated[resetting] = False

    def close(self) -> None:
        batch, self._batch = self._batch, None
        if batch is not None:
            batch.close()


def make_backend(
    backend: Any,
    spec: TaskSpec,
    config: Mapping[str, Any],
    core: Mapping[str, Any],
    num_envs: int = 1,
    *,
    sitl_path: Any = None,
    sitl_address: Any = None,
    vehicle: int = 1,
    timeout: float = 5.0,
    num_threads: int = 1,
):
    """The backend named `backend` ("sitl" or "native") running `num_envs` instances of
    `spec` with `config` (`core`: its `TaskSpec.describe`)."""
    if check_backend(backend, sitl_path, sitl_address) == "native":
        return NativeBackend(spec, config, num_envs, num_threads)
    from .sitl_backend import SitlBackend

    return SitlBackend(
        spec, config, core, num_envs,
        sitl_path=sitl_path, sitl_address=sitl_address, vehicle=vehicle, timeout=timeout,
    )  # fmt: skip
