"""examples/train/fast_ppo.py: the compact PPO on the native vector env learns QuadHover in
seconds and Lander2D-v1 in minutes (here: its first stretch), and the same run over the SITL
vector env learns exactly the same thing."""

from __future__ import annotations

import json
import subprocess
import sys
import time

import pytest
from training_support import REPO, TRAIN, run_script

# The lander's short run: 20 updates of 128 envs x 128 steps (~23 CPU seconds). Measured
# (seed 0, held-out seeds 1,000,000..1,000,019): mean return 2.6 against -302.6 for random
# actions, 4 of 20 landed (still learning to land; a policy that only hovers scores ~-100).
LANDER_SHORT_STEPS = 327_680
LANDER_MIN_GAIN = 150.0


def summary(out, backend):
    return json.loads((out / backend / "summary.json").read_text())


@pytest.mark.training
def test_fast_ppo_learns_quadhover_on_the_native_vector_env(tmp_path):
    # docs/training.md's run. Measured (seed 0, 64 envs, 303,104 env steps; idle 2-core machine,
    # 10 s): training success >= 90 % after 270,336 steps (9.3 s); held-out 95 % (100
    # episodes, seeds 1,000,000..), mean return 188.3; random actions succeed 0 % (test_
    # training_sb3_hover.py: mean return 4.3). Bounds below leave room for another CPU's floats.
    done = run_script(TRAIN / "fast_ppo.py", "--out", str(tmp_path), "--no-progress-bar")
    assert done.returncode == 0, done.stderr[-3000:]
    print(done.stdout)
    s = summary(tmp_path, "native")
    assert s["env_steps"] == 303_104 and s["backend"] == "native"
    assert s["evaluation"]["episodes"] == 100
    assert s["evaluation"]["success_rate"] >= 0.8, s["evaluation"]
    assert s["evaluation"]["mean_return"] >= 150.0, s["evaluation"]
    assert s["first_update_at_90_percent"] is not None
    assert (tmp_path / "learning_curve.png").is_file()
    assert (tmp_path / "native" / "progress.csv").is_file()

    # evaluate.py records a hover episode and names its outcome in hover's words (it called
    # a held target "landed").
    gif, figures = tmp_path / "hover.gif", tmp_path / "eval.json"
    done = run_script(
        TRAIN / "evaluate.py", str(tmp_path / "native"), "--episodes", "1",
        "--json", str(figures), "--gif", str(gif),
    )  # fmt: skip
    assert done.returncode == 0, done.stderr[-3000:]
    held = json.loads(figures.read_text())["success_rate"] == 1.0
    words = "held the target" if held else "did not hold the target"
    assert f"steps, {words}" in done.stdout and "landed" not in done.stdout, done.stdout
    assert gif.read_bytes()[:6] == b"GIF89a"


@pytest.mark.training
def test_fast_ppo_learns_the_same_over_the_sitl_as_in_process(tmp_path, sitl_binary):
    """Same seed, same env steps: every update's figures and the held-out evaluation are
    identical on both backends (same observations bit for bit, rewards equal after the
    wire's float32 rounding, which the native env applies too); only the wall time differs."""
    done = run_script(
        TRAIN / "fast_ppo.py",
        *("--backend", "native", "sitl", "--timesteps", "16384", "--num-envs", "16"),
        *("--eval-episodes", "8", "--out", str(tmp_path), "--no-progress-bar"),
    )
    assert done.returncode == 0, done.stderr[-3000:]
    native, sitl = summary(tmp_path, "native"), summary(tmp_path, "sitl")
    assert native["env_steps"] == sitl["env_steps"] == 16_384
    strip = [{k: v for k, v in r.items() if k != "wall_s"} for r in native["rows"]]
    assert strip == [{k: v for k, v in r.items() if k != "wall_s"} for r in sitl["rows"]]
    assert native["evaluation"] == sitl["evaluation"]
    assert sum(r["episodes"] for r in native["rows"]) > 0


