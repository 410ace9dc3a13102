"""Action wrappers of seed 001, with the fixes noted in docs/reference/quadrotor.md.

Both wrap QuadHover or QuadWaypoints (4 motor commands in [0, 1]) and clip their own action
into their action space before using it.
"""

from __future__ import annotations

from typing import Any

import gymnasium as gym
import numpy as np

from .spaces import FastBox

# Observation values 29..32 hold the motor commands in effect (QuadHoverEnv's docs).
_COMMANDS = slice(29, 33)


def _check_quadrotor(env: gym.Env, wrapper: str) -> None:
    space = env.action_space
    ok = (
        isinstance(space, gym.spaces.Box)
        and space.shape == (4,)
        and np.all(space.low == 0.0)
        and np.all(space.high == 1.0)
    )
    if not ok:
        raise TypeError(
            f"{wrapper} wraps a quadrotor env with 4 motor commands in [0, 1] "
            f"(flyloop/QuadHover-v0, flyloop/QuadWaypoints-v0); got action space {space}"
        )


class ThrustChangeController(gym.ActionWrapper):
    """Actions are motor command *rates*: ``command ← clip(command + dt · rate · action, 0, 1)``.

    Action space ``Box(-1, 1, (4,), float32)``; actions outside are clipped. With the default
    ``rate=1.0`` a motor goes from 0 to full in one second, as in the seed. ``dt`` is the
    env's control period. At reset the command starts from the one the core reports in the
    observation (values 29–32: the hover state at the start of an episode).
    """

    def __init__(self, env: gym.Env, rate: float = 1.0) -> None:
        _check_quadrotor(env, "ThrustChangeController")
        super().__init__(env)
        if not (isinstance(rate, (int, float)) and rate > 0 and np.isfinite(rate)):
            raise ValueError(f"rate must be a finite number > 0 (per second), got {rate!r}")
        self.rate = float(rate)
        self.dt = float(env.unwrapped.dt)
        self.action_space = FastBox(-1.0, 1.0, (4,), np.float32)
        self.command = np.zeros(4, np.float32)

    def reset(self, *, seed: int | None = None, options: dict[str, Any] | None = None):
        obs, info = self.env.reset(seed=seed, options=options)
        self.command = np.asarray(obs[_COMMANDS], np.float32).copy()
        return obs, info

    def action(self, action):
        a = np.clip(np.asarray(action, np.float32), -1.0, 1.0)
        step = np.float32(self.dt * self.rate)
        self.command = np.clip(self.command + step * a, 0.0, 1.0).astype(np.float32)
        return self.command.copy()


class MotionPrimitiveActionWrapper(gym.ActionWrapper):
    """Actions are motion primitives ``[hover, roll, pitch, yaw]``, mixed per motor with the
    seed's mixer and clipped to [0, 1]:

        m0 = h + s·(r + p + y)   front-right (CCW)
        m1 = h + s·(−r − p + y)  rear-left   (CCW)
        m2 = h + s·(−r + p − y)  front-left  (CW)
        m3 = h + s·(r − p − y)   rear-right  (CW)

    Action space: hover in [0, 1], roll/pitch/yaw in [−1, 1] (the seed's were in [0, 1], so it
    could not command a negative moment), clipped into the space; ``scale`` s (default 0.5)
    scales the moments. On the PX4 quad-X of the core (body FLU) the signs mean:

    - roll > 0 raises the right-hand motors: the vehicle rolls left (body rate x < 0) and
      drifts toward +y (its left);
    - pitch > 0 raises the front motors: the nose pitches up (body rate y < 0 in FLU) and
      the vehicle drifts backward (−x);
    - yaw > 0 speeds up the CCW rotors: their reaction turns the vehicle clockwise seen from
      above, nose to the right (body rate z < 0).
    """

    MIX = np.array(
        [
            [1.0, 1.0, 1.0, 1.0],
            [1.0, -1.0, -1.0, 1.0],
            [1.0, -1.0, 1.0, -1.0],
            [1.0, 1.0, -1.0, -1.0],
        ],
        np.float32,
    )

    def __init__(self, env: gym.Env, scale: float = 0.5) -> None:
        _check_quadrotor(env, "MotionPrimitiveActionWrapper")
        super().__init__(env)
        if not (isinstance(scale, (int, float)) and 0 < scale <= 1):
            raise ValueError(f"scale must be in (0, 1], got {scale!r}")
        self.scale = float(scale)
        self.action_space = FastBox(
            np.array([0.0, -1.0, -1.0, -1.0], np.float32),
            np.array([1.0, 1.0, 1.0, 1.0], np.float32),
            dtype=np.float32,
        )

    def action(self, action):
        a = np.clip(np.asarray(action, np.float32), self.action_space.low, self.action_space.high)
        scaled = a * np.array([1.0, self.scale, self.scale, self.scale], np.float32)
        return np.clip(self.MIX @ scaled, 0.0, 1.0).astype(np.float32)
