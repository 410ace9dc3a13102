"""Fixtures of the env tests: the real flyloop-sitl release binary (built by cargo when
FLYLOOP_SITL does not name one) and a tracker that closes every env a test made."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from flyloop import find_sitl_binary

# torch's optimizers import triton (through torch._dynamo) when first made; in a process where
# pygame has opened an X11 window (test_render_human.py) that import segfaults (the window's
# graphics libraries and triton's own LLVM clash). Loaded first, before any window, it loads
# cleanly: the tests that train in-process (tests/training) may share a pytest-xdist worker
# with the window tests. Measured: window then Adam -> SIGSEGV; this import, window, Adam -> ok.
try:
    import torch._dynamo  # noqa: F401
except ImportError:  # torch is a test peer of the training tests only
    pass


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
