"""evaluate.py loads what train_sb3.py saved (PPO and SAC, hover and lander), reports success
rate and mean return, repeats itself exactly, and refuses a folder that holds no run."""

from __future__ import annotations

import json

import numpy as np
import pytest
from training_support import TRAIN, run_script


def train_tiny(out, env, algo, timesteps):
    """A run folder from a few thousand steps (in this process: no second torch import)."""
    from sb3_training import train

    return train(env, algo, timesteps, 1, out, progress_bar=False, baseline_episodes=2)


def evaluate_cli(run, tmp_path, episodes=3):
    path = tmp_path / "eval.json"
    done = run_script(
        TRAIN / "evaluate.py", str(run), "--episodes", str(episodes), "--json", str(path)
    )
    assert done.returncode == 0, done.stderr[-3000:]
    return done.stdout, json.loads(path.read_text())


@pytest.mark.training
def test_evaluate_loads_a_saved_ppo_model_and_repeats_exactly(sitl_binary, tmp_path):
    run = tmp_path / "ppo"
    summary = train_tiny(run, "hover", "ppo", 2048)
    assert summary["timesteps"] == 2048 and summary["action"] == "motors"

    stdout, first = evaluate_cli(run, tmp_path)
    assert "success rate" in stdout and "mean return" in stdout
    assert first["episodes"] == 3 and first["policy"] == str(run)
    assert 0.0 <= first["success_rate"] <= 1.0
    assert np.isfinite(first["mean_return"]) and first["mean_length"] >= 1
    # Deterministic policy, seeded episodes: a second evaluation gives the same figures.
    import evaluate

    assert evaluate.evaluate(run, 3) == first

    # The loaded policy acts as the saved one: same normalised observation, same action.
    from stable_baselines3 import PPO

    loaded = evaluate.SavedRun(run)
    direct = PPO.load(run / "model.zip", device="cpu")
    obs = np.zeros(33, np.float32)
    obs[2] = 1.0  # target 1 m above
    normalised = loaded.norm.normalize_obs(obs[None, :])
    expected, _ = direct.predict(normalised, deterministic=True)
    assert np.array_equal(loaded.act(obs), expected[0])
    # VecNormalize statistics were saved, not the identity.
    assert not np.allclose(normalised[0], obs)


@pytest.mark.training
def test_evaluate_loads_sac_and_lander_runs(sitl_binary, tmp_path):
    import evaluate

    sac = tmp_path / "sac"
    train_tiny(sac, "hover", "sac", 300)
    result = evaluate.evaluate(sac, 2)
    assert result["env_id"] == "flyloop/QuadHover-v0" and np.isfinite(result["mean_return"])

    lander = tmp_path / "lander"
    summary = train_tiny(lander, "lander", "ppo", 1024)
    assert summary["action"] is None
    result = evaluate.evaluate(lander, 2)
    assert result["env_id"] == "flyloop/Lander2D-v1"
    assert result["median_final_distance_m"] is None  # hover-only figure
    assert np.isfinite(result["mean_return"])


def test_evaluate_refuses_a_folder_without_a_run(tmp_path):
    done = run_script(TRAIN / "evaluate.py", str(tmp_path), "--episodes", "1")
    assert done.returncode == 2
    assert "summary.json not found" in done.stderr


def test_evaluate_points_an_offboard_policy_to_px4_offboard():
    # Regression: the shipped PX4 offboard policy (train_offboard.py) gave a KeyError traceback.
    offboard = TRAIN.parent.parent / "policies" / "px4_offboard_hover"
    done = run_script(TRAIN / "evaluate.py", str(offboard), "--episodes", "1")
    assert done.returncode == 2
    assert "Traceback" not in done.stderr
    assert "examples/px4_offboard.py" in done.stderr


def test_train_refuses_bad_arguments(tmp_path):
    for args, message in (
        (["--env", "moon"], "unknown env 'moon'"),
        (["--env", "lander", "--action", "rates"], "has no action interface 'rates'"),
        (["--timesteps", "0"], "--timesteps must be > 0"),
    ):
        done = run_script(TRAIN / "train_sb3.py", *args, "--out", str(tmp_path / "x"))
        assert done.returncode == 2, args
        assert message in done.stderr, done.stderr
        assert not (tmp_path / "x").exists()


