"""What the fleet flight benchmarks (fleet_px4.py, fleet_ardupilot.py) report of a run: its
figures from flyloop's stop line and /proc, and the one line a run prints."""

from __future__ import annotations

import os
import time


def fleet_result(sitl, worst: float, cpu_flyloop: float, cpu_autopilots: float) -> dict:
    """A stopped fleet's run: the worst hold error `worst` (m), flyloop's counters, the CPU
    seconds of flyloop and of all the autopilots, and flyloop's share of them."""
    c = sitl.counters()
    return {
        "worst_m": worst,
        "rtf": float(c["real_time_factor"]),
        "sim_s": float(c["time_s"]),
        "cpu_flyloop_s": cpu_flyloop,
        "cpu_autopilots_s": cpu_autopilots,
        "share": cpu_flyloop / (cpu_flyloop + cpu_autopilots),
        "silenced": sitl.stderr().count("silent for"),
    }


def held(r: dict) -> bool:
    """Every vehicle held within 0.3 m and no autopilot fell silent."""
    return r["worst_m"] <= 0.3 and r["silenced"] == 0


def run_line(k: int, n: int, autopilot: str, r: dict, start: float) -> str:
    """Run `k`'s line for `n` vehicles flown by `autopilot` ("PX4", "ArduPilot"), begun at
    `start` (time.monotonic())."""
    return (
        f"run {k + 1}: {n} {autopilot}s {'all held 5 m and landed' if held(r) else 'FAILED'}"
        f" worst {r['worst_m']:.3f} m, world {r['sim_s']:.1f} s at {r['rtf']:.2f}x real"
        f" time, CPU flyloop {r['cpu_flyloop_s']:.1f} s / {autopilot}s"
        f" {r['cpu_autopilots_s']:.1f} s (flyloop {100 * r['share']:.1f} %,"
        f" {r['cpu_autopilots_s'] / n:.1f} s per {autopilot}), silenced {r['silenced']},"
        f" wall {time.monotonic() - start:.0f} s, load {os.getloadavg()[0]:.2f}"
    )
