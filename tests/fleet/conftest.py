"""Fixtures of the fleet system tests: the release flyloop-sitl, the PX4 and ArduPilot builds,
and every process started stopped afterwards."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest
from flyloop import find_sitl_binary

TESTS = Path(__file__).resolve().parents[1]
for folder in ("sitl", "px4", "ardupilot", "fleet"):
    sys.path.insert(0, str(TESTS / folder))
from ardupilot_support import ardupilot_build  # noqa: E402
from px4_support import px4_root  # noqa: E402


@pytest.fixture(scope="session")
def sitl_binary():
    return find_sitl_binary(build=True)


@pytest.fixture(scope="session")
def px4_dir(tmp_path_factory):
    return px4_root(tmp_path_factory.mktemp("px4-build"))


@pytest.fixture(scope="session")
def ardupilot(tmp_path_factory):
    return ardupilot_build(tmp_path_factory.mktemp("ardupilot-build"))


@pytest.fixture
def started():
    """Processes the test started (anything with kill() or stop()), stopped at the end in
    reverse order: every one, even when stopping another failed (the failures reported
    together; none can block: processes.stop bounds every wait)."""
    procs: list = []
    yield procs
    failures = []
    for p in reversed(procs):
        try:
            (getattr(p, "kill", None) or p.stop)()
        except Exception as e:  # noqa: BLE001 — reported below, after the rest are stopped
            failures.append(f"{type(p).__name__}: {e}")
    if failures:
        pytest.fail("teardown: " + "; ".join(failures))
