"""RLlib's multi-agent API (new API stack, PPO) on flyloop's MultiHover: 2 env runners on a
local Ray (2 CPUs), 4 agents per env, every agent mapped to the one policy "shared" by a
policy_mapping_fn (examples/train/train_rllib_multi.py through flyloop.rllib); two training
iterations complete, sample every agent and update only the shared policy."""

from __future__ import annotations

import json
import math

import pytest
from training_support import TRAIN, run_script


@pytest.mark.training
def test_two_iterations_of_a_shared_policy_with_two_env_runners(tmp_path):
    out = tmp_path / "iterations.json"
    done = run_script(
        TRAIN / "train_rllib_multi.py",
        *("--num-agents", "4", "--max-steps", "250", "--num-env-runners", "2"),
        *("--iterations", "2", "--train-batch", "1000", "--minibatch", "250", "--epochs", "2"),
        *("--json", str(out)),
        timeout=300,
    )
    assert done.returncode == 0, (done.stdout + done.stderr)[-4000:]
    assert "iteration   2: episode return mean" in done.stdout
    history = json.loads(out.read_text())["iterations"]
    assert len(history) == 2
    for figures in history:
        assert figures["modules"] == ["shared"]
        assert figures["env_steps"] >= 1000
        # 4 agents fly each env step until they leave one by one: more agent steps than env
        # steps (2,870-2,879 measured per iteration), at most 4 per env step.
        assert figures["env_steps"] < figures["agent_steps"] <= 4 * figures["env_steps"] + 8
        assert figures["episodes"] >= 1
        # An episode's return is summed over its 4 agents: each step's reward is in
        # (-0.5, 1], at most 250 steps, minus 10 per collision started.
        assert math.isfinite(figures["episode_return_mean"])
        assert -4 * (125 + 10) < figures["episode_return_mean"] <= 4 * 250
