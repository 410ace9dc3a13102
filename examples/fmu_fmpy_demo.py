"""Quadrotor.fmu in fmpy: hover for 2 s, then all four motors 0.03 above hover; plots the
result to runs/demo/fmu_hover.png (docs/fmu.md's figure: ``--out docs/img/fmu_hover.png``).

    bash scripts/pack-fmus.sh && .venv/bin/python examples/fmu_fmpy_demo.py
"""

import argparse
from pathlib import Path

import numpy as np
from fmpy import simulate_fmu
from matplotlib.figure import Figure

ROOT = Path(__file__).resolve().parents[1]
HOVER = (9.81 / 40) ** 0.5  # motor state that carries 1 kg with k = 10 N per motor


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    # runs/ is git-ignored: running the demo leaves the checkout clean.
    parser.add_argument("--out", type=Path, default=ROOT / "runs" / "demo" / "fmu_hover.png")
    args = parser.parse_args(argv)
    # Motor commands, no external wind (the model's own wind still blows), healthy motors.
    names = [f"motor_command_{i}" for i in range(4)] + [f"wind_input_{a}" for a in "xyz"]
    names += [f"motor_effectiveness_{i}" for i in range(4)]
    rows = [(0, *[HOVER] * 4), (2, *[HOVER] * 4), (2, *[HOVER + 0.03] * 4)]
    rows.append((6, *[HOVER + 0.03] * 4))
    rows = [(*row, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 1.0) for row in rows]
    u = np.array(rows, dtype=[("time", float)] + [(n, float) for n in names])
    result = simulate_fmu(
        str(ROOT / "dist" / "fmu" / "Quadrotor.fmu"),
        stop_time=6,
        output_interval=0.01,
        start_values={"initial_motor": HOVER, "seed": 1},
        input=u,
        output=["z", "vz", "x", "y", "wind_x", "wind_y", "motor_state_0"],
    )
    t = result["time"]
    fig = Figure(figsize=(8, 7))
    axes = fig.subplots(3, 1, sharex=True)
    axes[0].plot(t, result["z"], label="z (height)")
    axes[0].plot(t, result["vz"], label="vz")
    axes[0].set_ylabel("m, m/s")
    axes[1].plot(t, result["x"], label="x (east)")
    axes[1].plot(t, result["y"], label="y (north)")
    axes[1].plot(t, result["wind_x"], "--", label="wind_x")
    axes[1].plot(t, result["wind_y"], "--", label="wind_y")
    axes[1].set_ylabel("m, m/s")
    axes[2].plot(t, result["motor_state_0"], label="motor_state_0")
    axes[2].axhline(HOVER, color="grey", lw=0.8, label="hover")
    axes[2].set_ylabel("1")
    axes[2].set_xlabel("time (s)")
    for ax in axes:
        ax.grid(True, alpha=0.3)
        ax.legend(loc="upper left", fontsize=8)
    fig.suptitle("Quadrotor.fmu in fmpy: hover, then +0.03 on every motor at t = 2 s")
    fig.tight_layout()
    args.out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(args.out, dpi=100)
    print(args.out)


if __name__ == "__main__":
    main()
