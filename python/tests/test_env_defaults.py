"""The envs read the core's tables. Task arguments: every default equals the core's default
of the parameters it sets, every task parameter is an argument (or fixed by the env id), and
the signature, the vector env and the docstring show those defaults. Observation layout:
the core's groups cover the observation and name what each part holds."""

from __future__ import annotations

import inspect

import gymnasium as gym
import numpy as np
import pytest

import flyloop  # noqa: F401  (registers the ids)
from flyloop.envs import Lander2DEnv, Lander2DLandingEnv, QuadHoverEnv, QuadWaypointsEnv
from flyloop.tasks import observation_slices, resolve_config

ENVS = [QuadHoverEnv, QuadWaypointsEnv, Lander2DEnv, Lander2DLandingEnv]


@pytest.mark.parametrize("cls", ENVS, ids=lambda c: c.__name__)
def test_every_signature_default_sets_the_cores_default(cls):
    spec = cls.SPEC
    params = inspect.signature(cls).parameters
    task = {a.name: params[a.name].default for a in spec.arguments}
    config = resolve_config(spec, task, None)
    fixed = dict(spec.fixed)
    for name, value in config.items():
        if name in fixed:
            assert value == fixed[name]
        else:
            assert value == spec.defaults[name], name
    # Every parameter of the task itself is set by an argument or by the env id.
    own = {p["name"] for p in spec.parameters if p["group"].startswith("task")}
    assert own <= set(config)
    # The core built from the defaults holds its defaults (the id's fixed values aside).
    core = spec.describe(config)
    for p in core["parameters"]:
        assert p["value"] == fixed.get(p["name"], p["default"]), p["name"]


@pytest.mark.parametrize("cls", ENVS, ids=lambda c: c.__name__)
def test_single_and_vector_envs_resolve_the_same_config(cls):
    env = cls(backend="native")
    venv = gym.make_vec(
        cls.SPEC.env_id, num_envs=2, vectorization_mode="vector_entry_point", backend="native"
    )
    try:
        assert env.config == venv.unwrapped.config
        assert env.config == resolve_config(cls.SPEC, cls.SPEC.argument_defaults(), None)
    finally:
        env.close()
        venv.close()


def test_the_docstring_lists_the_arguments_with_the_cores_defaults_and_units():
    doc = QuadWaypointsEnv.__doc__
    assert "- ``max_num_waypoints=15``: Waypoints per episode" in doc
    assert "- ``crash_tilt_threshold=80.0``: Crash beyond this |roll| or |pitch| (deg)" in doc
    assert "- ``wind_strength_range=(0.0, 5.0)``:" in doc
    assert "- ``wind_direction=None``:" in Lander2DEnv.__doc__


@pytest.mark.parametrize(
    "env_id, kwargs",
    [
        ("flyloop/QuadHover-v0", {}),
        ("flyloop/QuadHover-v0", {"action_interface": "rates"}),
        ("flyloop/QuadWaypoints-v0", {}),
        ("flyloop/Lander2D-v1", {}),
        ("flyloop/Lander2D-v1", {"moving_platform": True}),
    ],
)
def test_the_observation_layout_covers_the_observation_and_names_its_parts(env_id, kwargs):
    env = gym.make(env_id, backend="native", **kwargs).unwrapped
    try:
        at = observation_slices(env.core)
        sizes = [s.stop - s.start for s in at.values()]
        assert sum(sizes) == env.observation_space.shape[0] and min(sizes) >= 1
        obs, info = env.reset(seed=4)
        obs, *_, info = env.step(env.action_space.sample())
        if "quaternion" in at:
            assert np.linalg.norm(obs[at["quaternion"]]) == pytest.approx(1.0, abs=1e-5)
            assert ((obs[at["motor_states"]] >= 0) & (obs[at["motor_states"]] <= 1)).all()
        if "target_offset" in at and "quaternion" in at:  # world frame (motor interface)
            offset = np.asarray(info["target_position"]) - np.asarray(info["position"])
            np.testing.assert_allclose(obs[at["target_offset"]], offset, atol=1e-4)
        if "platform_velocity" in at:
            assert at["platform_velocity"].start == 11
    finally:
        env.close()
