"""The envs' task arguments come from the core's parameter table: every default equals the
core's default of the parameters it sets, every task parameter is an argument (or fixed by
the env id), and the signature, the vector env and the docstring show those defaults."""

from __future__ import annotations

import inspect

import gymnasium as gym
import pytest

import flyloop  # noqa: F401  (registers the ids)
from flyloop.envs import Lander2DEnv, Lander2DLandingEnv, QuadHoverEnv, QuadWaypointsEnv
from flyloop.tasks import resolve_config

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
