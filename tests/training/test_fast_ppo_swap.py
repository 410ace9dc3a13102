"""examples/train/fast_ppo.py --env swap: one policy shared by four agents of the Swap-v0
world, trained on flyloop.MultiAgentVectorEnv with the separation term in the learner's
reward. The smoke test CI affords: a few updates run, write their figures and evaluate on
held-out worlds."""

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
    assert s["env_id"] == "flyloop/Swap-v0" and s["env_kwargs"]["num_agents"] == 4
    assert s["config"]["separation_penalty"] == 0.5 and s["config"]["separation_radius"] == 0.8
    # 32 sub-envs = 8 worlds x 4 agents, 128 steps each: two updates.
    assert s["env_steps"] == 8192 and len(s["rows"]) == 2
    assert s["evaluation"]["episodes"] == 4
    assert 0.0 <= s["evaluation"]["success_rate"] <= 1.0
    assert (tmp_path / "native" / "policy.pt").is_file()
    # --init goes on from that run's policy and observation statistics.
    again = run_script(
        TRAIN / "fast_ppo.py",
        *("--env", "swap", "--timesteps", "4096", "--num-envs", "32", "--seed", "1"),
        *("--init", str(tmp_path / "native"), "--eval-episodes", "4"),
        *("--out", str(tmp_path / "again"), "--no-progress-bar"),
    )
    assert again.returncode == 0, again.stderr[-3000:]
    s = json.loads((tmp_path / "again" / "native" / "summary.json").read_text())
    assert s["init"] == str(tmp_path / "native") and s["earlier"]["env_steps"] == 8192
    # One training of three updates: the earlier two, then this one.
    assert s["env_steps"] == 8192 + 4096 and [r["env_steps"] for r in s["rows"]] == [
        4096,
        8192,
        12288,
    ]
