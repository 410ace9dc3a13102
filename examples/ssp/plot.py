"""Runs the examples/ssp systems in fmpy, ecos and libcosim and plots them: height, horizontal
position and yaw over time, one colour per engine, one column per system (the controller
systems, then the policy systems), the target dotted in grey.

Usage: .venv/bin/python examples/ssp/plot.py [--fmus dist/fmu] [--out runs/ssp/closed_loops.png]
"""

import argparse
import sys
import tempfile
from pathlib import Path

import matplotlib
import numpy as np

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent))
import build  # noqa: E402
import engines  # noqa: E402
from systems import SYSTEMS  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
STYLE = {
    "fmpy": {"color": "tab:blue"},
    "ecos": {"color": "tab:orange", "linestyle": "--"},
    "libcosim": {"color": "tab:green", "linestyle": ":"},
}


def targets(system) -> dict[str, float]:
    """The target a system's controller or policy is given: {"x": .., "y": .., "z": ..}."""
    found = {}
    for component in system.components:
        for coordinate in "xyz":
            value = component.parameters.get(f"target_{coordinate}")
            if value is not None:
                found[coordinate] = value
    return found


def main(argv=None) -> Path:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--fmus", type=Path, default=ROOT / "dist" / "fmu")
    parser.add_argument("--out", type=Path, default=ROOT / "runs" / "ssp" / "closed_loops.png")
    args = parser.parse_args(argv)
    panels = [
        ("plant.z", "height z (m)"),
        ("plant.x", "x, y (m)"),
        ("plant.yaw", "yaw, unwrapped (rad)"),
    ]
    fig, axes = plt.subplots(len(panels), len(SYSTEMS), figsize=(16, 7.5), sharex="col")
    with tempfile.TemporaryDirectory() as tmp:
        for col, (name, system) in enumerate(SYSTEMS.items()):
            ssp = build.build(system, args.fmus, Path(tmp))
            for engine in engines.ENGINES:
                run = engines.run(ssp, engine, system.stop_time, system.step_size, system.watch)
                for row, (var, label) in enumerate(panels):
                    ax = axes[row, col]
                    # Yaw unwrapped: the offboard policy turns about its yaw axis as it flies.
                    values = np.unwrap(run[var]) if var == "plant.yaw" else run[var]
                    ax.plot(run["time"], values, label=f"{engine} {var[6:]}", **STYLE[engine])
                    if var == "plant.x":
                        ax.plot(
                            run["time"],
                            run["plant.y"],
                            label=f"{engine} y",
                            alpha=0.6,
                            **STYLE[engine],
                        )
                    ax.set_ylabel(label)
                    ax.grid(alpha=0.3)
            for row, coordinate in ((0, "z"), (1, "x"), (1, "y")):
                target = targets(system).get(coordinate)
                if target is not None:
                    axes[row, col].axhline(target, color="grey", linestyle=":", linewidth=1)
            axes[0, col].set_title(f"{name}.ssp", fontsize=10)
            axes[-1, col].set_xlabel("time (s)")
    for ax in axes.flat:
        ax.legend(fontsize=7, loc="best")
    fig.suptitle(
        "flyloop SSP systems in fmpy, ecos and libcosim: Quadrotor.fmu + RateController.fmu"
        " (+ AttitudeController.fmu); trained policies as FMUs (HexaHoverPolicy.fmu on"
        " Hexacopter.fmu; OffboardPolicy.fmu through RateController.fmu)",
        fontsize=10,
    )
    fig.tight_layout()
    args.out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(args.out, dpi=110)
    print(args.out)
    return args.out


if __name__ == "__main__":
    main()
