"""The training table of the README: fast_ppo.py on hover and both landers, three training
seeds each, one run per cell, on this machine.

    .venv/bin/python examples/train/training_table.py [--seeds 0 1 2] [--tasks hover lander
        lander_moving] [--jobs 1] [--out runs/training_table] [--timesteps N]

Each cell is `fast_ppo.py --env TASK --seed S --out OUT/TASK_sS` with the task's own settings
(TASKS in fast_ppo.py); the table reads the runs' summary.json: env steps, wall seconds of
training (the evaluation after it not included), and the held-out success on the task's
evaluation episodes (seeds from 1,000,000, which training never uses). `--jobs 2` trains two
runs at a time (one per core: each run's learner is one torch thread); the table says which.
Prints a Markdown table and writes it to OUT/table.md with the machine's CPU and load.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

HERE = Path(__file__).resolve().parent


def cpu_model() -> str:
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return "unknown CPU"


def train(task: str, seed: int, out: Path, timesteps: int | None) -> dict:
    folder = out / f"{task}_s{seed}"
    command = [sys.executable, str(HERE / "fast_ppo.py"), "--env", task, "--seed", str(seed)]
    command += ["--out", str(folder), "--no-progress-bar"]
    if timesteps is not None:
        command += ["--timesteps", str(timesteps)]
    done = subprocess.run(command, capture_output=True, text=True)
    if done.returncode != 0:
        raise RuntimeError(f"{' '.join(command)} failed:\n{done.stderr[-3000:]}")
    return json.loads((folder / "native" / "summary.json").read_text())


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--tasks", nargs="+", default=["hover", "lander", "lander_moving"])
    parser.add_argument("--seeds", nargs="+", type=int, default=[0, 1, 2])
    parser.add_argument("--jobs", type=int, default=1, help="runs trained at the same time")
    parser.add_argument("--out", type=Path, default=Path("runs/training_table"))
    parser.add_argument(
        "--timesteps", type=int, help="env steps of every run (default: each task's own)"
    )
    args = parser.parse_args(argv)
    if args.jobs < 1:
        parser.error("--jobs must be at least 1")
    load = os.getloadavg()[0]
    start = time.perf_counter()
    cells = [(task, seed) for task in args.tasks for seed in args.seeds]
    with ThreadPoolExecutor(args.jobs) as pool:
        summaries = list(pool.map(lambda c: train(c[0], c[1], args.out, args.timesteps), cells))
    by_cell = dict(zip(cells, summaries, strict=True))
    lines = [
        f"{cpu_model()}, {os.cpu_count()} CPUs, load {load:.2f} at the start, "
        f"{args.jobs} run(s) at a time; {time.perf_counter() - start:.0f} s in all",
        "",
        "| task | env steps | training time, s (seeds " + ", ".join(map(str, args.seeds)) + ") "
        "| held-out success (episodes) | command |",
        "|---|---|---|---|---|",
    ]
    for task in args.tasks:
        runs = [by_cell[(task, seed)] for seed in args.seeds]
        steps = sorted({r["env_steps"] for r in runs})
        walls = " / ".join(f"{r['wall_time_s']:.0f}" for r in runs)
        rates = " / ".join(f"{100 * r['evaluation']['success_rate']:.1f} %" for r in runs)
        episodes = runs[0]["evaluation"]["episodes"]
        name = runs[0]["env_id"].split("/")[-1]
        lines.append(
            f"| {name} (`{task}`) | {', '.join(f'{s:,}' for s in steps)} | {walls} "
            f"| {rates} ({episodes}) | `fast_ppo.py --env {task} --seed S` |"
        )
    table = "\n".join(lines)
    print(table)
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / "table.md").write_text(table + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
