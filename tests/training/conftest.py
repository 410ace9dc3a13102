"""Fixtures of the training tests: the real flyloop-sitl release binary, and the example
scripts (examples/train/*.py, examples/demo_gym_pd.py) importable and runnable.

The `training` marker tags the tests that train (minutes of CPU). They run in the default
`pytest` invocation, as CI runs it; `pytest -m "not training"` skips them locally.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

import pytest
from flyloop import find_sitl_binary
from training_support import EXAMPLES, TRAIN

for folder in (TRAIN, EXAMPLES):
    if str(folder) not in sys.path:
        sys.path.insert(0, str(folder))


def pytest_configure(config: pytest.Config) -> None:
    config.addinivalue_line(
        "markers", "training: trains a policy for minutes of CPU (runs by default, as in CI)"
    )


@pytest.fixture(scope="session")
def sitl_binary() -> Path:
    """The SITL the envs fly (FLYLOOP_SITL, else cargo's release build), exported as
    FLYLOOP_SITL for the envs and the scripts' subprocesses."""
    path = find_sitl_binary(build=True)
    os.environ["FLYLOOP_SITL"] = str(path)
    return path
