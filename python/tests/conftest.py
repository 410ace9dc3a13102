"""Fixtures of the env tests: the real flyloop-sitl release binary (built by cargo when
FLYLOOP_SITL does not name one) and a tracker that closes every env a test made."""

from __future__ import annotations

import os
import subprocess
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]


def _cargo_binary() -> Path:
    target = Path(os.environ.get("CARGO_TARGET_DIR") or REPO / "target")
    if not target.is_absolute():
        target = REPO / target
    return target / "release" / "flyloop-sitl"


@pytest.fixture(scope="session")
def sitl_binary() -> Path:
    """The SITL every env test flies; exported as FLYLOOP_SITL so the envs find it."""
    given = os.environ.get("FLYLOOP_SITL")
    if given:
        path = Path(given)
    else:
        subprocess.run(
            ["cargo", "build", "--release", "-p", "flyloop-sitl", "--quiet"], cwd=REPO, check=True
        )
        path = _cargo_binary()
    assert path.is_file(), f"no flyloop-sitl binary at {path}"
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
