"""Fixtures for the SITL system tests: the release binary (built by cargo if missing or stale)
and SITL processes on ephemeral ports, stopped after each test."""

from __future__ import annotations

import pytest
from flyloop import find_sitl_binary
from sitl_client import Client, Sitl


@pytest.fixture(scope="session")
def sitl_binary():
    return find_sitl_binary(build=True)


@pytest.fixture
def start_sitl(sitl_binary):
    """Starts a SITL with extra CLI arguments; every SITL started is stopped afterwards."""
    started: list[Sitl] = []

    def start(*args: str, gcs: str = "off") -> Sitl:
        sitl = Sitl(sitl_binary, "--gcs", gcs, *args)
        started.append(sitl)
        return sitl

    yield start
    for sitl in started:
        sitl.stop()


@pytest.fixture
def client_for():
    """Makes a controller client for a SITL; closed afterwards."""
    clients: list[Client] = []

    def make(sitl: Sitl, timeout: float = 5.0) -> Client:
        c = Client(sitl.address, timeout)
        clients.append(c)
        return c

    yield make
    for c in clients:
        c.close()
