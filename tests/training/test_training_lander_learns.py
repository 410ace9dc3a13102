"""A short PPO run on Lander2D-v1 (the landing reward, static pad; fixed seed, CPU, in-process)
learns: on the same seeded episodes the trained policy's return and time in the air beat the
random policy's by stated margins. Landings come later (the landing rate passes 10 % after about
400k env steps: see the README's learning curve); this run is the CI-sized first stretch of it."""

from __future__ import annotations

import json

import pytest
from training_support import TRAIN, run_script

TIMESTEPS = 294_912  # 72 PPO updates of 8 envs × 512 steps
EVAL_EPISODES = 20
# The margins. Measured over these 20 episodes (seeds 1,000,000.., deterministic policy): random
# actions mean return -302.6, mean length 111 steps, no landing; PPO after TIMESTEPS with seed 0
# (80 s on an idle 2-core machine): mean return -55.9, mean length 917 steps, 1 landing in 20.
# (After 98,304 steps it was -152.9 and 614 steps.) Required: return +150 over random, episodes
# at least 3x as long.
MIN_GAIN = 150.0
MIN_LENGTH_RATIO = 3.0


@pytest.mark.training
def test_short_ppo_run_on_lander_v1_beats_the_random_policy(tmp_path):
    out = tmp_path / "lander_ppo"
    done = run_script(
        TRAIN / "train_sb3.py",
        *("--env", "lander", "--algo", "ppo", "--seed", "0", "--n-envs", "8"),
        *("--timesteps", str(TIMESTEPS), "--out", str(out), "--no-progress-bar"),
    )
    assert done.returncode == 0, done.stderr[-3000:]
    summary = json.loads((out / "summary.json").read_text())
    assert summary["env_id"] == "flyloop/Lander2D-v1"
    assert summary["timesteps"] == TIMESTEPS

    import evaluate

    trained = evaluate.evaluate(out, EVAL_EPISODES)
    random = evaluate.evaluate(None, EVAL_EPISODES, env="lander")
    print(
        f"Lander2D-v1 over {EVAL_EPISODES} episodes: mean return trained "
        f"{trained['mean_return']:.1f} vs random {random['mean_return']:.1f}; mean length "
        f"{trained['mean_length']:.0f} vs {random['mean_length']:.0f}; landings "
        f"{trained['success_rate']:.2f} vs {random['success_rate']:.2f}"
    )
    assert trained["mean_return"] >= random["mean_return"] + MIN_GAIN, (trained, random)
    # It learned to stay in the air instead of falling or flying off: longer episodes.
    assert trained["mean_length"] >= MIN_LENGTH_RATIO * random["mean_length"], (trained, random)