@pytest.mark.training
def test_training_continues_from_a_saved_run_with_a_decaying_learning_rate(tmp_path):
    """--init-from starts from the saved policy and normalisation statistics (not from
    scratch), --lr-decay anneals the learning rate to 0 over the continued run."""
    import evaluate
    from sb3_training import train

    first = tmp_path / "first"
    train("lander", "ppo", 4096, 0, first, n_envs=2, progress_bar=False, baseline_episodes=1)
    before = evaluate.SavedRun(first)
    second = tmp_path / "second"
    s = train(
        "lander",
        "ppo",
        2048,
        1,
        second,
        n_envs=2,
        progress_bar=False,
        baseline_episodes=1,
        init_from=first,
        lr_decay=True,
    )
    assert s["init_from"] == str(first) and s["lr_decay"] is True
    assert s["timesteps"] == 2048  # counted from 0 again
    after = evaluate.SavedRun(second)
    # The statistics went on from the first run's count, not from a fresh VecNormalize (the
    # 2048 steps' observations and the first reset's 2).
    assert after.norm.obs_rms.count == before.norm.obs_rms.count + 2048 + 2
    # The learning rate fell linearly to 0: the last update ran at (almost) 0.
    assert after.model.lr_schedule(0.0) == 0.0
    assert after.model.lr_schedule(1.0) == pytest.approx(3e-4)

    # learning_curve.py draws the two runs as one curve, the second counted on from the first.
    from learning_curve import read_runs

    log, summaries = read_runs([first, second])
    assert [s["timesteps"] for s in summaries] == [4096, 2048]
    assert log.steps == sorted(log.steps) and log.steps[-1] > 4096
    curve = tmp_path / "curve.png"
    done = run_script(TRAIN / "learning_curve.py", str(first), str(second), "--out", str(curve))
    assert done.returncode == 0, done.stderr[-3000:]
    assert f"{len(log)} episodes of 2 run(s)" in done.stdout and curve.stat().st_size > 10_000


@pytest.mark.training
def test_evaluate_loads_a_fast_ppo_run(tmp_path):
    """evaluate.py loads fast_ppo.py's folder (policy.pt, summary.json): the same deterministic
    policy on the same seeded episodes as fast_ppo.py's own held-out evaluation (a batched
    forward pass there, one observation at a time here: floats may differ in the last bits).
    The moving pad's run: its critic has the time remaining as an extra input."""
    done = run_script(
        TRAIN / "fast_ppo.py",
        *("--env", "lander_moving", "--timesteps", "16384", "--num-envs", "16"),
        *("--eval-episodes", "4", "--out", str(tmp_path), "--no-progress-bar"),
    )
    assert done.returncode == 0, done.stderr[-3000:]
    run = tmp_path / "native"
    saved = json.loads((run / "summary.json").read_text())
    assert saved["config"]["time_limit_terminal"] is True
    own = saved["evaluation"]
    stdout, result = evaluate_cli(run, tmp_path, episodes=4)
    assert "success rate" in stdout
    assert result["env_id"] == "flyloop/Lander2D-v1" and result["first_seed"] == own["seed"]
    assert result["success_rate"] == own["success_rate"]
    assert result["mean_return"] == pytest.approx(own["mean_return"], abs=1.0)


def test_each_task_names_its_outcome_in_its_own_words(tmp_path):
    """Regression: evaluate.py called a successful hover episode "landed"."""
    import training_envs

    hover = training_envs.preset("hover")
    assert hover.outcome(True).startswith("held the target") and "land" not in hover.outcome(True)
    assert hover.outcome(False) == "did not hold the target"
    assert training_envs.preset("offboard").outcomes == hover.outcomes
    for name in ("lander", "lander_moving", "lander_v0"):
        p = training_envs.preset(name)
        assert (p.outcome(True), p.outcome(False)) == ("landed", "did not land"), name
    # The recorded episode's line, for random actions (which fail both tasks).
    for env, words in (("hover", "did not hold the target"), ("lander", "did not land")):
        gif = tmp_path / f"{env}.gif"
        done = run_script(
            TRAIN / "evaluate.py", "--random", "--env", env, "--episodes", "1", "--gif", str(gif)
        )
        assert done.returncode == 0, done.stderr[-2000:]
        assert f"steps, {words}) to {gif}" in done.stdout, done.stdout
