"""Processes and ports of the system tests, shared by the PX4, ArduPilot and fleet tests and
the fleet benchmarks: is a port free, a fresh working directory, and stopping a process so
that a test's teardown can never block.

Why process groups: PX4 runs its startup script through system(): `sh -c /bin/sh rcS` and the
`px4-<module>` clients it starts are children of PX4 in the group of whoever started PX4 (the
pytest worker), so killing PX4's PID leaves them behind. Autopilots are started in a session
of their own (`start_new_session=True`) and stopped by their group. Every wait is bounded: a
process that outlives SIGKILL (a thread in uninterruptible sleep) is reported with its kernel
state instead of hanging the worker in wait4.
"""

from __future__ import annotations

import os
import signal
import socket
import subprocess
import tempfile
from pathlib import Path

# Seconds a process has to go after SIGKILL before the teardown reports it and moves on.
KILL_GRACE_S = 20.0


def port_free(kind: int, port: int) -> bool:
    """Whether 127.0.0.1:`port` can be bound now (kind: socket.SOCK_STREAM or SOCK_DGRAM)."""
    with socket.socket(socket.AF_INET, kind) as s:
        try:
            s.bind(("127.0.0.1", port))
        except OSError:
            return False
    return True


def fresh_dir(prefix: str) -> Path:
    return Path(tempfile.mkdtemp(prefix=prefix))


def _leads_group(proc: subprocess.Popen) -> bool:
    """Whether the process (alive or an unreaped zombie: its PID is still its own) leads a
    process group of its own."""
    try:
        return os.getpgid(proc.pid) == proc.pid
    except ProcessLookupError:
        return False


def _signal(proc: subprocess.Popen, sig: int, group: bool) -> None:
    try:
        if group:
            # A group's id is not given to a new process while any member lives.
            os.killpg(proc.pid, sig)
        else:
            proc.send_signal(sig)
    except ProcessLookupError:
        pass  # all gone


def kernel_state(pid: int) -> str:
    """The process's state and its threads' (state, wait channel, count) from /proc, for a
    report: a killed process whose leader is a zombie is not reaped while a thread lives."""
    try:
        status = Path(f"/proc/{pid}/status").read_text().splitlines()
        state = next((line for line in status if line.startswith("State:")), "State: ?")
        threads: dict[str, int] = {}
        for task in Path(f"/proc/{pid}/task").iterdir():
            try:
                t = (task / "stat").read_text().rsplit(")", 1)[1].split()[0]
                w = (task / "wchan").read_text().strip() or "-"
            except OSError:
                continue
            threads[f"{t}/{w}"] = threads.get(f"{t}/{w}", 0) + 1
    except OSError:
        return "gone from /proc"
    return f"{state.split(':', 1)[1].strip()}; threads (state/wchan: count) {threads}"


def stop(proc: subprocess.Popen, sig: int = signal.SIGTERM, timeout: float = 10) -> None:
    """Stops a process (its group, when it leads one): `sig`, then SIGKILL after `timeout`
    seconds, then at most KILL_GRACE_S more. Raises RuntimeError naming the PID and its kernel
    state if it is still there; never waits without a bound. The group is killed once more at
    the end: children that outlived their parent go too."""
    if proc.poll() is not None:
        return
    group = _leads_group(proc)
    _signal(proc, sig, group)
    try:
        proc.wait(timeout=timeout)
    except subprocess.TimeoutExpired:
        _signal(proc, signal.SIGKILL, group)
        try:
            proc.wait(timeout=KILL_GRACE_S)
        except subprocess.TimeoutExpired:
            raise RuntimeError(
                f"process {proc.pid} ({proc.args[0] if proc.args else '?'}) outlived SIGKILL"
                f" by {KILL_GRACE_S:.0f} s: {kernel_state(proc.pid)}"
            ) from None
    if group:
        _signal(proc, signal.SIGKILL, group)


def stop_counters(log: str) -> dict[str, str]:
    """The counters of the line flyloop-sitl logs when it stops (`stopped: key=value ...`)."""
    return dict(kv.split("=", 1) for kv in log.split("stopped: ", 1)[1].split())
