"""Fixtures of the env tests: the real flyloop-sitl release binary (built by cargo when
FLYLOOP_SITL does not name one) and a tracker that closes every env a test made."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from flyloop import find_sitl_binary


@pytest.fixture(scope="session")
def sitl_binary() -> Path:
    """The SITL every env test flies; exported as FLYLOOP_SITL so the envs find it."""
    path = find_sitl_binary(build=True)
    os.environ["FLYLOOP_SITL"] = str(path)
    return path


@pytest.fixture
def make_env(sitl_binary):
    """make_env(cls_or_id, **kwargs): an env closed after the test."""
    import gymnasium as gym

    import flyloop  # noqa: F401  (registers the ids)

    made = []

    def make(what, **kwargs):
        env = gym.make(what, **kwargs) if isinstance(what, str) else what(**kwargs)
        made.append(env)
        return env

    yield make
    for env in made:
        env.close()
