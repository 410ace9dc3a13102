"""RLlib PPO with 2 env runners on a local Ray (2 CPUs): two training iterations complete and
report episode returns, each env runner flies its own SITL process, and every SITL is gone
once the script has stopped the algorithm and Ray."""

from __future__ import annotations

import json
import math
import os
import subprocess
import sys
import time
from pathlib import Path

import pytest
from training_support import REPO, TRAIN


def sitl_pids(binary: Path) -> set[int]:
    """PIDs of live processes whose program path is `binary` (zombies excluded)."""
    found = set()
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit():
            continue
        try:
            argv0 = (entry / "cmdline").read_bytes().split(b"\0", 1)[0]
            state = (entry / "stat").read_text().rsplit(")", 1)[1].split()[0]
        except OSError:
            continue
        if argv0 == bytes(binary) and state != "Z":
            found.add(int(entry.name))
    return found


@pytest.mark.training
def test_two_iterations_with_two_env_runners(sitl_binary, tmp_path):
    # The env runners start the SITL through a link of their own, so the processes this
    # test starts are told apart from any other SITL on the machine.
    binary = tmp_path / "flyloop-sitl-rllib-test"
    binary.symlink_to(sitl_binary)
    out = tmp_path / "iterations.json"
    command = [
        sys.executable,
        str(TRAIN / "train_rllib.py"),
        *("--num-env-runners", "2", "--iterations", "2", "--train-batch", "1000"),
        *("--minibatch", "250", "--epochs", "2", "--measure-sampling", "200"),
        *("--json", str(out)),
    ]
    seen: set[int] = set()
    most_at_once = 0
    with subprocess.Popen(
        command,
        cwd=REPO,
        env={**os.environ, "FLYLOOP_SITL": str(binary)},
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
    ) as process:
        deadline = time.monotonic() + 300
        while process.poll() is None and time.monotonic() < deadline:
            live = sitl_pids(binary)
            seen |= live
            most_at_once = max(most_at_once, len(live))
            time.sleep(0.2)
        if process.poll() is None:
            process.kill()
        output = process.stdout.read()
    assert process.returncode == 0, output[-4000:]

    result = json.loads(out.read_text())
    history = result["iterations"]
    assert len(history) == 2
    for figures in history:
        assert figures["env_steps"] >= 1000
        assert figures["episodes"] >= 1
        # Hover returns are in (−0.5, 1] per step and an episode is at most 250 steps.
        assert math.isfinite(figures["episode_return_mean"])
        assert -125 < figures["episode_return_mean"] <= 250
        assert figures["env_steps_per_s"] > 0
    assert "iteration   2: episode return mean" in output
    # Both env runners sampled (at least) 200 steps each, at the same time.
    assert result["sampling"]["env_runners"] == 2
    assert result["sampling"]["env_steps"] >= 400

    # One SITL per env runner (none in the driver), and none left behind.
    assert most_at_once == 2, (most_at_once, seen)
    time.sleep(0.5)
    assert not sitl_pids(binary), "SITL processes outlived the RLlib run"


@pytest.mark.training
def test_one_env_runner_steps_a_native_vector_env(sitl_binary, tmp_path):
    """--backend native: one env runner, 32 envs in one native vector env (RLlib's
    VECTOR_ENTRY_POINT mode), no SITL process at all; an iteration samples from all 32."""
    binary = tmp_path / "flyloop-sitl-rllib-native-test"
    binary.symlink_to(sitl_binary)
    out = tmp_path / "iterations.json"
    command = [
        sys.executable,
        str(TRAIN / "train_rllib.py"),
        *("--backend", "native", "--num-env-runners", "1", "--envs-per-env-runner", "32"),
        *("--iterations", "1", "--train-batch", "2048", "--minibatch", "512", "--epochs", "1"),
        *("--json", str(out)),
    ]
    with subprocess.Popen(
        command,
        cwd=REPO,
        env={**os.environ, "FLYLOOP_SITL": str(binary)},
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
    ) as process:
        started = set()
        deadline = time.monotonic() + 300
        while process.poll() is None and time.monotonic() < deadline:
            started |= sitl_pids(binary)
            time.sleep(0.2)
        if process.poll() is None:
            process.kill()
        output = process.stdout.read()
    assert process.returncode == 0, output[-4000:]
    assert "1 env runners × 32 envs, native vector envs" in output
    assert not started, "the native backend started a SITL"
    (figures,) = json.loads(out.read_text())["iterations"]
    assert figures["env_steps"] >= 2048
    # 32 envs at once: an untrained policy's hover episodes end within ~1 s (~40-50 steps),
    # so one iteration of 2048 steps finishes dozens of episodes (30 measured).
    assert figures["episodes"] >= 16
    assert math.isfinite(figures["episode_return_mean"])
