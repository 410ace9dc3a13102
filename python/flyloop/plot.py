"""python -m flyloop.plot FILE [-o PNG] [--ulg PX4.ulg]: a PNG of a recording over
simulation time — position, attitude, body rates and motor commands — with an autopilot's
estimate beside the truth where the recording has one (or from PX4's own log, --ulg).

FILE is a recording: .rrd (python -m flyloop.view --save, flyloop.view.Watch) or .tlog
(flyloop-sitl --record). docs/view.md."""

from __future__ import annotations

import argparse
import math
import sys
import tempfile
from collections import defaultdict
from pathlib import Path

import numpy as np

GROUPS = (
    ("position", "position NED (m)", ("N", "E", "D")),
    ("attitude", "attitude (deg)", ("roll", "pitch", "yaw")),
    ("rates", "body rates FRD (deg/s)", ("p", "q", "r")),
)


class PlotError(RuntimeError):
    """A file the plot cannot read, in one line."""


def _columns(path: str | Path, column: str):
    """(entity path, sim times s, values) of every chunk of an .rrd on the simulation clock
    that holds `column` (e.g. "Scalars:scalars")."""
    from .view import read_recording

    try:
        chunks = read_recording(path)
    except Exception as e:
        raise PlotError(f"{path}: not a readable Rerun recording ({e})") from None
    for c in chunks:
        if "sim_time" not in c.timeline_names:
            continue
        batch = c.to_record_batch()
        if column not in batch.schema.names:
            continue
        t = batch.column("sim_time").cast("int64").to_numpy(zero_copy_only=False) / 1e9
        yield str(c.entity_path), t, batch.column(column).to_pylist()


def series_of_rrd(path: str | Path) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """Entity path -> (sim time s, value) of every scalar series in an .rrd."""
    parts: dict[str, list] = defaultdict(list)
    for name, t, values in _columns(path, "Scalars:scalars"):
        width = max((len(x) for x in values if x), default=1)
        for i in range(width):
            v = [x[i] if x and len(x) > i else math.nan for x in values]
            parts[_series_name(name, i, width)].append((t, np.asarray(v, float)))
    out = {}
    for name, pieces in parts.items():
        t = np.concatenate([p[0] for p in pieces])
        v = np.concatenate([p[1] for p in pieces])
        order = np.argsort(t, kind="stable")
        out[name] = (t[order], v[order])
    return out


# The view logs a group's series as one entity (scene.Scene._series): its i-th value is
# the series named here, the names the view's recordings had when each was its own entity.
_AXES = {"position": "NED", "attitude": ("roll", "pitch", "yaw"), "rates": "pqr"}


def _series_name(path: str, i: int, width: int) -> str:
    if width == 1:
        return path
    root = path.split("/")[1]
    if root in _AXES:
        prefix, kind = path.rsplit("/", 1)
        return f"{prefix}/{_AXES[root][i]}/{kind}"
    if root == "motors":
        return f"{path}/m{i}"
    return f"{path}/{'xyz'[i]}" if width == 3 else f"{path}/{i}"


def events_of_rrd(path: str | Path) -> list[tuple[float, str, str]]:
    """(sim time s, entity path, text) of every event (text log line) in an .rrd, in time
    order: collisions, faults that fired or ended, what a fleet and its autopilots said."""
    out = []
    for name, t, texts in _columns(path, "TextLog:text"):
        out += [(float(ti), name, x[0] if x else "") for ti, x in zip(t, texts, strict=True)]
    return sorted(out, key=lambda e: e[0])


def series_of(path: str | Path) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """The scalar series of a recording: an .rrd as it is, a .tlog drawn into one first (the
    view's own scene, so the plot shows what the view shows)."""
    return _read_as_rrd(path, series_of_rrd)


def events_of(path: str | Path) -> list[tuple[float, str, str]]:
    """The events of a recording (see `events_of_rrd`), an .rrd or a .tlog."""
    return _read_as_rrd(path, events_of_rrd)


def _read_as_rrd(path: str | Path, read):
    """`read(rrd)` of a recording: an .rrd as it is, a .tlog replayed into one first."""
    path = Path(path)
    if not path.is_file():
        raise PlotError(f"{path}: no such file")
    if path.suffix != ".tlog":
        return read(path)
    from .view import Viewer, ViewError

    with tempfile.TemporaryDirectory() as tmp:
        rrd = Path(tmp) / "tlog.rrd"
        viewer = Viewer(serve=False, save=rrd)
        try:
            viewer.replay(path)
        except ViewError as e:
            raise PlotError(str(e)) from None
        viewer.close()
        del viewer
        return read(rrd)


