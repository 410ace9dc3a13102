"""A separation term for the learner's reward on the multi-agent tasks (fast_ppo.py's
Config.separation_penalty): a dense warning before a collision.

The env's own reward only knows a collision when hulls touch (−collision_penalty, and in Swap
the episode ends for all four), so until then "fly straight at the target" earns the most and
PPO meets the collision as a cliff. The term charges each agent, per step and per observed
neighbour closer than `radius`, penalty · (1 − d / radius): the potential-field style
separation penalty of multi-robot collision avoidance (Long et al. 2018, "Towards optimally
decentralized multi-robot collision avoidance via deep reinforcement learning", reward term
for d < 3 radii; Reynolds 1987's separation rule). Only the learner sees it: the returns
and successes fast_ppo.py reports are the env's.
"""

from __future__ import annotations

import numpy as np

# Values per neighbour slot: relative position (3), relative velocity (3), present (1).
NEIGHBOUR_VALUES = 7


class SeparationShaping:
    """penalty · Σ over present neighbour slots of max(0, 1 − d / radius), per row of raw
    (unnormalised) observations; `layout` is the env's observation layout."""

    def __init__(self, layout, penalty: float, radius: float) -> None:
        if radius <= 0.0:
            raise ValueError(f"separation_radius must be > 0 m, got {radius}")
        at = 0
        for name, size, *_ in layout:
            if name == "neighbours":
                break
            at += size
        else:
            raise ValueError("separation_penalty needs an env that observes its neighbours")
        slots = np.arange(at, at + size, NEIGHBOUR_VALUES)
        self._position = slots[:, None] + np.arange(3)  # slot × xyz
        self._present = slots + 6
        self.penalty, self.radius = penalty, radius

    def __call__(self, obs: np.ndarray) -> np.ndarray:
        """The term (≤ 0) per row."""
        d = np.linalg.norm(obs[:, self._position], axis=-1)
        close = np.clip(1.0 - d / self.radius, 0.0, None) * obs[:, self._present]
        return -self.penalty * close.sum(-1)
