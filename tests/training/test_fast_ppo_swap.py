"""examples/train/fast_ppo.py --env swap: one policy shared by four agents of the Swap-v1
world, trained on flyloop.MultiAgentVectorEnv. The smoke test CI affords: a few updates run,
write their figures and evaluate on held-out worlds."""

from __future__ import annotations

import json

import pytest
from training_support import TRAIN, run_script


@pytest.mark.training
def test_fast_ppo_swap_runs_a_few_updates_and_evaluates_held_out_worlds(tmp_path):
    done = run_script(
        TRAIN / "fast_ppo.py",
        *("--env", "swap", "--timesteps", "8192", "--num-envs", "32"),
        *("--eval-episodes", "4", "--out", str(tmp_path), "--no-progress-bar"),
    )
    assert done.returncode == 0, done.stderr[-3000:]
    s = json.loads((tmp_path / "native" / "summary.json").read_text())
    assert s["env_id"] == "flyloop/Swap-v1" and s["env_kwargs"]["num_agents"] == 4
    # 32 sub-envs = 8 worlds x 4 agents, 128 steps each: two updates.
    assert s["env_steps"] == 8192 and len(s["rows"]) == 2
    assert s["evaluation"]["episodes"] == 4
    assert 0.0 <= s["evaluation"]["success_rate"] <= 1.0
    assert (tmp_path / "native" / "policy.pt").is_file()
