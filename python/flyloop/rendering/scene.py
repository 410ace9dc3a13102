"""What the views draw: plain per-step data, built from what an env already receives.

Each field says its unit and frame. Vectors are validated on construction (shape and
finiteness) and stored as float64 numpy arrays, so a bad value fails here with the field's
name instead of deep inside a drawing call.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np


def _vector(name: str, value: Any, size: int) -> np.ndarray:
    try:
        arr = np.array(value, dtype=float).reshape(-1)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"{name} must be {size} numbers, got {value!r}") from exc
    if arr.shape != (size,):
        raise ValueError(f"{name} must be {size} numbers, got {arr.size}: {value!r}")
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{name} must be finite, got {arr.tolist()}")
    return arr


def _number(name: str, value: Any, minimum: float | None = None) -> float:
    try:
        x = float(value)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"{name} must be a number, got {value!r}") from exc
    if not math.isfinite(x):
        raise ValueError(f"{name} must be finite, got {x}")
    if minimum is not None and x < minimum:
        raise ValueError(f"{name} must be >= {minimum}, got {x}")
    return x


def _optional_number(name: str, value: Any) -> float | None:
    return None if value is None else _number(name, value)


def _extras(value: Mapping[str, Any] | tuple) -> tuple[tuple[str, str], ...]:
    items = value.items() if isinstance(value, Mapping) else value
    return tuple((str(k), str(v)) for k, v in items)


def _set(obj: object, name: str, value: Any) -> None:
    object.__setattr__(obj, name, value)


@dataclass(frozen=True, eq=False)
class QuadScene:
    """One frame of the quadrotor (tasks Hover and Waypoints).

    Frames as the core: world ENU (x east, y north, z up), body FLU, quaternion [w, x, y, z]
    rotating body to world; motors in PX4 quad-X order (0 front-right, 1 rear-left,
    2 front-left, 3 rear-right).
    """

    time_s: float  # episode time, s
    step: int  # steps since reset
    position: np.ndarray  # (3,) m, world ENU
    velocity: np.ndarray  # (3,) m/s, world ENU
    quaternion: np.ndarray  # (4,) [w, x, y, z], body FLU -> world ENU; normalised here
    motors: np.ndarray = field(default_factory=lambda: np.zeros(4))  # (4,) states, [0, 1]
    body_rates: np.ndarray = field(default_factory=lambda: np.zeros(3))  # (3,) rad/s, body FLU
    wind: np.ndarray = field(default_factory=lambda: np.zeros(3))  # (3,) m/s, world ENU
    target: np.ndarray | None = None  # (3,) m, world ENU: the current target / waypoint
    next_waypoint: np.ndarray | None = None  # (3,) m, the waypoint after the target
    reward: float | None = None  # reward of the last step
    episode_return: float | None = None  # sum of rewards since reset
    bounds_half_size: float = 1.5  # m: targets live in x, y in [-h, h], z in [0, 2h]
    arm_length: float = 0.1  # m, centre to rotor
    waypoints_reached: int | None = None  # Waypoints task only
    status: str = ""  # e.g. "crashed", "out of bounds"; empty while flying
    extras: tuple[tuple[str, str], ...] = ()  # more (label, text) lines for the info panel

    def __post_init__(self) -> None:
        _set(self, "time_s", _number("time_s", self.time_s))
        _set(self, "step", int(_number("step", self.step, minimum=0)))
        _set(self, "position", _vector("position", self.position, 3))
        _set(self, "velocity", _vector("velocity", self.velocity, 3))
        q = _vector("quaternion", self.quaternion, 4)
        norm = float(np.linalg.norm(q))
        if norm < 1e-9:
            raise ValueError(f"quaternion must not be zero, got {q.tolist()}")
        _set(self, "quaternion", q / norm)
        # Lagged motor states may overshoot by rounding; the bars show [0, 1].
        _set(self, "motors", np.clip(_vector("motors", self.motors, 4), 0.0, 1.0))
        _set(self, "body_rates", _vector("body_rates", self.body_rates, 3))
        _set(self, "wind", _vector("wind", self.wind, 3))
        for name in ("target", "next_waypoint"):
            value = getattr(self, name)
            if value is not None:
                _set(self, name, _vector(name, value, 3))
        _set(self, "reward", _optional_number("reward", self.reward))
        _set(self, "episode_return", _optional_number("episode_return", self.episode_return))
        _set(self, "bounds_half_size", _number("bounds_half_size", self.bounds_half_size, 1e-3))
        _set(self, "arm_length", _number("arm_length", self.arm_length, 1e-4))
        if self.waypoints_reached is not None:
            reached = int(_number("waypoints_reached", self.waypoints_reached, 0))
            _set(self, "waypoints_reached", reached)
        _set(self, "extras", _extras(self.extras))


@dataclass(frozen=True, eq=False)
class LanderScene:
    """One frame of the Lander2D (task Landing). World metres, x right, y up, angles CCW.

    Defaults are the core's Lander2dParams / LandingParams defaults; an env passes its own.
    """

    time_s: float  # episode time, s
    step: int  # steps since reset
    position: np.ndarray  # (2,) m, drone centre
    velocity: np.ndarray  # (2,) m/s
    angle: float  # rad, counter-clockwise
    angular_velocity: float  # rad/s, counter-clockwise
    thrust: np.ndarray  # (2,) N, (left, right) motor thrust of the last step
    battery: float  # charge left, units
    platform_x: float  # m, platform centre x
    wind_force: np.ndarray = field(default_factory=lambda: np.zeros(2))  # (2,) N on the drone
    wind_speed: float = 0.0  # m/s, for the label (the force is what acts)
    platform_vx: float = 0.0  # m/s
    landed: bool = False
    crashed: bool = False
    outcome: str = ""  # another ending: "lost control", "out of bounds", "battery empty", ...
    max_steps: int | None = None
    reward: float | None = None
    episode_return: float | None = None
    max_thrust: float = 15.0  # N per motor
    initial_battery: float = 100.0  # units
    world_width: float = 50.0  # m: the world is x in (0, W)
    world_height: float = 50.0  # m: y in (0, H)
    ground_height: float = 10.0  # m
    platform_width: float = 5.0  # m
    platform_height: float = 0.5  # m above the ground
    drone_width: float = 1.0  # m, tip to tip
    drone_height: float = 0.2  # m, side of each square motor
    spawn_center: np.ndarray = field(default_factory=lambda: np.array([25.0, 40.0]))  # (2,) m
    spawn_half_range: float = 5.0  # m, half side of the spawn square; 0 = fixed start

    def __post_init__(self) -> None:
        _set(self, "time_s", _number("time_s", self.time_s))
        _set(self, "step", int(_number("step", self.step, minimum=0)))
        _set(self, "position", _vector("position", self.position, 2))
        _set(self, "velocity", _vector("velocity", self.velocity, 2))
        _set(self, "thrust", _vector("thrust", self.thrust, 2))
        _set(self, "wind_force", _vector("wind_force", self.wind_force, 2))
        _set(self, "spawn_center", _vector("spawn_center", self.spawn_center, 2))
        for name in ("angle", "angular_velocity", "platform_x", "platform_vx"):
            _set(self, name, _number(name, getattr(self, name)))
        for name in ("battery", "wind_speed", "spawn_half_range", "ground_height"):
            _set(self, name, _number(name, getattr(self, name), minimum=0.0))
        for name in (
            "max_thrust",
            "initial_battery",
            "world_width",
            "world_height",
            "platform_width",
            "platform_height",
            "drone_width",
            "drone_height",
        ):
            _set(self, name, _number(name, getattr(self, name), minimum=1e-6))
        if self.max_steps is not None:
            _set(self, "max_steps", int(_number("max_steps", self.max_steps, minimum=1)))
        _set(self, "reward", _optional_number("reward", self.reward))
        _set(self, "episode_return", _optional_number("episode_return", self.episode_return))
        _set(self, "landed", bool(self.landed))
        _set(self, "crashed", bool(self.crashed))

    @property
    def platform_top(self) -> tuple[float, float]:
        """Top centre of the platform, m: where the sensor line points."""
        return self.platform_x, self.ground_height + self.platform_height

    @property
    def distance_to_platform(self) -> float:
        """Distance from the drone centre to the platform's top centre, m."""
        tx, ty = self.platform_top
        return math.hypot(tx - self.position[0], ty - self.position[1])
