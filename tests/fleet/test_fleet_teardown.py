"""A PX4 stopped by the tests leaves nothing behind: PX4 runs its startup script through
system() (`sh -c /bin/sh rcS` and `px4-<module>` clients, children of PX4), so it is started
in a group of its own and the whole group is killed, within a bounded wait; and none of its
threads is real-time (a killed PX4's FIFO threads waited tens of seconds for a CPU)."""

from __future__ import annotations

import os
import time
from pathlib import Path

from px4_support import Px4, free_instance, fresh_dir


def _group(pgid: int) -> list[str]:
    """Command names of the live (not zombie) processes of a process group."""
    names = []
    for entry in os.listdir("/proc"):
        if not entry.isdigit():
            continue
        try:
            stat = open(f"/proc/{entry}/stat").read()
        except OSError:
            continue
        name, rest = stat.split("(", 1)[1].rsplit(")", 1)
        state, _ppid, group = rest.split()[:3]
        if int(group) == pgid and state != "Z":
            names.append(name)
    return names


def test_a_killed_px4_takes_its_startup_shell_and_clients_with_it(px4_dir):
    px4 = Px4(px4_dir, free_instance(), fresh_dir("px4-teardown-"))
    # PX4 waits for a simulator inside its startup script: the shell and the
    # px4-simulator_mavlink client are there, in PX4's own group.
    deadline = time.monotonic() + 60
    while "Waiting for simulator" not in px4.output() and time.monotonic() < deadline:
        time.sleep(0.1)
    # No real-time thread (processes.py and px4_support.WITHOUT_REALTIME say why): the
    # policy field of every thread's stat is SCHED_OTHER (0).
    tasks = list(Path(f"/proc/{px4.proc.pid}/task").iterdir())
    policies = {int((t / "stat").read_text().rsplit(")", 1)[1].split()[38]) for t in tasks}
    assert len(tasks) >= 5 and policies == {0}, (len(tasks), policies)
    members = _group(px4.proc.pid)
    assert len(members) >= 3 and "sh" in members, members
    start = time.monotonic()
    px4.kill()
    assert time.monotonic() - start < 10
    deadline = time.monotonic() + 5
    while _group(px4.proc.pid) and time.monotonic() < deadline:
        time.sleep(0.05)
    assert _group(px4.proc.pid) == []
