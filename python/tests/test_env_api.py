"""Registration, spaces, argument validation, binary discovery, and the adapter's tables
checked against the real SITL's own listings."""

from __future__ import annotations

import re
import subprocess
from pathlib import Path

import gymnasium as gym
import numpy as np
import pytest

import flyloop
from flyloop import SitlNotFoundError, SitlParameterError, find_sitl_binary
from flyloop.envs import Lander2DEnv, QuadHoverEnv, QuadWaypointsEnv
from flyloop.tasks import TASKS

IDS = {
    "flyloop/QuadHover-v0": (QuadHoverEnv, 33, 4, 0.0),
    "flyloop/QuadWaypoints-v0": (QuadWaypointsEnv, 37, 4, 0.0),
    "flyloop/Lander2D-v0": (Lander2DEnv, 11, 2, -1.0),
}


@pytest.mark.parametrize("env_id", sorted(IDS))
def test_each_id_is_registered_and_makes_its_env_with_float32_spaces(make_env, env_id):
    cls, n_obs, n_act, low = IDS[env_id]
    env = make_env(env_id)
    assert isinstance(env.unwrapped, cls)
    assert env.observation_space.shape == (n_obs,)
    assert env.observation_space.dtype == np.float32
    assert env.action_space.shape == (n_act,)
    assert env.action_space.dtype == np.float32
    assert (env.action_space.low == low).all() and (env.action_space.high == 1.0).all()
    assert env.spec.max_episode_steps is None, "the core truncates; no TimeLimit on top"
    obs, info = env.reset(seed=0)
    assert obs.dtype == np.float32 and env.observation_space.contains(obs)


def test_the_module_prefix_form_imports_the_package(make_env):
    env = make_env("flyloop:flyloop/QuadHover-v0")
    assert isinstance(env.unwrapped, QuadHoverEnv)


def test_constructor_arguments_reach_the_core(make_env):
    env = make_env("flyloop/QuadHover-v0", max_steps=3, dt=0.02, use_wind=False)
    env.reset(seed=1)
    flags = []
    for _ in range(3):
        _, _, terminated, truncated, info = env.step(np.full(4, 0.5, np.float32))
        flags.append(truncated)
    assert flags == [False, False, True]
    assert info["episode_time"] == pytest.approx(0.06)
    assert env.unwrapped.metadata["render_fps"] == 50
    obs, _ = env.reset(seed=1)
    assert (obs[22:25] == 0).all(), "no wind"
    # The wind bound follows the arguments: 1 m/s without wind (core wind_bound).
    assert env.observation_space.high[22] == 1.0


def test_a_moving_platform_adds_the_twelfth_observation(make_env):
    env = make_env("flyloop/Lander2D-v0", moving_platform=True, platform_speed=2.5)
    obs, info = env.reset(seed=4)
    assert obs.shape == (12,) and abs(obs[11]) == pytest.approx(1.0)
    _, _, _, _, info2 = env.step(np.zeros(2, np.float32))
    moved = info2["platform_position"][0] - info["platform_position"][0]
    assert abs(moved) == pytest.approx(2.5 * 0.02, rel=1e-4)


def test_waypoint_arguments_reach_the_core(make_env):
    env = make_env("flyloop/QuadWaypoints-v0", max_num_waypoints=2, waypoint_reach_threshold_m=5.0)
    env.reset(seed=2)
    _, reward, _, truncated, info = env.step(np.full(4, 0.5, np.float32))
    # Every waypoint is within 5 m of the cube's points: one per step, bonus paid each time.
    assert info["waypoints_reached"] == 1 and reward >= 10.0 - 2 * 0.01
    _, reward, _, truncated, info = env.step(np.full(4, 0.5, np.float32))
    assert info["waypoints_reached"] == 2 and truncated


@pytest.mark.parametrize(
    "kwargs, error, text",
    [
        ({"max_steps": 10.5}, TypeError, "max_steps must be an integer"),
        ({"use_wind": 1}, TypeError, "use_wind must be True or False"),
        ({"dt": float("nan")}, ValueError, "dt must be a finite number"),
        ({"wind_strength_range": 3.0}, TypeError, "wind_strength_range must be a pair"),
        ({"wind_strength_range": (4.0, 1.0)}, ValueError, "min must not exceed max"),
        ({"model_params": {"mas": 1.0}}, ValueError, "did you mean 'mass'"),
        ({"model_params": {"wind_enabled": True}}, ValueError, "already set by the argument"),
        ({"render_mode": "ascii"}, ValueError, "render_mode must be None"),
        ({"timeout": 0}, ValueError, "timeout must be"),
        ({"max_num_waypoints": 3}, TypeError, "unexpected arguments"),
    ],
)
def test_bad_argument_types_are_refused_before_any_process_starts(kwargs, error, text):
    with pytest.raises(error, match=re.escape(text)):
        QuadHoverEnv(sitl_path="/nonexistent/flyloop-sitl", **kwargs)


@pytest.mark.parametrize(
    "cls, kwargs, named",
    [
        (QuadHoverEnv, {"max_steps": 0}, "max_steps"),
        (QuadHoverEnv, {"dt": -0.01}, "dt"),
        (QuadHoverEnv, {"crash_tilt_threshold": 200.0}, "crash_tilt_threshold"),
        (QuadHoverEnv, {"wind_strength_range": (0.0, 500.0)}, "wind_strength_range"),
        (QuadHoverEnv, {"model_params": {"mass": -1.0}}, "model_params['mass']"),
        (QuadWaypointsEnv, {"max_num_waypoints": 0}, "max_num_waypoints"),
        (Lander2DEnv, {"platform_speed": -1.0}, "platform_speed"),
        (Lander2DEnv, {"initial_pos_random_range_m": -5.0}, "initial_pos_random_range_m"),
    ],
)
def test_out_of_range_values_are_refused_by_the_core_naming_the_argument(
    sitl_binary, cls, kwargs, named
):
    with pytest.raises(SitlParameterError) as err:
        cls(**kwargs)
    text = str(err.value)
    assert named in text and "out of range" in text, text
    assert isinstance(err.value, ValueError)


