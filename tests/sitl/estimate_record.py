"""An autopilot's position estimate beside flyloop's ground truth, for the estimate-vs-truth
flights of tests/px4 and tests/ardupilot: a recorder of the estimates an autopilot sends
(whatever else the test reads from the same link), their comparison with flyloop's track at
the same instants, a CSV of both, and its plot (examples/estimate_plot.py)."""

from __future__ import annotations

import bisect
import csv
import math
import os
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path

PLOT = Path(__file__).resolve().parents[2] / "examples" / "estimate_plot.py"
COLUMNS = ("time_s", "est_north", "est_east", "est_down", "north", "east", "down", "grounded")

# The flight both autopilots fly: after arming and the takeoff (CLIMB_S), legs to these
# points (north, east of home, m), each held until LEG_S after its start, the landing, and
# GROUND_S on the ground after the disarm: about 5 minutes from arming.
LEGS = ((10.0, 0.0), (10.0, 10.0), (0.0, 10.0), (0.0, 0.0))
CLIMB_S = 35.0
LEG_S = 45.0
GROUND_S = 60.0
HEIGHT_LIMIT = 0.15
HORIZONTAL_LIMIT = 0.3


def fly_square(autopilot, recorder: Recorder, goto, land) -> None:
    """After the takeoff command: the climb, the legs (`goto(north, east)` of home), `land()`, the
    autopilot's own disarm and the minute on the ground, timed by the autopilot's clock."""
    end = recorder.now_ms() + CLIMB_S * 1000
    recorder.wait_until(end, autopilot)
    for north, east in LEGS:
        goto(north, east)
        end += LEG_S * 1000
        recorder.wait_until(end, autopilot)
    land()
    autopilot.wait_for(
        "the automatic disarm after landing",
        lambda m: m.get_srcSystem() == autopilot.target and not autopilot.armed(m),
        90,
        "HEARTBEAT",
    )
    recorder.wait_until(recorder.now_ms() + GROUND_S * 1000, autopilot)


def flyloop_args() -> list[str]:
    """flyloop-sitl's options for the flight: `--config FILE` with FLYLOOP_ESTIMATE_CONFIG."""
    config = os.environ.get("FLYLOOP_ESTIMATE_CONFIG")
    return ["--config", config] if config else []


class Recorder:
    """Keeps every message of `kind` that arrives on a pymavlink `link`, as `convert(message)`
    → (time_ms, north, east, down) or None, while the test reads the link as usual."""

    def __init__(self, link, kind: str, convert):
        self.kind = kind
        self.samples: list[tuple[int, float, float, float]] = []
        receive = link.recv_msg

        def recv_msg():
            m = receive()
            if m is not None and m.get_type() == kind:
                sample = convert(m)
                if sample is not None:
                    self.samples.append(sample)
            return m

        link.recv_msg = recv_msg

    def now_ms(self) -> int:
        """The autopilot's clock at its latest estimate (0 before the first)."""
        return self.samples[-1][0] if self.samples else 0

    def wait_until(self, ms: float, autopilot) -> None:
        """Reads the link on (the test's `autopilot.wait_for`) until the autopilot's clock
        reaches `ms`."""
        while self.now_ms() < ms:
            autopilot.wait_for(f"a {self.kind}", lambda m: True, 30, self.kind)


@dataclass(frozen=True)
class Comparison:
    """The estimates (in flyloop's frame: north, east, down from its home, of the centre of
    mass, m) beside the truth at the same instants."""

    rows: list[dict[str, float]]

    def height_errors(self) -> list[float]:
        """Estimated height − true height, m, per sample."""
        return [r["down"] - r["est_down"] for r in self.rows]

    def horizontal_errors(self) -> list[float]:
        rows = self.rows
        return [math.hypot(r["est_north"] - r["north"], r["est_east"] - r["east"]) for r in rows]

    def worst(self) -> tuple[float, float]:
        """Largest |height error| and horizontal error, m."""
        return max(map(abs, self.height_errors())), max(self.horizontal_errors())

    def write(self, path: Path) -> None:
        with open(path, "w", newline="") as f:
            w = csv.writer(f)
            w.writerow(COLUMNS)
            for r in self.rows:
                w.writerow([f"{r[c]:.4f}" for c in COLUMNS])

    def plot(self, csv_path: Path, png: Path, autopilot: str) -> None:
        """Writes the CSV and draws it (the script docs/px4.md and docs/ardupilot.md show)."""
        self.write(csv_path)
        subprocess.run([sys.executable, str(PLOT), str(csv_path), str(png), autopilot], check=True)
        assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def compare(
    track: list[dict[str, float]], samples: list[tuple[int, float, float, float]], since_ms: int
) -> Comparison:
    """Each estimate from `since_ms` on that falls within the track (the autopilot's clock is
    flyloop's simulation time), beside the truth interpolated between the track's rows."""
    times = [r["time_us"] / 1000 for r in track]
    rows = []
    for t, n, e, d in samples:
        if t < since_ms or not times[0] <= t <= times[-1]:
            continue
        i = min(max(bisect.bisect_left(times, t), 1), len(times) - 1)
        a, b = track[i - 1], track[i]
        w = (t - times[i - 1]) / (times[i] - times[i - 1])
        truth = {k: a[k] + w * (b[k] - a[k]) for k in ("north", "east", "down")}
        grounded = a["grounded"] if w < 0.5 else b["grounded"]
        rows.append(
            {
                "time_s": t / 1000,
                "est_north": n,
                "est_east": e,
                "est_down": d,
                **truth,
                "grounded": grounded,
            }
        )
    return Comparison(rows)


def check_flight(flight: Comparison, autopilot: str, takeoff_alt: float) -> None:
    """Plots the flight into FLYLOOP_ESTIMATE_OUT (if set: NAME_estimate.csv and .png), checks
    that it flew (5 minutes compared, up at the takeoff height, around the square, the last
    minute on the ground), then that the estimate kept within the limits throughout."""
    out = os.environ.get("FLYLOOP_ESTIMATE_OUT")
    if out:
        name = autopilot.lower()
        Path(out).mkdir(parents=True, exist_ok=True)
        flight.plot(
            Path(out) / f"{name}_estimate.csv", Path(out) / f"{name}_estimate.png", autopilot
        )
    rows = flight.rows
    assert rows[-1]["time_s"] - rows[0]["time_s"] > 270, (rows[0], rows[-1])
    assert max(-r["down"] for r in rows) > takeoff_alt - 0.5
    assert max(math.hypot(r["north"], r["east"]) for r in rows) > 13.0
    assert all(r["grounded"] for r in rows if r["time_s"] > rows[-1]["time_s"] - GROUND_S)
    height, horizontal = flight.worst()
    print(f"{autopilot} estimate vs truth: |height| {height:.3f} m, horizontal {horizontal:.3f} m")
    assert height <= HEIGHT_LIMIT, f"height error {height:.3f} m"
    assert horizontal <= HORIZONTAL_LIMIT, f"horizontal error {horizontal:.3f} m"
