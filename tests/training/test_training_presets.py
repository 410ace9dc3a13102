"""The training presets (examples/train/training_envs.py): success as documented, action
interfaces that map the zero action to hover, and the learning-curve helpers."""

from __future__ import annotations

import numpy as np
import pytest
import training_envs
from learning_curve import EpisodeLog, plot_learning_curve, rolling_mean


def test_hover_success_needs_the_time_limit_and_the_target():
    success = training_envs.preset("hover").success
    assert success(False, True, {"distance_to_target": 0.49})
    assert not success(False, True, {"distance_to_target": 0.51})
    assert not success(True, False, {"distance_to_target": 0.0})  # crashed on the target
    assert not success(True, True, {"distance_to_target": 0.1})


def test_lander_success_is_landed():
    success = training_envs.preset("lander").success
    assert success(True, False, {"landed": True})
    assert not success(True, False, {"landed": False})
    assert not success(False, True, {"landed": False})


def test_env_names_and_errors():
    assert training_envs.preset("flyloop/QuadHover-v0").name == "hover"
    assert training_envs.preset("Lander2D").name == "lander"
    with pytest.raises(ValueError, match="unknown env 'moon'"):
        training_envs.preset("moon")
    with pytest.raises(ValueError, match="no action interface 'rates'"):
        training_envs.check_action(training_envs.preset("lander"), "rates")


def test_zero_action_is_half_throttle_on_every_motor(sitl_binary):
    env = training_envs.make_env("hover", overrides={"use_wind": False})
    try:
        assert env.action_space.low.tolist() == [-1] * 4
        assert env.action_space.high.tolist() == [1] * 4
        assert env.action(np.zeros(4, np.float32)).tolist() == [0.5] * 4
        obs, _ = env.reset(seed=0)
        obs, *_ = env.step(np.zeros(4, np.float32))
        assert obs[29:33].tolist() == [0.5] * 4  # the commands the core applied
        assert env.unwrapped.dt == 0.02
    finally:
        env.close()


def test_success_info_is_set_at_the_end_only(sitl_binary):
    env = training_envs.make_success_env("hover", overrides={"max_steps": 3, "use_wind": False})
    try:
        env.reset(seed=1)
        infos = [env.step(np.zeros(4, np.float32))[4] for _ in range(3)]
    finally:
        env.close()
    assert "is_success" not in infos[0] and "is_success" not in infos[1]
    assert infos[2]["is_success"] is False  # 3 steps: still > 1 m from the target


def test_rolling_mean_and_curve(tmp_path):
    assert rolling_mean([1, 2, 3, 4], 2).tolist() == [1.0, 1.5, 2.5, 3.5]
    assert rolling_mean([], 5).size == 0
    log = EpisodeLog()
    for i in range(30):
        log.add(100 * i, float(i), 50, i > 20)
    png = plot_learning_curve(log, tmp_path / "c.png", title="t", random_return=1.0, window=5)
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    log.write_csv(tmp_path / "e.csv")
    lines = (tmp_path / "e.csv").read_text().splitlines()
    assert lines[0] == "env_steps,return,length,success" and lines[-1] == "2900,29.0,50,1"
