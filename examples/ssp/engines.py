"""Runs an SSP built by build.py in a co-simulation engine and returns the watched outputs:
fmpy's SSP support (`fmpy.ssp.simulation.simulate_ssp`), ecos (`ecospy`) or libcosim
(`libcosimpy`, OSP's engine). No Python runs in the loop in any: the engine steps the FMUs and
moves the values along the connections (ecos and libcosim are stepped from Python only to read
the watched outputs after each step).

The engines differ in one way that matters here: fmpy moves the values after every FMU has
stepped (a Jacobi master: each connection delays by one communication step, and the inputs
start at 0 before the first move), ecos sets each FMU's inputs from the outputs read at the
start of the step (also one step of delay, but the inputs start at the FMUs' start values);
libcosim's fixed-step algorithm does as ecos does.
So the two runs are the same closed loop sampled alike but not bit for bit the same.
"""

import sys
import time
from pathlib import Path

import numpy as np
from fmpy.ssp.simulation import simulate_ssp
from fmpy.ssp.ssd import ParameterSet, read_ssd

sys.path.insert(0, str(Path(__file__).resolve().parent))
from systems import PARAMETER_SET  # noqa: E402

ENGINES = ("fmpy", "ecos", "libcosim")
NANOSECONDS = 1_000_000_000  # libcosim's time unit


def bindings(ssp: Path) -> ParameterSet:
    """The components' ParameterBindings as the one parameter set fmpy's simulate_ssp applies
    (it matches `<component>.<variable>`; it does not read bindings itself). Booleans become
    0/1: fmpy turns the SSV text "false" into True."""
    system = read_ssd(str(ssp)).system
    merged = ParameterSet(name="bindings")
    for component in system.elements:
        for binding in component.parameterBindings:
            for values in binding.parameterValues:
                for p in values.parameters:
                    if p.type == "Boolean":
                        p.value = 1.0 if p.value == "true" else 0.0
                    p.name = f"{component.name}.{p.name}"
                    merged.parameters.append(p)
    return merged


def run_fmpy(ssp: Path, stop_time: float, step_size: float, watch) -> dict[str, np.ndarray]:
    result = simulate_ssp(
        str(ssp), stop_time=stop_time, step_size=step_size, parameter_set=bindings(ssp)
    )
    # fmpy records after each step at the step's start time; the values are at its end.
    out = {"time": result["time"] + step_size}
    out.update({name: np.asarray(result[name]) for name in watch})
    return out


def run_ecos(ssp: Path, stop_time: float, step_size: float, watch) -> dict[str, np.ndarray]:
    from ecospy import EcosSimulation

    rows = []
    with EcosSimulation(ssp_path=str(ssp), step_size=step_size) as sim:
        sim.init(parameter_set=PARAMETER_SET)
        steps = round(stop_time / step_size)
        for _ in range(steps):
            sim.step()
            rows.append([sim.get_time()] + [sim.get_real(n.replace(".", "::", 1)) for n in watch])
        sim.terminate()
    data = np.array(rows)
    out = {"time": data[:, 0]}
    out.update({name: data[:, i + 1] for i, name in enumerate(watch)})
    return out


def run_libcosim(ssp: Path, stop_time: float, step_size: float, watch) -> dict[str, np.ndarray]:
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
    from libcosimpy.CosimObserver import CosimObserver

    log_output_level(CosimLogLevel.ERROR)
    execution = CosimExecution.from_ssp_file(str(ssp), step_size=round(step_size * NANOSECONDS))
    index = {i.name.decode(): i.index for i in execution.slave_infos()}
    refs = []
    for name in watch:
        component, variable = name.split(".", 1)
        by_name = {
            v.name.decode(): v.reference for v in execution.slave_variables(index[component])
        }
        refs.append((index[component], by_name[variable]))
    observer = CosimObserver.create_last_value()
    execution.add_observer(observer)
    rows = []
    for k in range(round(stop_time / step_size)):
        execution.step()
        values = [observer.last_real_values(slave, [ref])[0] for slave, ref in refs]
        rows.append([(k + 1) * step_size, *values])
    data = np.array(rows)
    out = {"time": data[:, 0]}
    out.update({name: data[:, i + 1] for i, name in enumerate(watch)})
    return out


def run(ssp: Path, engine: str, stop_time: float, step_size: float, watch) -> dict[str, np.ndarray]:
    """The watched outputs (`component.variable`) at every communication point after the start,
    and the wall-clock seconds the run took under "wall"."""
    runner = {"fmpy": run_fmpy, "ecos": run_ecos, "libcosim": run_libcosim}.get(engine)
    if runner is None:
        raise ValueError(f"engine {engine!r} is not one of {', '.join(ENGINES)}")
    start = time.perf_counter()
    out = runner(Path(ssp), stop_time, step_size, watch)
    out["wall"] = time.perf_counter() - start
    return out
