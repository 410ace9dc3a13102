"""Episode log of a training run and its learning-curve plot (PNG, matplotlib without a
display).

As a command it redraws the curve of one run, or of consecutive runs (a run continued with
train_sb3.py --init-from) as one curve, from their episodes.csv and summary.json:

    .venv/bin/python examples/train/learning_curve.py RUN [RUN ...] --out curve.png
"""

from __future__ import annotations

import argparse
import csv
import json
import sys
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np


@dataclass
class EpisodeLog:
    """One row per finished training episode: env steps so far, return, length, success."""

    steps: list[int] = field(default_factory=list)
    returns: list[float] = field(default_factory=list)
    lengths: list[int] = field(default_factory=list)
    successes: list[bool] = field(default_factory=list)

    def add(self, step: int, episode_return: float, length: int, success: bool) -> None:
        self.steps.append(int(step))
        self.returns.append(float(episode_return))
        self.lengths.append(int(length))
        self.successes.append(bool(success))

    def __len__(self) -> int:
        return len(self.steps)

    def write_csv(self, path: Path) -> None:
        with open(path, "w", newline="") as f:
            out = csv.writer(f)
            out.writerow(["env_steps", "return", "length", "success"])
            out.writerows(
                zip(self.steps, self.returns, self.lengths, map(int, self.successes), strict=True)
            )


def read_runs(folders: list[Path]) -> tuple[EpisodeLog, list[dict]]:
    """The episode logs of consecutive runs as one log (each run's env steps counted on from
    the end of the run before), and the runs' summaries."""
    log, summaries, offset = EpisodeLog(), [], 0
    for folder in folders:
        summary = json.loads((Path(folder) / "summary.json").read_text())
        with open(Path(folder) / "episodes.csv", newline="") as f:
            for row in csv.DictReader(f):
                log.add(
                    offset + int(row["env_steps"]),
                    float(row["return"]),
                    int(row["length"]),
                    row["success"] == "1",
                )
        offset += int(summary["timesteps"])
        summaries.append(summary)
    return log, summaries


def rolling_mean(values: list[float], window: int) -> np.ndarray:
    """Mean of the last `window` values at each index (fewer at the start)."""
    x = np.asarray(values, dtype=float)
    if x.size == 0:
        return x
    cumulative = np.concatenate([[0.0], np.cumsum(x)])
    hi = np.arange(1, x.size + 1)
    lo = np.maximum(0, hi - window)
    return (cumulative[hi] - cumulative[lo]) / (hi - lo)


def plot_learning_curve(
    log: EpisodeLog,
    path: Path,
    *,
    title: str,
    random_return: float | None = None,
    window: int = 50,
) -> Path:
    """Episode returns (dots), their rolling mean, the random policy's mean return, and the
    rolling success rate, against env steps."""
    from matplotlib.figure import Figure

    fig = Figure(figsize=(8, 6), layout="constrained")
    top, bottom = fig.subplots(2, 1, sharex=True, height_ratios=[2, 1])
    top.plot(log.steps, log.returns, ".", ms=2, alpha=0.3, color="tab:blue", label="episode")
    top.plot(
        log.steps,
        rolling_mean(log.returns, window),
        color="tab:blue",
        label=f"mean of last {window} episodes",
    )
    if random_return is not None:
        top.axhline(random_return, ls="--", color="tab:red", label="random policy")
    top.set_ylabel("episode return")
    top.set_title(title)
    top.legend(loc="lower right")
    top.grid(alpha=0.3)
    bottom.plot(
        log.steps,
        100.0 * rolling_mean([float(s) for s in log.successes], window),
        color="tab:green",
    )
    bottom.set_ylabel(f"success, % (last {window})")
    bottom.set_ylim(-3, 103)
    bottom.set_xlabel("env steps")
    bottom.grid(alpha=0.3)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=100)
    return path


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[1])
    parser.add_argument("runs", type=Path, nargs="+", help="train_sb3.py output folders, in order")
    parser.add_argument("--out", type=Path, required=True, help="PNG to write")
    args = parser.parse_args(argv)
    log, summaries = read_runs(args.runs)
    first = summaries[0]
    steps = sum(int(s["timesteps"]) for s in summaries)
    wall = sum(float(s["wall_time_s"]) for s in summaries)
    runs = f"{len(summaries)} runs, " if len(summaries) > 1 else ""
    title = (
        f"{first['algo'].upper()} on {first['env_id']} ({first['env']}, {runs}"
        f"{first['n_envs']} envs, {steps:,} steps, {wall:.0f} s)"
    )
    args.out.parent.mkdir(parents=True, exist_ok=True)
    plot_learning_curve(log, args.out, title=title, random_return=first["random_mean_return"])
    print(f"{len(log)} episodes of {len(summaries)} run(s) drawn to {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
