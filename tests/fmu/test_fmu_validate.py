"""fmpy's validator and fmutool (fmu-manipulation-toolbox: schema and semantic checks) find no
problem in any of the four FMUs (FMI 2.0 and FMI 3.0); each FMU holds what it should."""

import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest
from fmpy import read_model_description
from fmpy.validation import validate_fmu

ALL_FMUS = ["Quadrotor", "Lander2D", "Quadrotor-fmi3", "Lander2D-fmi3"]


@pytest.mark.parametrize("name", ALL_FMUS)
def test_fmpy_validate_reports_no_problems(fmus, name):
    assert validate_fmu(str(fmus[name])) == []


@pytest.mark.parametrize("name", ALL_FMUS)
def test_fmutool_check_finds_the_fmu_compliant(fmus, name):
    version = "3" if name.endswith("-fmi3") else "2"
    # The console script next to this interpreter (the venv's), else on PATH.
    fmutool = Path(sys.executable).with_name("fmutool")
    tool = str(fmutool) if fmutool.is_file() else shutil.which("fmutool")
    assert tool, "fmutool missing: pip install -r tests/requirements.txt"
    run = subprocess.run(
        [tool, "-input", str(fmus[name]), "-check"], capture_output=True, text=True, timeout=120
    )
    text = run.stdout + run.stderr
    assert run.returncode == 0, text
    assert f"This FMU seems to be compliant with FMI-{version}.0." in text, text
    assert f"No semantic error against the FMI-{version} standard." in text, text
    assert not [ln for ln in text.splitlines() if "WARNING" in ln or "ERROR" in ln], text


@pytest.mark.parametrize("name", ["Quadrotor", "Lander2D"])
def test_the_fmu_holds_its_model_description_and_binary(fmus, name):
    with zipfile.ZipFile(fmus[name]) as zf:
        names = set(zf.namelist())
    assert names == {"modelDescription.xml", f"binaries/linux64/{name}.so"}
    md = read_model_description(str(fmus[name]))
    assert md.fmiVersion == "2.0"
    assert md.coSimulation.modelIdentifier == name
    assert md.coSimulation.canGetAndSetFMUstate
    assert md.coSimulation.canSerializeFMUstate
    assert float(md.defaultExperiment.stepSize) > 0
    for v in md.modelVariables:
        assert v.description, v.name
        if v.type == "Real":
            assert v.unit, v.name
    outputs = {v.name for v in md.modelVariables if v.causality == "output"}
    expected = {
        "Quadrotor": {
            "x",
            "vz",
            "az",
            "qw",
            "roll",
            "yaw",
            "wz",
            "motor_state_3",
            "wind_z",
        },
        "Lander2D": {"x", "y", "angle", "battery", "landed", "crashed", "platform_x"},
    }[name]
    assert expected <= outputs
