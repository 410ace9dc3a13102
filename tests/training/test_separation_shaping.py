"""examples/train/separation_shaping.py: the learner's separation term on real Swap-v0
observations — zero for agents far apart, penalty · (1 − d / radius) per neighbour closer
than the radius, nothing for an absent neighbour slot."""

from __future__ import annotations

import flyloop
import numpy as np
import pytest
from separation_shaping import SeparationShaping


def swap_env(**kwargs):
    return flyloop.MultiAgentVectorEnv("flyloop/Swap-v0", num_worlds=1, **kwargs)


def test_agents_on_the_start_circle_are_outside_the_radius():
    envs = swap_env()
    obs, _ = envs.reset(seed=7)
    # Neighbours 2.83 m (adjacent) and 4 m (opposite) away on the 2 m circle.
    assert np.all(SeparationShaping(envs.observation_layout, 0.5, 0.8)(obs) == 0.0)
    # With a 3 m radius only the two adjacent ones count: 0.5 · 2 · (1 − 2√2 / 3) each.
    term = SeparationShaping(envs.observation_layout, 0.5, 3.0)(obs)
    expected = -0.5 * 2 * (1 - 2 * np.sqrt(2) / 3)
    np.testing.assert_allclose(term, expected, atol=0.02)  # the starts' jitter: ±0.1 m


def test_one_neighbour_halfway_into_the_radius_costs_half_the_penalty():
    envs = swap_env()
    shaping = SeparationShaping(envs.observation_layout, 0.5, 0.8)
    obs = np.zeros((2, envs.single_observation_space.shape[0]), np.float32)
    start = obs.shape[1] - 21  # three neighbour slots of 7 values
    obs[0, start : start + 7] = [0.0, 0.4, 0.0, 0.0, 0.0, 0.0, 1.0]  # 0.4 m away, present
    obs[1, start : start + 7] = [0.0, 0.4, 0.0, 0.0, 0.0, 0.0, 0.0]  # the same, absent
    np.testing.assert_allclose(shaping(obs), [-0.25, 0.0])


def test_bad_settings_name_the_setting():
    layout = swap_env().observation_layout
    with pytest.raises(ValueError, match="separation_radius must be > 0"):
        SeparationShaping(layout, 0.5, 0.0)
    with pytest.raises(ValueError, match="observes its neighbours"):
        SeparationShaping([("target_offset", 3)], 0.5, 1.0)
