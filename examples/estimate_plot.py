"""Plots an autopilot's position estimate against flyloop's ground truth, from the CSV the
estimate-vs-truth system tests write (tests/px4/test_px4_estimate.py,
tests/ardupilot/test_ardupilot_estimate.py; columns time_s, est_north, est_east, est_down,
north, east, down, grounded: m in flyloop's frame, north/east/down from its home).

    .venv/bin/python examples/estimate_plot.py estimate.csv docs/img/px4_estimate.png PX4

Top: true and estimated height above home. Bottom: estimated − true height and the
horizontal distance between estimate and truth, with the limits the tests hold (0.15 m,
0.3 m); shaded: the vehicle on the ground.
"""

from __future__ import annotations

import csv
import math
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

HEIGHT_LIMIT = 0.15
HORIZONTAL_LIMIT = 0.3


def read(path: Path) -> list[dict[str, float]]:
    with open(path) as f:
        return [{k: float(v) for k, v in row.items()} for row in csv.DictReader(f)]


def shade_ground(ax, rows: list[dict[str, float]]) -> None:
    """Shades the spans in which the vehicle stands on its feet."""
    start = None
    for r in rows + [{"time_s": rows[-1]["time_s"], "grounded": 0.0}]:
        if r["grounded"] and start is None:
            start = r["time_s"]
        elif not r["grounded"] and start is not None:
            ax.axvspan(start, r["time_s"], color="0.9", lw=0)
            start = None


def plot(rows: list[dict[str, float]], out: Path, autopilot: str) -> None:
    t = [r["time_s"] for r in rows]
    height = [r["down"] - r["est_down"] for r in rows]
    horizontal = [math.hypot(r["est_north"] - r["north"], r["est_east"] - r["east"]) for r in rows]
    fig, (top, bottom) = plt.subplots(2, 1, figsize=(10, 6), dpi=100, sharex=True)
    for ax in (top, bottom):
        shade_ground(ax, rows)
        ax.grid(True)
    top.plot(t, [-r["down"] for r in rows], label="flyloop's truth")
    top.plot(t, [-r["est_down"] for r in rows], "--", label=f"{autopilot}'s estimate")
    top.set(ylabel="height above home (m)", title=f"{autopilot} on flyloop: estimate vs truth")
    top.legend(fontsize=8)
    bottom.plot(t, height, label=f"height error (max |{max(map(abs, height)):.3f}| m)")
    bottom.plot(t, horizontal, label=f"horizontal error (max {max(horizontal):.3f} m)")
    lim = max(0.4, 1.1 * max(max(map(abs, height)), max(horizontal)))
    bottom.axhline(HEIGHT_LIMIT, color="k", ls=":", lw=0.8, label=f"height limit ±{HEIGHT_LIMIT} m")
    bottom.axhline(-HEIGHT_LIMIT, color="k", ls=":", lw=0.8)
    bottom.axhline(HORIZONTAL_LIMIT, color="k", ls="-.", lw=0.8, label="horizontal limit")
    bottom.set(
        xlabel=f"simulation time (s) = {autopilot}'s clock; shaded: on the ground",
        ylabel="estimate − truth (m)",
        ylim=(-lim, lim),
    )
    bottom.legend(fontsize=8, loc="lower left")
    fig.tight_layout()
    fig.savefig(out)
    plt.close(fig)


def main() -> None:
    if len(sys.argv) != 4:
        sys.exit("usage: estimate_plot.py ESTIMATE.csv OUT.png AUTOPILOT")
    plot(read(Path(sys.argv[1])), Path(sys.argv[2]), sys.argv[3])


if __name__ == "__main__":
    main()
