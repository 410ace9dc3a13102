"""Cost of the examples/ssp systems per simulated second in each engine (fmpy's SSP support,
ecos, libcosim), wall clock, best of a few rounds (engines alternate each round, so a load
change hits all). Each system runs for its stop time T and for 2T: the difference over T is
the cost of simulating (per simulated second), the rest of the T run the fixed cost of
unpacking, loading and instantiating the FMUs. `--clock cpu` times the process's CPU seconds
(all its threads) instead of the wall clock: on a loaded machine (load far above the core
count) the wall clock mostly measures waiting for a core.

    bash scripts/pack-fmus.sh && bash scripts/pack-policy-fmus.sh
    .venv/bin/python benchmarks/ssp_engines.py [--rounds N] [SYSTEM ...]
"""

import argparse
import os
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "examples" / "ssp"))
import build  # noqa: E402
import engines  # noqa: E402
from systems import SYSTEMS  # noqa: E402


def main(argv=None) -> dict:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--fmus", type=Path, default=ROOT / "dist" / "fmu")
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--clock", choices=("wall", "cpu"), default="wall")
    parser.add_argument(
        "systems", nargs="*", default=list(SYSTEMS), help=f"any of {', '.join(SYSTEMS)}"
    )
    args = parser.parse_args(argv)
    unknown = [s for s in args.systems if s not in SYSTEMS]
    if unknown:
        parser.error(f"unknown system {unknown[0]!r}: known are {', '.join(SYSTEMS)}")
    chosen = {name: SYSTEMS[name] for name in args.systems}
    clock = time.perf_counter if args.clock == "wall" else time.process_time
    best = {}  # (system, engine, T or 2T) -> best seconds on the clock
    with tempfile.TemporaryDirectory() as tmp:
        for name, system in chosen.items():
            ssp = build.build(system, args.fmus, Path(tmp))
            for _ in range(args.rounds):
                for engine in engines.ENGINES:
                    for span in (1, 2):
                        stop = span * system.stop_time
                        start = clock()
                        engines.run(ssp, engine, stop, system.step_size, system.watch)
                        spent = clock() - start
                        key = (name, engine, span)
                        best[key] = min(best.get(key, spent), spent)
    load = os.getloadavg()[0]
    print(f"{args.clock} clock; load average {load:.1f} (1 min) on {os.cpu_count()} cores")
    result = {}
    for name, system in chosen.items():
        for engine in engines.ENGINES:
            once, twice = best[name, engine, 1], best[name, engine, 2]
            per_second = (twice - once) / system.stop_time
            setup = once - per_second * system.stop_time
            steps = round(1 / system.step_size)
            result[name, engine] = (per_second, setup)
            print(
                f"{name:15s} {engine:5s} {1000 * per_second:6.1f} ms per simulated second "
                f"({len(system.components)} FMUs x {steps} steps), {1000 * setup:6.1f} ms to load"
            )
    return result


if __name__ == "__main__":
    main()
