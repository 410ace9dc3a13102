"""A flight for the view tests: flyloop-sitl in lockstep with its ground-station link on a
given port (where the view listens) and a recording, flown by the SITL tests' PD controller
at about real time, keeping every reply's ground truth."""

from __future__ import annotations

import socket
import subprocess
import sys
import threading
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "tests" / "sitl"))

from sitl_client import Client, Sitl, local_ned  # noqa: E402
from test_sitl_lockstep import pd_motors  # noqa: E402


def free_port(kind: int = socket.SOCK_DGRAM) -> int:
    with socket.socket(socket.AF_INET, kind) as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


class Flight:
    """Flies vehicle 1 to `target_ned` (changed with `fly_to`) in a thread, a 0.01 s step
    every `period` s of wall time (0.01: ~real time)."""

    def __init__(
        self,
        binary: Path,
        gcs_port: int,
        record: Path | None = None,
        seed: int = 3,
        period: float = 0.01,
    ) -> None:
        self.period = period
        args = ["--gcs", f"127.0.0.1:{gcs_port}", "--seed", str(seed)]
        args += ["--record", str(record)] if record else []
        self.sitl = Sitl(binary, *args)
        self.client = Client(self.sitl.address)
        msgs = self.client.reset(seed)
        self.state = next(m for m in msgs if m.get_type() == "HIL_STATE_QUATERNION")
        self.target = list(local_ned(self.state))
        self.truth: list[tuple[int, tuple[float, float, float]]] = [
            (self.state.time_usec, local_ned(self.state))
        ]
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._fly, daemon=True)
        self._thread.start()

    def fly_to(self, target_ned) -> None:
        self.target = list(target_ned)

    def _fly(self) -> None:
        next_t = time.monotonic()
        while not self._stop.is_set():
            msgs = self.client.step(pd_motors(self.state, self.target))
            self.state = next(m for m in msgs if m.get_type() == "HIL_STATE_QUATERNION")
            self.truth.append((self.state.time_usec, local_ned(self.state)))
            next_t += self.period
            time.sleep(max(0.0, next_t - time.monotonic()))

    def stop(self) -> None:
        self._stop.set()
        self._thread.join(timeout=5)
        self.client.close()
        self.sitl.stop()


class View:
    """`python -m flyloop.view ARGS` in a process; `url` is the URL it printed."""

    def __init__(self, *args: str) -> None:
        self.web_port, self.grpc_port = free_port(socket.SOCK_STREAM), free_port(socket.SOCK_STREAM)
        cmd = [
            sys.executable,
            "-m",
            "flyloop.view",
            "--web-port",
            str(self.web_port),
            "--grpc-port",
            str(self.grpc_port),
            *args,
        ]
        self.proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        line = self.proc.stdout.readline()
        if "open http" not in line:
            self.proc.kill()
            raise AssertionError(f"the view did not start: {line!r} {self.proc.stderr.read()}")
        self.url = line.split("open ", 1)[1].strip()

    def stop(self) -> tuple[int, str]:
        import signal

        if self.proc.poll() is None:
            self.proc.send_signal(signal.SIGINT)
            try:
                self.proc.wait(timeout=15)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait()
        return self.proc.returncode, self.proc.stderr.read()


def rise(browser, rows_before, pixels: float, timeout: float) -> tuple[float, bytes]:
    """Screenshots until the hub's centre is `pixels` above `rows_before`' (the viewer on a
    software rasteriser shows the data some seconds late); returns how far it rose and the
    last screenshot."""
    from flyloop.view.screenshot import hub_pixels

    deadline = time.monotonic() + timeout
    while True:
        shot = browser.screenshot()
        rows = hub_pixels(shot)[:, 0]
        risen = rows_before.mean() - rows.mean() if len(rows) >= 30 else 0.0
        if risen > pixels or time.monotonic() > deadline:
            return risen, shot
        time.sleep(2.0)
