"""Episode log of a training run and its learning-curve plot (PNG, matplotlib without a
display)."""

from __future__ import annotations

import csv
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
