"""docs/fmu.md's Ray sweep (examples/fmu_sweep.py) on a small grid: the hover command it finds
through the FMU is the analytic sqrt(m g / 4 k), and a heavier vehicle climbs less."""

import importlib.util
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def load_example():
    spec = importlib.util.spec_from_file_location("fmu_sweep", ROOT / "examples" / "fmu_sweep.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_ray_sweep_finds_the_analytic_hover_command(fmus, tmp_path):
    sweep = load_example()
    out = tmp_path / "sweep.png"
    argv = ["--fmu", str(fmus["Quadrotor"]), "--masses", "0.8,1.4", "--thrust", "8,12"]
    results = sweep.main([*argv, "--num-cpus", "2", "--out", str(out)])
    assert [(r["mass"], r["thrust"]) for r in results] == [(0.8, 8), (0.8, 12), (1.4, 8), (1.4, 12)]
    for r in results:
        analytic = (r["mass"] * 9.81 / (4 * r["thrust"])) ** 0.5
        assert abs(r["hover"] - analytic) < 1e-9, r
        # Hover holds until the step, then the vehicle climbs.
        assert abs(r["dz"][round(sweep.STEP_AT / sweep.DT)]) < 1e-9, r
        assert r["dz"][-1] > 0.1, r
    climb = {(r["mass"], r["thrust"]): r["dz"][-1] for r in results}
    assert climb[(1.4, 12)] < climb[(0.8, 12)]
    assert out.stat().st_size > 10_000
