"""Per-step cost of Quadrotor.fmu (FMI 2.0) and Quadrotor-fmi3.fmu (FMI 3.0) through fmpy (a
real importer, ctypes), in one run, to put next to the Rust-side cost of the same doStep
(cargo bench -p flyloop-fmu --bench fmu_do_step).

    bash scripts/pack-fmus.sh && .venv/bin/python benchmarks/fmu_fmpy.py [--steps N]

Prints microseconds per call for: doStep alone; set 4 commands + doStep + get 13 outputs;
doStep called through ctypes directly (without fmpy's wrapper), and on a NULL instance (what
is left is ctypes passing the arguments); an empty ctypes call into the same library
(fmi2GetVersion) as the floor of any call; and the FMI 3.0 / FMI 2.0 ratio of each.
"""

import argparse
import ctypes
import shutil
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave
from fmpy.fmi3 import FMU3Slave

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


@dataclass
class Instance:
    """An FMU instance initialised at hover, with the calls that set its motor commands and
    read its outputs (FMI 2.0's or 3.0's)."""

    slave: FMU2Slave | FMU3Slave
    fmi3: bool
    set_real: Callable
    get_real: Callable
    inputs: list[int]
    outputs: list[int]
    directory: str


def open_at_hover(fmu: str) -> Instance:
    """Extracts and instantiates `fmu` (FMI 2.0 or 3.0, from its modelDescription) and
    initialises it with the motors at hover."""
    md = read_model_description(fmu)
    fmi3 = md.fmiVersion.startswith("3")
    vrs = {v.name: v.valueReference for v in md.modelVariables}
    directory = extract(fmu)
    slave = (FMU3Slave if fmi3 else FMU2Slave)(
        guid=md.guid,
        unzipDirectory=directory,
        modelIdentifier=md.coSimulation.modelIdentifier,
        instanceName="bench",
    )
    slave.instantiate()
    if fmi3:
        slave.enterInitializationMode(startTime=0.0)
        slave.setFloat64([vrs["initial_motor"]], [HOVER])
        set_real, get_real = slave.setFloat64, slave.getFloat64
        inputs = [vrs["motor_command"]]
    else:
        slave.setupExperiment(startTime=0.0)
        slave.enterInitializationMode()
        slave.setReal([vrs["initial_motor"]], [HOVER])
        set_real, get_real = slave.setReal, slave.getReal
        inputs = [vrs[f"motor_command_{i}"] for i in range(4)]
    slave.exitInitializationMode()
    outputs = [vrs[name] for name in OUTPUTS]
    return Instance(slave, fmi3, set_real, get_real, inputs, outputs, directory)


def raw_do_step(fmu: Instance, h: float) -> Callable[..., None]:
    """`raw_step(t, instance=the FMU's)`: doStep of h from t without fmpy's Python wrapper
    (pre-made output arguments): what the FMU and ctypes cost, apart from the wrapper (FMI
    3.0's builds four ctypes objects and a tuple)."""
    slave = fmu.slave
    if fmu.fmi3:
        flags = [ctypes.c_bool() for _ in range(3)]
        last = ctypes.c_double()
        outs = [ctypes.byref(f) for f in flags] + [ctypes.byref(last)]
        raw = slave.dll.fmi3DoStep

        def raw_step(t: float, instance=slave.component) -> None:
            raw(instance, t, h, True, *outs)
    else:
        raw = slave.dll.fmi2DoStep

        def raw_step(t: float, instance=slave.component) -> None:
            raw(instance, t, h, 1)

    return raw_step


def timed_loops(fmu: Instance) -> dict[str, Callable[[int], None]]:
    """The loops `measure` times, each `loop(count)`: one clock of 10 ms steps runs on through
    all of them, so every doStep continues from the last."""
    slave, set_real, get_real = fmu.slave, fmu.set_real, fmu.get_real
    inputs, outputs = fmu.inputs, fmu.outputs
    h = 0.01
    n = 0

    def steps_only(count: int) -> None:
        nonlocal n
        for _ in range(count):
            slave.doStep(currentCommunicationPoint=n * h, communicationStepSize=h)
            n += 1

    def set_step_get(count: int) -> None:
        nonlocal n
        command = [HOVER] * 4
        for _ in range(count):
            set_real(inputs, command)
            slave.doStep(currentCommunicationPoint=n * h, communicationStepSize=h)
            get_real(outputs)
            n += 1

    raw_step = raw_do_step(fmu, h)

    def null_steps(count: int) -> None:
        # A NULL instance is refused at once: what is left is ctypes passing the arguments.
        for _ in range(count):
            raw_step(0.0, None)

    def steps_raw(count: int) -> None:
        nonlocal n
        for _ in range(count):
            raw_step(n * h)
            n += 1

    version = slave.dll.fmi2GetVersion

    def empty_call(count: int) -> None:
        for _ in range(count):
            version()

    return dict(
        steps_only=steps_only,
        set_step_get=set_step_get,
        steps_raw=steps_raw,
        null_steps=null_steps,
        empty_call=empty_call,
    )


def measure(fmu: str, steps: int) -> dict[str, float]:
    """Microseconds per call for one FMU (FMI 2.0 or 3.0, from its modelDescription)."""
    instance = open_at_hover(fmu)
    loops = timed_loops(instance)
    results = {
        "doStep (10 ms)": per_call(loops["steps_only"], steps),
        "set 4 + doStep + get 13": per_call(loops["set_step_get"], steps // 4),
        "doStep through ctypes, without fmpy's wrapper": per_call(loops["steps_raw"], steps),
        "the same on a NULL instance (argument passing)": per_call(loops["null_steps"], steps),
        "ctypes empty call (fmi2GetVersion)": per_call(loops["empty_call"], steps),
    }
    instance.slave.terminate()
    instance.slave.freeInstance()
    shutil.rmtree(instance.directory, ignore_errors=True)
    return results


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--fmu", default=str(ROOT / "dist" / "fmu" / "Quadrotor.fmu"))
    parser.add_argument("--fmu3", default=str(ROOT / "dist" / "fmu" / "Quadrotor-fmi3.fmu"))
    parser.add_argument("--steps", type=int, default=100_000)
    args = parser.parse_args()
    fmi2 = measure(args.fmu, args.steps)
    fmi3 = measure(args.fmu3, args.steps)
    print(f"{'fmpy, microseconds per call':46s} {'FMI 2.0':>8s} {'FMI 3.0':>8s} {'3.0/2.0':>8s}")
    for name in fmi2:
        ratio = fmi3[name] / fmi2[name]
        print(f"{name:46s} {fmi2[name]:8.3f} {fmi3[name]:8.3f} {ratio:8.3f}")


if __name__ == "__main__":
    main()
