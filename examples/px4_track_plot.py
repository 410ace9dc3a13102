"""Plots a PX4 (or ArduPilot) flight on flyloop from the ground-truth track of
`flyloop-sitl --px4 --track` (or `--ardupilot --track`: the same columns).

    .venv/bin/python examples/px4_track_plot.py track.csv docs/img/px4_mission.png
    .venv/bin/python examples/px4_track_plot.py track.csv mission.png ArduPilot

Left: the path seen from above (north up). Right: height above home and motor states over
simulation time. One line per PX4 connection. A track the SITL is still writing can be
plotted: its complete rows are.
"""

from __future__ import annotations

import csv
import io
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

# The columns the plot draws (flyloop-sitl --track writes them, among others).
COLUMNS = {"connection", "time_us", "north", "east", "down", "m0"}


def read(path: Path) -> tuple[list[dict[str, float]], bool]:
    """The track's complete rows, and whether a partial last row was left out: the SITL may
    still be writing the file (it writes whole buffers, which end anywhere in a row)."""
    text = path.read_text()
    partial = not text.endswith("\n")
    if partial:
        text = text[: text.rfind("\n") + 1]
    rows = [
        {k: float(v) for k, v in row.items() if k != "faults"}  # `faults`: event text
        for row in csv.DictReader(io.StringIO(text))
    ]
    return rows, partial and bool(rows)


def plot(rows: list[dict[str, float]], out: Path, autopilot: str = "PX4") -> None:
    fig, (top, side) = plt.subplots(1, 2, figsize=(10, 4), dpi=100)
    for connection in sorted({r["connection"] for r in rows}):
        flight = [r for r in rows if r["connection"] == connection]
        label = f"{autopilot} connection {int(connection)}"
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
    if len(sys.argv) not in (3, 4):
        sys.exit("usage: px4_track_plot.py TRACK.csv OUT.png [AUTOPILOT (default PX4)]")
    track, out = Path(sys.argv[1]), Path(sys.argv[2])
    try:
        rows, partial = read(track)
    except (OSError, ValueError) as exc:
        sys.exit(f"px4_track_plot.py: cannot read {track}: {exc}")
    if not rows:
        sys.exit(f"px4_track_plot.py: {track} has no complete row yet")
    missing = sorted(COLUMNS - set(rows[0]))
    if missing:
        sys.exit(f"px4_track_plot.py: {track} is not a flyloop-sitl --track file: no {missing}")
    plot(rows, out, *sys.argv[3:])
    note = " (its last row, still being written, left out)" if partial else ""
    print(f"plotted {len(rows)} rows of {track}{note} to {out}")


if __name__ == "__main__":
    main()
