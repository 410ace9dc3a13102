"""Fixtures of the ArduPilot system tests: the release flyloop-sitl, the ArduCopter SITL build
from $FLYLOOP_ARDUPILOT, and every process stopped afterwards."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest
from flyloop import find_sitl_binary

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "sitl"))
from ardupilot_support import (  # noqa: E402
    PARM,
    ArduPilot,
    Flyloop,
    ardupilot_build,
    free_instance,
    fresh_dir,
)


@pytest.fixture(scope="session")
def sitl_binary():
    return find_sitl_binary(build=True)


@pytest.fixture(scope="session")
def build(tmp_path_factory):
    return ardupilot_build(tmp_path_factory.mktemp("ardupilot-build"))


@pytest.fixture
def pair(build, sitl_binary):
    """Starts flyloop-sitl and ArduPilot instances (each ArduPilot on a free instance number,
    sending to flyloop's free port); stops them all."""
    started: list = []
    work = fresh_dir("flyloop-ardupilot-")

    class Pair:
        def flyloop(self, *args: str) -> Flyloop:
            f = Flyloop(sitl_binary, work, *args)
            started.append(f)
            return f

        def ardupilot(
            self, flyloop: Flyloop, *extra: str, connect: bool = True, parm: Path = PARM
        ) -> ArduPilot:
            """An ArduPilot flying `flyloop` with flyloop's `parm` file; with `connect`, the
            test's pymavlink link on its TCP port (else a ground station must connect:
            ArduPilot waits for one)."""
            a = ArduPilot(
                build, free_instance(), flyloop.port, fresh_dir("arducopter-"), *extra, parm=parm
            )
            started.append(a)
            if connect:
                a.connect()
            return a

    yield Pair()
    for p in reversed(started):
        if isinstance(p, ArduPilot):
            p.kill()
        else:
            p.stop()