def test_binary_discovery_order_and_the_missing_binary_message(tmp_path, monkeypatch):
    fake = tmp_path / "bin" / "flyloop-sitl"
    fake.parent.mkdir()
    fake.write_text("#!/bin/sh\n")
    fake.chmod(0o755)
    other = tmp_path / "other-sitl"
    other.write_text("#!/bin/sh\n")
    other.chmod(0o755)
    monkeypatch.delenv("FLYLOOP_SITL", raising=False)
    monkeypatch.setenv("PATH", str(fake.parent))
    monkeypatch.setenv("CARGO_TARGET_DIR", str(tmp_path / "no-target"))
    assert find_sitl_binary() == fake
    monkeypatch.setenv("FLYLOOP_SITL", str(other))
    assert find_sitl_binary() == other
    assert find_sitl_binary(sitl_path=fake) == fake
    with pytest.raises(SitlNotFoundError, match="sitl_path = '/nope' is not an executable"):
        find_sitl_binary("/nope")
    monkeypatch.setenv("FLYLOOP_SITL", str(tmp_path / "missing"))
    with pytest.raises(SitlNotFoundError, match="FLYLOOP_SITL = .* is not an executable"):
        find_sitl_binary()
    monkeypatch.delenv("FLYLOOP_SITL")
    monkeypatch.setenv("PATH", str(tmp_path / "empty"))
    # The wheel's console command beside the interpreter comes last.
    scripts = tmp_path / "scripts"
    monkeypatch.setattr(flyloop.sitl_process.sysconfig, "get_path", lambda name: str(scripts))
    with pytest.raises(SitlNotFoundError) as err:
        find_sitl_binary()
    text = str(err.value)
    assert "build it with: cargo build --release -p flyloop-sitl" in text.lower()
    assert str(tmp_path / "no-target" / "release" / "flyloop-sitl") in text
    assert str(scripts / "flyloop-sitl") in text
    installed = scripts / "flyloop-sitl"
    installed.parent.mkdir()
    installed.write_text("#!/bin/sh\n")
    installed.chmod(0o755)
    assert find_sitl_binary() == installed
    # The workspace build under CARGO_TARGET_DIR comes before it.
    built = tmp_path / "no-target" / "release" / "flyloop-sitl"
    built.parent.mkdir(parents=True)
    built.write_text("#!/bin/sh\n")
    built.chmod(0o755)
    assert find_sitl_binary() == built


def test_a_missing_binary_stops_the_constructor_with_the_build_command(monkeypatch, tmp_path):
    monkeypatch.delenv("FLYLOOP_SITL", raising=False)
    monkeypatch.setenv("PATH", str(tmp_path))
    monkeypatch.setenv("CARGO_TARGET_DIR", str(tmp_path))
    monkeypatch.setattr(flyloop.sitl_process.sysconfig, "get_path", lambda name: str(tmp_path))
    with pytest.raises(SitlNotFoundError, match="cargo build --release -p flyloop-sitl"):
        gym.make("flyloop/Lander2D-v0")


def _listed(binary: Path, task: str, flag: str) -> str:
    return subprocess.run(
        [str(binary), "--task", task, flag], capture_output=True, text=True, check=True
    ).stdout


@pytest.mark.parametrize("task", sorted(TASKS))
def test_the_param_id_table_matches_the_sitls_listing(sitl_binary, task):
    spec = TASKS[task]
    listed = {}
    for row in _listed(sitl_binary, task, "--list-params").splitlines()[2:]:
        cells = [c.strip().strip("`") for c in row.strip("|").split("|")]
        listed[cells[1] or cells[0]] = cells[0]
    assert listed == spec.param_ids


@pytest.mark.parametrize("task", sorted(TASKS))
def test_the_info_layout_matches_the_sitls_frame_description(sitl_binary, task):
    spec = TASKS[task]
    text = _listed(sitl_binary, task, "--describe-frame")
    got = [
        (m.group(3), 1 if m.group(2) is None else int(m.group(2)) - int(m.group(1)))
        for m in re.finditer(r"^(\d+)(?:\.\.(\d+))? info\.(\w+)", text, re.M)
    ]
    assert got == [(name, n) for name, _, n in spec.info]
    n_obs = int(re.search(r"observation \((\d+) values\)", text).group(1))
    assert n_obs == spec.describe({})["observation_low"].size


def test_package_exports():
    assert flyloop.SitlParameterError.__mro__[1] is ValueError
    assert "flyloop/QuadWaypoints-v0" in gym.registry


def test_bad_actions_are_refused_and_the_episode_goes_on(make_env):
    env = make_env(QuadHoverEnv)
    env.reset(seed=0)
    for bad in ([0.5, np.nan, 0.5, 0.5], [np.inf, 0, 0, 0], [0.5, 0.5, 0.5]):
        with pytest.raises(ValueError, match="finite|shape"):
            env.step(np.array(bad, np.float32))
    _, _, _, _, info = env.step(np.full(4, 0.5, np.float32))
    assert info["step_count"] == 1
    # Out-of-range values are clipped by the core: the commands in effect stay in [0, 1].
    obs, *_ = env.step(np.array([2.0, -1.0, 0.5, 0.5], np.float32))
    np.testing.assert_array_equal(obs[29:33], [1.0, 0.0, 0.5, 0.5])
