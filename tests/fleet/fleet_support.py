"""A fleet of real autopilots (PX4s, ArduPilots) flying one flyloop-sitl world: free blocks
of instance numbers, flyloop-sitl in fleet mode, the STATUSTEXT it sends a ground station, and
landing a fleet. The autopilots themselves (and which of their ports are free) come from
tests/px4/px4_support.py and tests/ardupilot/ardupilot_support.py; processes and ports from
tests/sitl/processes.py."""

from __future__ import annotations

import csv
import os
import subprocess
import sys
import time
from pathlib import Path

os.environ["MAVLINK20"] = "1"
from pymavlink import mavutil  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "sitl"))
from ardupilot_support import ardupilot_ports_free  # noqa: E402, F401 (re-exported)
from processes import stop, stop_counters  # noqa: E402
from px4_support import px4_ports_free  # noqa: E402, F401 (re-exported)

# flyloop's home (its default, where the Iris preset's magnetic field is PX4's World Magnetic
# Model's): ArduPilots of a fleet are started with it (`--home`), heading north.
HOME = (47.397742, 8.545594, 488.0, 0.0)


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
        stop(self.proc)
        self.gcs.close()
        return self.proc.returncode

    def counters(self) -> dict[str, str]:
        """The counters of the line flyloop logs when it stops."""
        return stop_counters(self.stderr())

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


def land_all(px4s, timeout: float = 120) -> None:
    """Lands every PX4 of `px4s` and waits (each up to `timeout` s) for its automatic disarm."""
    for p in px4s:
        p.land()
    for p in px4s:
        p.wait_for(
            "the automatic disarm after landing",
            lambda m, p=p: m.get_srcSystem() == p.target and not p.armed(m),
            timeout,
            "HEARTBEAT",
        )


def read_track(path: Path) -> dict[str, list[dict[str, float]]]:
    """A fleet track (`--track` in fleet mode): each vehicle's rows by its name, every other
    column a number (an empty motor column of a vehicle with fewer rotors is left out) but
    `faults`, the fault events (text: `+motor_off:1@30.000 -link_loss@32.004`)."""
    by_vehicle: dict[str, list[dict[str, float]]] = {}
    with open(path) as f:
        for row in csv.DictReader(f):
            name = row.pop("vehicle")
            values = {k: float(v) for k, v in row.items() if v != "" and k != "faults"}
            by_vehicle.setdefault(name, []).append(values)
    return by_vehicle
