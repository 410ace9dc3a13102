"""MAVProxy, the real ground station, as a peer in the system tests: started headless from the
test venv, typed commands on its stdin, its console lines read by a thread so a test can wait
for one with a timeout."""

from __future__ import annotations

import os
import queue
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path


class MavProxy:
    """A `mavproxy.py` process with `args` (e.g. `--master=...`), logging into `cwd`."""

    def __init__(self, cwd: Path, *args: str):
        self.queue: queue.Queue[str] = queue.Queue()
        self.seen: list[str] = []
        self.proc = subprocess.Popen(
            [sys.executable, str(Path(sys.executable).parent / "mavproxy.py"), *args],
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            stderr=subprocess.STDOUT,
            text=True,
            cwd=cwd,  # its logs (mav.tlog, mav.parm) go there
            env={**os.environ, "MAVLINK20": "1"},
            # Its own process group: MAVProxy forks helper processes that outlive a killed
            # parent; kill() stops the whole group.
            start_new_session=True,
        )
        threading.Thread(target=self._read, daemon=True).start()

    def _read(self):
        for line in self.proc.stdout:
            self.queue.put(line)

    def type(self, command: str) -> None:
        """A command line, as an operator types it at MAVProxy's prompt."""
        self.proc.stdin.write(command + "\n")
        self.proc.stdin.flush()

    def wait_for(self, text: str, timeout: float) -> str:
        """The first console line from now on that contains `text`."""
        end = time.monotonic() + timeout
        while (left := end - time.monotonic()) > 0:
            try:
                line = self.queue.get(timeout=left)
            except queue.Empty:
                break
            self.seen.append(line)
            if text in line:
                return line
        raise AssertionError(f"no {text!r} within {timeout} s in:\n{self.console()}")

    def console(self) -> str:
        """The last 200 lines MAVProxy printed so far."""
        while not self.queue.empty():
            self.seen.append(self.queue.get())
        return "".join(self.seen[-200:])

    def kill(self) -> None:
        # MAVProxy's own shutdown can take long; what a test needed is already read. The
        # group (this process's id) holds MAVProxy and the helpers it forked.
        try:
            os.killpg(self.proc.pid, signal.SIGKILL)
        except ProcessLookupError:
            pass
        self.proc.wait()
