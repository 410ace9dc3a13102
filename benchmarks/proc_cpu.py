"""What every benchmark that weighs processes reads from /proc: a process's CPU seconds, the
CPU model, and the machine line a report starts with."""

from __future__ import annotations

import os
from pathlib import Path

TICKS = os.sysconf("SC_CLK_TCK")


def cpu_seconds(pid: int) -> float:
    """User + system CPU time of a live process, s."""
    fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / TICKS


def cpu_model() -> str:
    for line in Path("/proc/cpuinfo").read_text().splitlines():
        if line.startswith("model name"):
            return line.split(":", 1)[1].strip()
    return "unknown"


def machine_line() -> str:
    """The cores, their model and the load before the runs."""
    return f"cpu: {os.cpu_count()} x {cpu_model()}, load before: {os.getloadavg()[0]:.2f}"