def series_of_ulg(path: str | Path) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """PX4's estimate from its .ulg (vehicle_local_position, vehicle_attitude,
    vehicle_angular_velocity) as series named like the view's (`.../estimate`)."""
    from pyulog import ULog

    from .view.scene import euler_ned

    try:
        log = ULog(
            str(path), ["vehicle_local_position", "vehicle_attitude", "vehicle_angular_velocity"]
        )
    except Exception as e:
        raise PlotError(f"{path}: not a readable PX4 log ({e})") from None
    out = {}
    for d in log.data_list:
        t, f = d.data["timestamp"] / 1e6, d.data
        if d.name == "vehicle_local_position":
            for axis, key in zip("NED", "xyz", strict=True):
                out[f"/position/vehicle1/{axis}/estimate"] = (t, f[key])
        elif d.name == "vehicle_attitude":
            q = np.c_[f["q[0]"], f["q[1]"], f["q[2]"], f["q[3]"]]
            e = np.degrees(np.array([euler_ned(row) for row in q]))
            for i, axis in enumerate(("roll", "pitch", "yaw")):
                out[f"/attitude/vehicle1/{axis}/estimate"] = (t, e[:, i])
        elif d.name == "vehicle_angular_velocity":
            for axis, key in zip("pqr", ("xyz[0]", "xyz[1]", "xyz[2]"), strict=True):
                out[f"/rates/vehicle1/{axis}/estimate"] = (t, np.degrees(f[key]))
    return out


def plot(series: dict, png: str | Path, title: str) -> Path:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    names = sorted({k.split("/")[2] for k in series if k.startswith(("/position/", "/attitude/"))})
    if not names:
        raise PlotError(f"{title}: no vehicle in it (no position or attitude series)")
    name = names[0]
    fig, axes = plt.subplots(4, 1, figsize=(10, 11), sharex=True)
    for ax, (group, label, axis_names) in zip(axes, GROUPS, strict=False):
        for axis, color in zip(axis_names, ("tab:red", "tab:green", "tab:blue"), strict=True):
            for kind, style in (("truth", "-"), ("estimate", "--")):
                key = f"/{group}/{name}/{axis}/{kind}"
                if key in series:
                    t, v = series[key]
                    ax.plot(t, v, style, color=color, lw=1.2, label=f"{axis} {kind}")
        ax.set_ylabel(label)
        ax.grid(alpha=0.3)
        if ax.lines:
            ax.legend(loc="upper right", fontsize=7, ncol=2)
        else:  # e.g. a gym env's recording: the envs report no body rates
            ax.text(0.5, 0.5, "not in this recording", transform=ax.transAxes, ha="center")
    # flyloop's motor commands (/motors/vehicle1_m0) and an autopilot's outputs
    # (/motors/vehicle1_autopilot/m0, all its 16 channels): the unused ones (never above 0)
    # left out, the autopilot's labelled as such.
    motors = []
    for key in sorted(k for k in series if k.startswith(f"/motors/{name}_")):
        t, v = series[key]
        if not np.any(np.asarray(v) > 0):
            continue
        source = "autopilot " if "_autopilot/" in key else ""
        axes[3].plot(t, v, lw=1.0, label=f"{source}{key.split('/')[-1].split('_')[-1]}")
        motors.append(key)
    axes[3].set_ylabel("motor commands [0, 1]")
    axes[3].set_xlabel("simulation time (s)")
    axes[3].grid(alpha=0.3)
    if motors:
        axes[3].legend(loc="upper right", fontsize=7, ncol=4)
    fig.suptitle(f"{title}: {name}")
    fig.tight_layout()
    png = Path(png)
    fig.savefig(png, dpi=90)
    plt.close(fig)
    return png


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog="python -m flyloop.plot", description=__doc__.split("\n\n")[0])
    p.add_argument("file", help="a recording: .rrd or .tlog")
    p.add_argument("-o", "--output", help="the PNG to write (default: FILE with .png)")
    p.add_argument("--ulg", help="PX4's log of the same flight: its estimate beside the truth")
    args = p.parse_args(argv)
    png = args.output or str(Path(args.file).with_suffix(".png"))
    try:
        series = series_of(args.file)
        if args.ulg:
            series.update(series_of_ulg(args.ulg))
        out = plot(series, png, Path(args.file).name)
    except PlotError as e:
        print(f"flyloop.plot: {e}", file=sys.stderr)
        return 1
    print(f"flyloop.plot: wrote {out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
