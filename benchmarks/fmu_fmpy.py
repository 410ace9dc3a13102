"""Per-step cost of Quadrotor.fmu through fmpy (a real importer, ctypes), to put next to the
Rust-side cost of the same doStep (cargo bench -p flyloop-fmu --bench fmu_do_step).

    bash scripts/pack-fmus.sh && .venv/bin/python benchmarks/fmu_fmpy.py [--steps N]

Prints microseconds per call for: doStep alone; setReal(4) + doStep + getReal(13);
and an empty ctypes call into the same library (fmi2GetVersion) as the floor of any call.
"""

import argparse
import shutil
import time
from pathlib import Path

from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave

ROOT = Path(__file__).resolve().parents[1]
HOVER = (9.81 / 40.0) ** 0.5
OUTPUTS = ["x", "y", "z", "vx", "vy", "vz", "qw", "qx", "qy", "qz", "wx", "wy", "wz"]


def per_call(loop, steps: int, repeats: int = 5) -> float:
    """Best of `repeats` runs of `loop(steps)`, in microseconds per iteration."""
    best = float("inf")
    for _ in range(repeats):
        start = time.perf_counter()
        loop(steps)
        best = min(best, time.perf_counter() - start)
    return best / steps * 1e6


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--fmu", default=str(ROOT / "dist" / "fmu" / "Quadrotor.fmu"))
    parser.add_argument("--steps", type=int, default=100_000)
    args = parser.parse_args()

    md = read_model_description(args.fmu)
    vrs = {v.name: v.valueReference for v in md.modelVariables}
    directory = extract(args.fmu)
    slave = FMU2Slave(
        guid=md.guid,
        unzipDirectory=directory,
        modelIdentifier=md.coSimulation.modelIdentifier,
        instanceName="bench",
    )
    slave.instantiate()
    slave.setupExperiment(startTime=0.0)
    slave.enterInitializationMode()
    slave.setReal([vrs["initial_motor"]], [HOVER])
    slave.exitInitializationMode()
    h = 0.01
    n = 0
    inputs = [vrs[f"motor_command_{i}"] for i in range(4)]
    outputs = [vrs[name] for name in OUTPUTS]

    def steps_only(count: int) -> None:
        nonlocal n
        for _ in range(count):
            slave.doStep(currentCommunicationPoint=n * h, communicationStepSize=h)
            n += 1

    def set_step_get(count: int) -> None:
        nonlocal n
        command = [HOVER] * 4
        for _ in range(count):
            slave.setReal(inputs, command)
            slave.doStep(currentCommunicationPoint=n * h, communicationStepSize=h)
            slave.getReal(outputs)
            n += 1

    version = slave.dll.fmi2GetVersion

    def empty_call(count: int) -> None:
        for _ in range(count):
            version()

    results = {
        "fmpy doStep (10 ms)": per_call(steps_only, args.steps),
        "fmpy setReal(4) + doStep + getReal(13)": per_call(set_step_get, args.steps // 4),
        "ctypes empty call (fmi2GetVersion)": per_call(empty_call, args.steps),
    }
    for name, micros in results.items():
        print(f"{name:42s} {micros:8.3f} us")
    slave.terminate()
    slave.freeInstance()
    shutil.rmtree(directory, ignore_errors=True)


if __name__ == "__main__":
    main()
