"""Fixtures for the FMU system tests: the packed FMUs and the core's own trajectory.

The FMUs (and the reference tool flyloop-fmu-core-trajectory) are built and packed
once per session with scripts/pack-fmus.sh (cargo rebuilds only what changed), so
`pytest tests/fmu` works on a fresh clone with cargo installed.
"""

import json
import os
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="session")
def fmus() -> dict[str, Path]:
    out = ROOT / "dist" / "fmu"
    subprocess.run(["bash", str(ROOT / "scripts" / "pack-fmus.sh"), str(out)], cwd=ROOT, check=True)
    names = ("Quadrotor", "Lander2D", "Hexacopter", "RateController", "AttitudeController")
    names += tuple(f"{name}-fmi3" for name in names)
    paths = {name: out / f"{name}.fmu" for name in names}
    for path in paths.values():
        assert path.is_file(), path
    return paths


@pytest.fixture(scope="session")
def core_trajectory(fmus):
    """Runs the core model from Rust (fmu/tests/tools/core_trajectory.rs) for a spec."""
    target = Path(os.environ.get("CARGO_TARGET_DIR", ROOT / "target"))
    if not target.is_absolute():
        target = ROOT / target
    tool = target / "release" / "flyloop-fmu-core-trajectory"
    assert tool.is_file(), f"{tool} was not built by scripts/pack-fmus.sh"

    def run(spec: dict) -> dict[str, list[float]]:
        result = subprocess.run(
            [str(tool)],
            input=json.dumps(spec),
            capture_output=True,
            text=True,
            check=True,
        )
        return json.loads(result.stdout)

    return run


@pytest.fixture(scope="session")
def policy_fmus(fmus) -> dict[str, Path]:
    """dist/fmu/HexaHoverPolicy.fmu, OffboardPolicy.fmu and their -fmi3.fmu
    (scripts/pack-policy-fmus.sh: the policy library links tract, so it is built only for the
    tests that need it)."""
    out = ROOT / "dist" / "fmu"
    script = ROOT / "scripts" / "pack-policy-fmus.sh"
    subprocess.run(["bash", str(script), str(out)], cwd=ROOT, check=True)
    names = ("HexaHoverPolicy", "OffboardPolicy")
    names += tuple(f"{name}-fmi3" for name in names)
    paths = {name: out / f"{name}.fmu" for name in names}
    for path in paths.values():
        assert path.is_file(), path
    return paths
