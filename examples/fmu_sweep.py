"""A parameter sweep of Quadrotor.fmu on Ray: mass × thrust coefficient → the hover motor
command (found by bisection on the FMU's vertical acceleration) and the climb after a +0.02
step on every motor. Each grid point is one Ray task; the FMU travels as bytes in Ray's
object store, so the same script runs on this machine or, with --address, on a Ray cluster
whose workers share no file system with the driver.

    bash scripts/pack-fmus.sh && .venv/bin/python examples/fmu_sweep.py
"""

import argparse
import shutil
import tempfile
from pathlib import Path

import numpy as np
import ray
from matplotlib.figure import Figure

ROOT = Path(__file__).resolve().parents[1]
STEP = 0.02  # motor command step above hover
DT = 0.01  # communication step, s
STEP_AT = 0.5  # time of the command step, s
STOP = 3.0  # end of the step response, s


@ray.remote
def sweep_point(fmu_bytes: bytes, mass: float, thrust: float) -> dict:
    """Hover command and step response of one (mass, thrust coefficient)."""
    from fmpy import extract, read_model_description
    from fmpy.fmi2 import FMU2Slave

    workdir = tempfile.mkdtemp(prefix="flyloop-sweep-")
    try:
        path = Path(workdir) / "Quadrotor.fmu"
        path.write_bytes(fmu_bytes)
        md = read_model_description(str(path))
        vr = {v.name: v.valueReference for v in md.modelVariables}
        slave = FMU2Slave(
            guid=md.guid,
            unzipDirectory=extract(str(path), unzipdir=str(Path(workdir) / "unzipped")),
            modelIdentifier=md.coSimulation.modelIdentifier,
            instanceName="sweep",
        )
        slave.instantiate()
        motors = [vr[f"motor_command_{i}"] for i in range(4)]

        def start(command: float) -> None:
            slave.reset()
            slave.setReal([vr["mass"], vr["thrust_coefficient"]], [mass, thrust])
            slave.setBoolean([vr["wind_enabled"]], [False])
            slave.setReal([vr["initial_motor"], vr["initial_z"]], [command, 10.0])
            slave.setupExperiment(startTime=0.0)
            slave.enterInitializationMode()
            slave.exitInitializationMode()
            slave.setReal(motors, [command] * 4)

        # Vertical acceleration grows with the command: bisect az = 0 on [0, 1].
        low, high = 0.0, 1.0
        for _ in range(60):
            middle = 0.5 * (low + high)
            start(middle)
            (az,) = slave.getReal([vr["az"]])
            low, high = (middle, high) if az < 0.0 else (low, middle)
        hover = 0.5 * (low + high)

        start(hover)
        times, heights = [], []
        n = round(STOP / DT)
        for k in range(n + 1):
            t = k * DT
            (z,) = slave.getReal([vr["z"]])
            times.append(t)
            heights.append(z - 10.0)
            if k == round(STEP_AT / DT):
                slave.setReal(motors, [hover + STEP] * 4)
            if k < n:
                slave.doStep(currentCommunicationPoint=t, communicationStepSize=DT)
        slave.terminate()
        slave.freeInstance()
        return {"mass": mass, "thrust": thrust, "hover": hover, "t": times, "dz": heights}
    finally:
        shutil.rmtree(workdir, ignore_errors=True)


def sweep(fmu: Path, masses: list[float], thrusts: list[float]) -> list[dict]:
    """Every (mass, thrust) point as a Ray task; results in grid order."""
    fmu_ref = ray.put(fmu.read_bytes())
    futures = [sweep_point.remote(fmu_ref, m, k) for m in masses for k in thrusts]
    return ray.get(futures)


def plot(results: list[dict], masses: list[float], thrusts: list[float], out: Path) -> None:
    grid = np.array([r["hover"] for r in results]).reshape(len(masses), len(thrusts))
    fig = Figure(figsize=(11, 4.5))
    left, right = fig.subplots(1, 2)
    image = left.imshow(grid, origin="lower", aspect="auto", cmap="viridis")
    left.set_xticks(range(len(thrusts)), [f"{k:g}" for k in thrusts])
    left.set_yticks(range(len(masses)), [f"{m:g}" for m in masses])
    left.set_xlabel("thrust_coefficient (N)")
    left.set_ylabel("mass (kg)")
    left.set_title("hover motor command")
    fig.colorbar(image, ax=left)
    colours = {m: c for m, c in zip(masses, ["C0", "C1", "C2", "C3", "C4", "C5"] * 9, strict=False)}
    for r in results:
        right.plot(r["t"], r["dz"], color=colours[r["mass"]], lw=0.9)
    for m in masses:
        right.plot([], [], color=colours[m], label=f"mass {m:g} kg")
    right.set_xlabel("time (s)")
    right.set_ylabel("height change (m)")
    right.set_title(f"climb after +{STEP} on every motor at t = {STEP_AT} s")
    right.grid(True, alpha=0.3)
    right.legend(fontsize=8)
    fig.suptitle("Quadrotor.fmu sweep on Ray: mass × thrust coefficient")
    fig.tight_layout()
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=90)


def numbers(text: str) -> list[float]:
    return [float(x) for x in text.split(",")]


def main(argv: list[str] | None = None) -> list[dict]:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--fmu", type=Path, default=ROOT / "dist" / "fmu" / "Quadrotor.fmu")
    parser.add_argument("--masses", type=numbers, default=numbers("0.6,0.8,1.0,1.2,1.4"))
    parser.add_argument("--thrust", type=numbers, default=numbers("6,8,10,12,14"))
    parser.add_argument("--address", help="Ray cluster to join (default: a local one)")
    parser.add_argument("--num-cpus", type=int, help="CPUs of the local Ray instance")
    parser.add_argument("--out", type=Path, default=ROOT / "docs" / "img" / "fmu_sweep.png")
    args = parser.parse_args(argv)
    if args.address:
        ray.init(address=args.address)
    else:
        # address="local": a fresh local instance, even when another Ray runs on this machine.
        ray.init(address="local", num_cpus=args.num_cpus, include_dashboard=False)
    try:
        results = sweep(args.fmu, args.masses, args.thrust)
    finally:
        ray.shutdown()
    plot(results, args.masses, args.thrust, args.out)
    for r in results:
        print(
            f"mass {r['mass']:g} kg, k {r['thrust']:g} N: "
            f"hover {r['hover']:.6f}, climb {r['dz'][-1]:.3f} m"
        )
    return results


if __name__ == "__main__":
    main()
