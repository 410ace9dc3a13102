"""examples/lander_pilot.py: the scripted pilot (no learning) lands on Lander2D-v1 over the real
SITL — the task is feasible, and this is the baseline of docs/training.md's table."""

from __future__ import annotations

import gymnasium as gym
import lander_pilot
import numpy as np


def fly_many(seeds, **kwargs):
    env = gym.make("flyloop/Lander2D-v1", **kwargs)
    try:
        return [lander_pilot.fly(env, seed) for seed in seeds]
    finally:
        env.close()


def test_pilot_lands_at_least_95_percent_on_the_static_pad(sitl_binary):
    flights = fly_many(range(50))
    landed = [f for f in flights if f["landed"]]
    assert len(landed) >= 48, f"landed {len(landed)} of 50"
    # A landing earns the +100 on top of ≈ 120 of shaping; a failure at most the shaping − 100.
    assert min(f["return"] for f in landed) > 150.0
    speeds = [float(f["info"]["touchdown_speed"]) for f in landed]
    assert max(speeds) < 1.5 and np.mean(speeds) < 1.0


def test_pilot_lands_on_the_moving_pad(sitl_binary):
    flights = fly_many(range(20), moving_platform=True)
    landed = sum(f["landed"] for f in flights)
    assert landed >= 17, f"landed {landed} of 20"


def test_pilot_command_line_prints_the_rate(sitl_binary, capsys):
    assert lander_pilot.main(["--episodes", "3", "--seed-offset", "100"]) == 0
    out = capsys.readouterr().out
    assert "static pad, seeds 100..102: landed" in out
