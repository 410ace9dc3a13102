"""flyloop.rllib's MultiAgentEnv: the ParallelEnv's results unchanged, "__all__" set on the
step the last agent leaves (whichever way each left), and RLlib's env_config keys ignored."""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("ray.rllib")

import flyloop  # noqa: E402
from flyloop.rllib import multi_agent_env  # noqa: E402


def test_same_episode_as_the_parallel_env_and_all_set_when_the_last_agent_leaves():
    config = {"env_id": "flyloop/Swap-v0", "num_agents": 3, "max_steps": 40}
    env = multi_agent_env({**config, "worker_index": 1, "num_workers": 2})
    par = flyloop.parallel_env(config.pop("env_id"), **config)
    obs, _ = env.reset(seed=7)
    ref_obs, _ = par.reset(seed=7)
    assert list(obs) == ["drone_0", "drone_1", "drone_2"]
    for agent in obs:
        np.testing.assert_array_equal(obs[agent], ref_obs[agent])
        assert env.observation_spaces[agent] == par.observation_space(agent)
    rng = np.random.default_rng(0)
    over = False
    for _ in range(40):
        actions = {a: rng.uniform(0.3, 0.7, 4).astype(np.float32) for a in env.agents}
        obs, rewards, terms, truncs, _ = env.step(actions)
        ref = par.step(actions)
        assert rewards == ref[1]
        for agent in obs:
            np.testing.assert_array_equal(obs[agent], ref[0][agent])
        over = terms.pop("__all__") or truncs.pop("__all__")
        assert terms == ref[2] and truncs == ref[3]
        assert over == (not par.agents)
        if over:
            break
    # The 40-step limit ends it at the latest.
    assert over and env.agents == []
