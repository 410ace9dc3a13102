"""tests/sitl/processes.py's stop(): a process group goes whole (children that outlive their
parent included), a process that ignores SIGTERM is killed after the timeout, and nothing
blocks the caller."""

from __future__ import annotations

import os
import signal
import subprocess
import time

from processes import stop


def _alive(pid: int) -> bool:
    try:
        state = open(f"/proc/{pid}/stat").read().rsplit(")", 1)[1].split()[0]
    except OSError:
        return False
    return state != "Z"


def _leader(script: str) -> tuple[subprocess.Popen, str]:
    """A shell leading a session of its own (as the tests start autopilots), and the first
    line it prints."""
    proc = subprocess.Popen(
        ["sh", "-c", script], stdout=subprocess.PIPE, text=True, start_new_session=True
    )
    return proc, proc.stdout.readline()


def test_a_group_leader_and_the_child_it_leaves_behind_both_go():
    # The shell starts a child and waits: as PX4 runs its rcS through system().
    proc, line = _leader("sleep 300 & echo $!; wait")
    child = int(line)
    assert _alive(child)
    start = time.monotonic()
    stop(proc, signal.SIGKILL)
    assert proc.returncode == -signal.SIGKILL
    deadline = time.monotonic() + 5
    while _alive(child) and time.monotonic() < deadline:
        time.sleep(0.05)
    assert not _alive(child), "the child outlived its group's SIGKILL"
    assert time.monotonic() - start < 5


def test_a_process_ignoring_sigterm_is_killed_after_the_timeout():
    proc, line = _leader("trap '' TERM; echo ready; while :; do sleep 0.1; done")
    assert line == "ready\n"
    start = time.monotonic()
    stop(proc, signal.SIGTERM, timeout=0.5)
    took = time.monotonic() - start
    assert proc.returncode == -signal.SIGKILL
    assert 0.5 <= took < 5, took


def test_a_process_of_the_callers_group_is_signalled_alone():
    # Not a group leader (flyloop-sitl in the tests): killpg would hit the test runner itself.
    proc = subprocess.Popen(["sleep", "300"])
    assert os.getpgid(proc.pid) == os.getpgid(0)
    stop(proc)
    assert proc.returncode == -signal.SIGTERM
    stop(proc)  # a second stop of a stopped process does nothing
