"""examples/train/train_offboard.py: a short run of the rates-interface training writes a
policy that examples/px4_offboard.py loads and that acts, in numpy, exactly as the trained
torch network; and the shipped policy holds its targets on the core's model of PX4 (the
held-out check of docs/px4.md, on fewer episodes)."""

from __future__ import annotations

import json
import sys

import numpy as np
import pytest
import torch
from training_support import EXAMPLES, TRAIN, run_script

sys.path.insert(0, str(EXAMPLES))
import px4_offboard  # noqa: E402

SHIPPED = TRAIN.parents[1] / "policies" / "px4_offboard_hover"


@pytest.mark.training
def test_a_short_run_exports_a_policy_the_deployment_script_runs_as_trained(tmp_path):
    done = run_script(
        TRAIN / "train_offboard.py",
        *("--timesteps", "16384", "--eval-episodes", "4", "--out", str(tmp_path)),
        "--no-progress-bar",
    )
    assert done.returncode == 0, done.stderr[-3000:]
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert set(summary["evaluation"]) == {"nominal", "randomized", "unseen"}
    policy = px4_offboard.Policy.load(tmp_path)
    assert policy.dt == 0.02 and policy.layout.startswith("flyloop rates interface")
    # The numpy MLP acts as the torch network it was exported from.
    import fast_ppo

    state = torch.load(tmp_path / "policy.pt", weights_only=False)
    model = fast_ppo.ActorCritic(16, 4, fast_ppo.TASKS["offboard"].config.hidden)
    model.load_state_dict(state["model"])
    norm = fast_ppo.RunningNorm(16)
    norm.mean, norm.var = state["obs_mean"], state["obs_var"]
    space_low, space_high = policy.action_low, policy.action_high
    rng = np.random.default_rng(0)
    for _ in range(20):
        obs = rng.normal(0, 1, 16)
        with torch.no_grad():
            unit = model.mu(torch.as_tensor(norm(obs[None]))).numpy()[0]
        expected = space_low + (np.clip(unit, -1, 1) + 1) * 0.5 * (space_high - space_low)
        assert np.allclose(policy(obs), expected, atol=1e-5)


@pytest.mark.training
def test_the_shipped_policy_holds_its_targets_on_the_model_of_px4():
    import train_offboard

    state = torch.load(SHIPPED / "policy.pt", weights_only=False)
    model = train_offboard.fast_ppo.ActorCritic(16, 4, 64)
    model.load_state_dict(state["model"])
    norm = train_offboard.fast_ppo.RunningNorm(16)
    norm.mean, norm.var = state["obs_mean"], state["obs_var"]
    for env in ({"randomize": None}, {"randomize": None, "model_params": train_offboard.UNSEEN}):
        result = train_offboard.evaluate(model, norm, 40, **env)
        assert result["success_rate"] >= 0.85, (env, result)
        assert result["mean_final_distance_m"] < 0.3, (env, result)
