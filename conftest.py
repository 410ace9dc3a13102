"""Test groups for pytest-xdist. scripts/test.sh runs the suites on several workers
(`-n N --dist loadgroup`); the tests of one group run on one worker, one after another:

- px4, ardupilot: each autopilot build is started one instance at a time, so two instances
  never race for the same free ports or work directories;
- fmu (with the README and docs snippets, which simulate the packed FMUs): the session's
  scripts/pack-fmus.sh rewrites dist/fmu/, which no other test may be reading meanwhile;
- fleetview: the fleet view tests, beside the px4 group (minutes of real time each);
- ray: one Ray on the machine at a time (the cluster test's `--address auto` must find its
  own head node).

Without xdist (a plain `pytest`), the groups change nothing.
"""

from __future__ import annotations

import math
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent
GROUPS = {
    "tests/px4/": "px4",
    "tests/ardupilot/": "ardupilot",
    # The fleet view tests (minutes of real time each, in a browser) run beside the PX4
    # group instead of lengthening it: their instance blocks are drawn at random and checked
    # free, as tests/view's PX4 flights are.
    "tests/fleet/test_fleet_view.py": "fleetview",
    # Fleets start PX4s (and ArduPilots) in blocks of instance numbers: after the PX4 tests.
    "tests/fleet/": "px4",
    "tests/fmu/": "fmu",
    "tests/readme/": "fmu",
    "tests/training/test_training_rllib": "ray",
}


# Before xdist's own hook, which reads the groups (it appends "@group" to the test ids).
@pytest.hookimpl(tryfirst=True)
def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    for item in items:
        path = item.path.relative_to(ROOT).as_posix()
        group = next((g for prefix, g in GROUPS.items() if path.startswith(prefix)), None)
        if group is not None:
            item.add_marker(pytest.mark.xdist_group(group))


# Where CI's pytest time goes: per xdist worker, its tests' summed durations and the span from
# its first test's start to its last's end; per group, the same. The longest span is the run.
_SPANS: dict[str, list[float]] = {}


def _account(key: str, report: pytest.TestReport) -> None:
    span = _SPANS.setdefault(key, [math.inf, -math.inf, 0.0, 0])
    span[0] = min(span[0], report.start)
    span[1] = max(span[1], report.stop)
    span[2] += report.duration
    span[3] += report.when == "call"


def pytest_runtest_logreport(report: pytest.TestReport) -> None:
    if not hasattr(report, "start"):
        return
    worker = getattr(getattr(report, "node", None), "gateway", None)
    suffix = report.nodeid.rsplit("@", 1)[-1]  # xdist's "@group" (a test id may hold an @)
    group = suffix if suffix in GROUPS.values() else "(no group)"
    _account(f"worker {worker.id if worker else 'main'}", report)
    _account(f"group {group}", report)


def pytest_terminal_summary(terminalreporter) -> None:
    if not _SPANS:
        return
    start = min(s[0] for s in _SPANS.values())
    terminalreporter.section("where the time went (s from the first test's start)")
    for key, (first, last, busy, n) in sorted(_SPANS.items()):
        span = f"from {first - start:6.1f} to {last - start:6.1f}"
        terminalreporter.write_line(f"{key:22} {n:4} tests  {busy:7.1f} s busy  {span}")
