"""FastBox: gymnasium's Box with a cheap sample() that draws exactly what Box draws."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest

from flyloop.spaces import FastBox


@pytest.mark.parametrize(
    "low, high",
    [(0.0, 1.0), (-1.0, 1.0), (np.array([0, -1, -1, -1], np.float32), 1.0), (-5.5, 1e3)],
)
def test_samples_equal_box_samples_for_the_same_seed(low, high):
    plain, fast = gym.spaces.Box(low, high, (4,), np.float32), FastBox(low, high, (4,), np.float32)
    plain.seed(7)
    fast.seed(7)
    for _ in range(2000):
        want, got = plain.sample(), fast.sample()
        np.testing.assert_array_equal(got, want)
        assert got.dtype == np.float32 and fast.contains(got)
    assert fast == plain


def test_unbounded_and_masked_sampling_fall_back_to_box():
    half_open = FastBox(np.float32(0.0), np.inf, (3,), np.float32)
    half_open.seed(1)
    assert (half_open.sample() >= 0).all()
    with pytest.raises(gym.error.Error):
        FastBox(0.0, 1.0, (2,), np.float32).sample(mask=np.ones(2))
