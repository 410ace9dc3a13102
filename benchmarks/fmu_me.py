"""Quadrotor.fmu as Model Exchange in fmpy with CVode: wall time of a 10 s flight and the
number of right-hand-side evaluations (derivative calls) the solver needed.

    bash scripts/pack-fmus.sh && .venv/bin/python benchmarks/fmu_me.py [--tolerance 1e-6]
    .venv/bin/python benchmarks/fmu_me.py --fmu dist/fmu/Quadrotor-fmi3.fmu    # FMI 3.0

A slow climb from 20 m, twice: wind off (no events; one smooth integration) and wind on (a
time event every turbulence_dt = 0.01 s, each restarting CVode). Best wall time of
`--repeats` runs.
"""

import argparse
import time
from pathlib import Path

from fmpy import read_model_description, simulate_fmu

ROOT = Path(__file__).resolve().parents[1]
HOVER = (9.81 / 40.0) ** 0.5


def run(fmu: str, wind: bool, tolerance: float) -> tuple[float, int, int]:
    """Wall time (s), derivative calls and time events of one 10 s flight (FMI 2.0 or 3.0)."""
    fmi3 = read_model_description(fmu).fmiVersion.startswith("3")
    derivatives, events = (
        ("fmi3GetContinuousStateDerivatives", "fmi3UpdateDiscreteStates")
        if fmi3
        else ("fmi2GetDerivatives", "fmi2NewDiscreteStates")
    )
    calls = {derivatives: 0, events: 0}
    commands = (
        {"motor_command": [HOVER + 0.01] * 4}
        if fmi3
        else {f"motor_command_{i}": HOVER + 0.01 for i in range(4)}
    )

    def count(line: str) -> None:
        name = line.split("(", 1)[0].strip()
        if name in calls:
            calls[name] += 1

    start_values = {
        "wind_enabled": wind,
        "seed": 3,
        "initial_z": 20.0,
        "initial_motor": HOVER,
        **commands,
    }
    start = time.perf_counter()
    simulate_fmu(
        fmu,
        fmi_type="ModelExchange",
        solver="CVode",
        relative_tolerance=tolerance,
        stop_time=10.0,
        output_interval=0.01,
        start_values=start_values,
        output=["z"],
        fmi_call_logger=count,
    )
    wall = time.perf_counter() - start
    return wall, calls[derivatives], calls[events]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--fmu", default=str(ROOT / "dist" / "fmu" / "Quadrotor.fmu"))
    parser.add_argument("--tolerance", type=float, default=1e-6)
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()
    for wind in (False, True):
        runs = [run(args.fmu, wind, args.tolerance) for _ in range(args.repeats)]
        wall, rhs, events = min(runs)
        print(
            f"wind {'on ' if wind else 'off'}: {wall:.3f} s wall for 10 s simulated, "
            f"{rhs} RHS evaluations, {events} event updates "
            f"(CVode rtol {args.tolerance:g})"
        )


if __name__ == "__main__":
    main()