@pytest.mark.training
def test_fast_ppo_flies_another_frame_the_same_over_the_sitl_as_in_process(tmp_path, sitl_binary):
    """--frame hexa_x: QuadHover on the hexacopter X (six motor commands), both backends
    learning exactly the same; --frame on a task that is not hover is refused."""
    done = run_script(
        TRAIN / "fast_ppo.py", "--frame", "hexa_x",
        *("--backend", "native", "sitl", "--timesteps", "8192", "--num-envs", "16"),
        *("--eval-episodes", "4", "--out", str(tmp_path), "--no-progress-bar"),
    )  # fmt: skip
    assert done.returncode == 0, done.stderr[-3000:]
    native, sitl = summary(tmp_path, "native"), summary(tmp_path, "sitl")
    assert native["env"] == "hover_hexa_x" and native["env_kwargs"]["frame"] == "hexa_x"
    strip = [{k: v for k, v in r.items() if k != "wall_s"} for r in native["rows"]]
    assert strip == [{k: v for k, v in r.items() if k != "wall_s"} for r in sitl["rows"]]
    assert native["evaluation"] == sitl["evaluation"]
    refused = run_script(TRAIN / "fast_ppo.py", "--env", "lander", "--frame", "hexa_x")
    assert refused.returncode == 2 and "--frame hexa_x flies --env hover only" in refused.stderr


@pytest.mark.training
def test_fast_ppo_short_lander_run_beats_random_actions(tmp_path):
    """A short run on Lander2D-v1 (static pad) with the lander's settings: on the same
    held-out episodes the deterministic policy's return and episode length clearly beat
    uniformly random actions'."""
    from training_envs import random_policy_baseline

    done = run_script(
        TRAIN / "fast_ppo.py",
        *("--env", "lander", "--timesteps", str(LANDER_SHORT_STEPS)),
        *("--eval-episodes", "20", "--out", str(tmp_path), "--no-progress-bar"),
    )
    assert done.returncode == 0, done.stderr[-3000:]
    print(done.stdout)
    s = summary(tmp_path, "native")
    assert s["env_id"] == "flyloop/Lander2D-v1" and s["env"] == "lander"
    assert s["env_steps"] == LANDER_SHORT_STEPS
    random_return, random_success = random_policy_baseline("lander", 20, 1_000_000)
    trained = s["evaluation"]
    print(f"trained {trained}, random: mean return {random_return:.1f}")
    assert random_success == 0.0
    assert trained["mean_return"] >= random_return + LANDER_MIN_GAIN, trained


