"""A fleet of real autopilots (PX4s, ArduPilots) flying one flyloop-sitl world: free blocks
of instance numbers, flyloop-sitl in fleet mode, and the STATUSTEXT it sends a ground
station. The autopilots themselves come from tests/px4/px4_support.py and
tests/ardupilot/ardupilot_support.py."""

from __future__ import annotations

import os
import socket
import subprocess
import time
from pathlib import Path

os.environ["MAVLINK20"] = "1"
from pymavlink import mavutil  # noqa: E402

# flyloop's home (its default, where the Iris preset's magnetic field is PX4's World Magnetic
# Model's): ArduPilots of a fleet are started with it (`--home`), heading north.
HOME = (47.397742, 8.545594, 488.0, 0.0)


def _free(kind: int, port: int) -> bool:
    with socket.socket(socket.AF_INET, kind) as s:
        try:
            s.bind(("127.0.0.1", port))
        except OSError:
            return False
    return True


def _px4_server_running(i: int) -> bool:
    """Whether PX4 instance i's server socket answers (a killed PX4 leaves the file behind;
    a new PX4 of that instance starts over a stale one)."""
    path = Path(f"/tmp/px4-sock-{i}")
    if not path.exists():
        return False
    with socket.socket(socket.AF_UNIX, socket.SOCK_STREAM) as s:
        try:
            s.connect(str(path))
        except OSError:
            return False
    return True


def px4_ports_free(i: int) -> bool:
    return (
        not _px4_server_running(i)
        and _free(socket.SOCK_STREAM, 4560 + i)
        and all(_free(socket.SOCK_DGRAM, p) for p in (14580 + i, 18570 + i, 14280 + i, 13030 + i))
    )


def ardupilot_ports_free(i: int) -> bool:
    return all(_free(socket.SOCK_STREAM, p + 10 * i) for p in (5760, 5762, 5763)) and all(
        _free(socket.SOCK_DGRAM, p + 10 * i) for p in (5501, 9002)
    )


def free_block(n: int, free, low: int, high: int) -> int:
    """A first instance b in [low, high - n] such that instances b..b+n-1 are all free."""
    for _ in range(200):
        b = low + int.from_bytes(os.urandom(2), "little") % (high - n - low)
        if all(free(b + k) for k in range(n)):
            return b
    raise RuntimeError(f"no block of {n} free instances")


class FleetSitl:
    """flyloop-sitl in fleet mode; its STATUSTEXT comes to a UDP socket of the test."""

    def __init__(self, binary: Path, workdir: Path, *args: str, speed: float = 0):
        self.gcs = mavutil.mavlink_connection("udpin:127.0.0.1:0", dialect="common")
        gcs_port = self.gcs.port.getsockname()[1]
        self.log = open(workdir / "flyloop.log", "w+")
        self.proc = subprocess.Popen(
            [
                str(binary),
                *args,
                "--speed-factor",
                str(speed),
                "--gcs",
                f"127.0.0.1:{gcs_port}",
            ],
            stdout=subprocess.PIPE,
            stderr=self.log,
            text=True,
        )
        line = self.proc.stdout.readline()
        if not line.startswith("flyloop-sitl ready "):
            self.stop()
            raise RuntimeError(f"flyloop-sitl did not start: {line!r} {self.stderr()}")
        self.ready = dict(kv.split("=", 1) for kv in line.split()[2:])
        self.texts: list[str] = []

    def stderr(self) -> str:
        self.log.flush()
        return Path(self.log.name).read_text()

    def stop(self) -> int:
        if self.proc.poll() is None:
            self.proc.terminate()
            try:
                self.proc.wait(timeout=10)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait()
        self.gcs.close()
        return self.proc.returncode

    def counters(self) -> dict[str, str]:
        """The counters of the line flyloop logs when it stops."""
        stats = self.stderr().split("stopped: ", 1)[1].split()
        return dict(kv.split("=", 1) for kv in stats)

    def statustext(self, contains: str, timeout: float) -> str:
        """The first STATUSTEXT (from now, or kept from before) containing `contains`."""
        end = time.monotonic() + timeout
        while True:
            for t in self.texts:
                if contains in t:
                    return t
            if time.monotonic() > end:
                raise AssertionError(
                    f"no STATUSTEXT with {contains!r}; got {self.texts}\n{self.stderr()[-3000:]}"
                )
            m = self.gcs.recv_match(type="STATUSTEXT", blocking=True, timeout=0.2)
            if m is not None:
                self.texts.append(m.text)
