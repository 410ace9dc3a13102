"""A Box whose sample() is cheap.

gymnasium's `Box.sample()` costs ~35 µs (it sorts every coordinate into bounded/unbounded
masks on each call), as much as half an env step here. Every flyloop action space is bounded
on all sides, so `FastBox.sample()` makes the one numpy call those masks boil down to
(uniform = low + (high − low) · random()): the same draws from the same generator, hence the
same samples for the same seed, in a few µs.
"""

from __future__ import annotations

import gymnasium as gym
import numpy as np


class FastBox(gym.spaces.Box):
    """gymnasium.spaces.Box, with a fast path for sampling a fully bounded float box."""

    def __init__(self, *args, **kwargs) -> None:
        super().__init__(*args, **kwargs)
        self._fast = self.dtype.kind == "f" and bool(self.is_bounded("both"))
        # Generator.uniform(low, high) is low + (high - low) · random(): the same draws.
        self._low64 = self.low.astype(np.float64)
        self._span64 = self.high.astype(np.float64) - self._low64

    def sample(self, mask: None = None, probability: None = None) -> np.ndarray:
        if not self._fast or mask is not None or probability is not None:
            return super().sample(mask, probability)
        return (self._low64 + self._span64 * self.np_random.random(self.shape)).astype(self.dtype)