@pytest.mark.training
def test_fast_ppo_lander_learns_the_same_over_the_sitl_as_in_process(tmp_path, sitl_binary):
    """As for hover, with the moving pad's settings (reward scale, minibatches, the learning
    rate falling to 0, the Gaussian over collective and differential thrust, the time limit
    terminal with the time remaining as the critic's input, the best validated policy kept;
    8 updates, validated after updates 4, 6 and 8 here): both backends give the same updates,
    validations, kept policy and held-out evaluation, and policy.pt is the kept policy."""
    import evaluate

    done = run_script(
        TRAIN / "fast_ppo.py",
        *("--env", "lander_moving", "--backend", "native", "sitl", "--timesteps", "16384"),
        *("--num-envs", "16", "--eval-episodes", "4", "--out", str(tmp_path)),
        *("--set", "select_every=2", "--set", "select_after=4", "--set", "select_episodes=8"),
        "--no-progress-bar",
    )
    assert done.returncode == 0, done.stderr[-3000:]
    native, sitl = summary(tmp_path, "native"), summary(tmp_path, "sitl")
    assert native["env_steps"] == sitl["env_steps"] == 16_384
    assert native["config"] == sitl["config"] and native["config"]["reward_scale"] < 1.0
    assert native["config"]["action_basis"] == "collective" and native["config"]["lr_end"] == 0.0
    assert native["config"]["time_limit_terminal"] is True
    strip = [{k: v for k, v in r.items() if k != "wall_s"} for r in native["rows"]]
    assert len(strip) == 8
    assert strip == [{k: v for k, v in r.items() if k != "wall_s"} for r in sitl["rows"]]
    assert native["evaluation"] == sitl["evaluation"]
    assert native["selected_policy"] == sitl["selected_policy"]
    assert sum(r["episodes"] for r in native["rows"]) > 0

    checked = {
        k + 1: (r["validation_success_rate"], r["validation_mean_return"])
        for k, r in enumerate(native["rows"])
        if r["validation_success_rate"] is not None
    }
    assert sorted(checked) == [4, 6, 8]
    kept = native["selected_policy"]
    best = max(checked, key=lambda k: (*checked[k], k))
    assert kept["update"] == best and kept["env_steps"] == best * 16 * 128
    assert (kept["validation_success_rate"], kept["validation_mean_return"]) == checked[best]
    # policy.pt is that policy with its observation statistics: flown one episode at a time
    # by evaluate.py, the validation episodes give the kept update's figures again (the
    # returns up to float32 summation), not another validated update's.
    again = evaluate.evaluate(tmp_path / "native", 8, kept["validation_seed"])
    assert again["success_rate"] == kept["validation_success_rate"]
    assert again["mean_return"] == pytest.approx(kept["validation_mean_return"], abs=0.01)
    others = [checked[k][1] for k in checked if k != best]
    assert all(abs(r - again["mean_return"]) > 0.01 for r in others), (checked, again)


@pytest.mark.training
def test_training_table_reads_one_row_per_task_with_one_figure_per_seed(tmp_path):
    """training_table.py (the README's training table): each cell a fast_ppo.py run; the row
    holds every seed's wall time and held-out success, and the table names the machine."""
    done = run_script(
        TRAIN / "training_table.py",
        *("--tasks", "hover", "--seeds", "0", "1", "--timesteps", "8192"),
        *("--out", str(tmp_path)),
    )
    assert done.returncode == 0, done.stderr[-3000:]
    table = (tmp_path / "table.md").read_text()
    assert "CPUs, load" in table and "1 run(s) at a time" in table
    row = next(line for line in table.splitlines() if line.startswith("| QuadHover-v0"))
    cells = [c.strip() for c in row.strip("|").split("|")]
    assert cells[1] == "8,192"
    assert len(cells[2].split(" / ")) == 2 and len(cells[3].split(" / ")) == 2
    for seed in (0, 1):
        s = summary(tmp_path / f"hover_s{seed}", "native")
        assert s["seed"] == seed and s["env_steps"] == 8192
        assert f"{100 * s['evaluation']['success_rate']:.1f} %" in cells[3]


def test_fast_ppo_says_each_phase_from_its_first_second(tmp_path):
    """Regression: nothing showed for the first seconds (torch and the envs loading) nor
    while it evaluated and drew. Now each phase is one stderr line as it starts."""
    start = time.monotonic()
    proc = subprocess.Popen(
        [sys.executable, str(TRAIN / "fast_ppo.py"), "--timesteps", "4096", "--num-envs", "16"]
        + ["--eval-episodes", "2", "--out", str(tmp_path), "--no-progress-bar"],
        cwd=REPO,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    first = proc.stderr.readline()
    waited = time.monotonic() - start
    out, err = proc.communicate(timeout=300)
    assert proc.returncode == 0, err[-3000:]
    # Before torch is imported (seconds): only the interpreter's start-up before it.
    assert first == "fast_ppo: loading torch and the envs\n", first
    assert waited < 3.0, waited
    said = [line.split(": ", 1)[1] for line in err.splitlines() if line.startswith("fast_ppo: ")]
    assert [s.split()[0] for s in said] == ["training", "evaluating", "drawing"], said
    assert said[0] == (
        "training hover on the native backend: 2 updates of 16 envs x 128 steps (4,096 env steps)"
    )
