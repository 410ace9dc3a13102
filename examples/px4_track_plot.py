"""Plots a PX4 flight on flyloop from the ground-truth track of `flyloop-sitl --px4 --track`.

    .venv/bin/python examples/px4_track_plot.py track.csv docs/img/px4_mission.png

Left: the path seen from above (north up). Right: height above home and motor states over
simulation time. One line per PX4 connection.
"""

from __future__ import annotations

import csv
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def read(path: Path) -> list[dict[str, float]]:
    with open(path) as f:
        return [{k: float(v) for k, v in row.items()} for row in csv.DictReader(f)]


def plot(rows: list[dict[str, float]], out: Path) -> None:
    fig, (top, side) = plt.subplots(1, 2, figsize=(10, 4), dpi=100)
    for connection in sorted({r["connection"] for r in rows}):
        flight = [r for r in rows if r["connection"] == connection]
        label = f"PX4 connection {int(connection)}"
        top.plot([r["east"] for r in flight], [r["north"] for r in flight], label=label)
        t = [r["time_us"] * 1e-6 for r in flight]
        side.plot(t, [-r["down"] for r in flight], label=f"height ({label})")
        side.plot(t, [r["m0"] for r in flight], alpha=0.5, label="motor 0 state")
    top.set(xlabel="east (m)", ylabel="north (m)", title="path from above")
    top.set_aspect("equal", adjustable="datalim")
    top.grid(True)
    side.set(xlabel="simulation time (s)", ylabel="m / motor state", title="height above home")
    side.grid(True)
    side.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(out)
    plt.close(fig)


def main() -> None:
    if len(sys.argv) != 3:
        sys.exit("usage: px4_track_plot.py TRACK.csv OUT.png")
    plot(read(Path(sys.argv[1])), Path(sys.argv[2]))


if __name__ == "__main__":
    main()
