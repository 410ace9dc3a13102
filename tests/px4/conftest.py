"""Fixtures of the PX4 system tests: the release flyloop-sitl, the PX4 SITL build from
$FLYLOOP_PX4, and every process and link stopped afterwards."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest
from flyloop import find_sitl_binary

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "sitl"))
from px4_support import Flyloop, Px4, free_instance, fresh_dir, px4_root  # noqa: E402


@pytest.fixture(scope="session")
def sitl_binary():
    return find_sitl_binary(build=True)


@pytest.fixture(scope="session")
def px4_dir(tmp_path_factory):
    return px4_root(tmp_path_factory.mktemp("px4-build"))


@pytest.fixture
def pair(px4_dir, sitl_binary):
    """Starts flyloop-sitl and PX4 instances on one free instance number; stops them all."""
    started: list = []
    instance = free_instance()
    work = fresh_dir("flyloop-px4-")

    class Pair:
        number = instance  # PX4's instance (`px4 -i`): its ports before it starts

        def flyloop(self, *args: str, speed=None) -> Flyloop:
            f = Flyloop(sitl_binary, instance, work, *args, speed=speed)
            started.append(f)
            return f

        def px4(self, **params: float) -> Px4:
            p = Px4(px4_dir, instance, fresh_dir("px4-work-"), **params)
            started.append(p)
            return p

    yield Pair()
    for p in reversed(started):
        if isinstance(p, Px4):
            p.kill()
        else:
            p.stop()
