"""docs/training.md's `tensorboard --logdir runs/hover_ppo/tb` line, run for real: TensorBoard
serves the logs train_sb3.py writes, with the two curves the page names (rollout/ep_rew_mean,
rollout/success_rate)."""

from __future__ import annotations

import json
import socket
import subprocess
import sys
import time
import urllib.request
from pathlib import Path

import pytest


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def scalar_tags(port: int) -> set[str]:
    url = f"http://127.0.0.1:{port}/data/plugin/scalars/tags"
    with urllib.request.urlopen(url, timeout=5) as response:
        runs = json.load(response)
    return {tag for tags in runs.values() for tag in tags}


@pytest.mark.training
def test_tensorboard_serves_the_training_curves(sitl_binary, tmp_path):
    from sb3_training import train

    run = tmp_path / "hover_ppo"
    # 4,096 steps of 250-step episodes: every rollout ends episodes, so both curves are logged.
    train("hover", "ppo", 4096, 1, run, progress_bar=False, baseline_episodes=1)
    assert any((run / "tb").rglob("events.out.tfevents.*"))

    tensorboard = Path(sys.executable).parent / "tensorboard"
    port = free_port()
    proc = subprocess.Popen(
        [str(tensorboard), "--logdir", str(run / "tb"), "--host", "127.0.0.1", "--port", str(port)],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        tags: set[str] = set()
        deadline = time.monotonic() + 90
        while time.monotonic() < deadline and proc.poll() is None:
            try:
                tags = scalar_tags(port)
            except OSError:
                pass  # not listening yet
            if {"rollout/ep_rew_mean", "rollout/success_rate"} <= tags:
                break
            time.sleep(1)
        assert proc.poll() is None, proc.stderr.read()[-2000:]
        assert {"rollout/ep_rew_mean", "rollout/success_rate"} <= tags, sorted(tags)
    finally:
        proc.terminate()
        try:
            proc.wait(timeout=10)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait()
        proc.stderr.close()
