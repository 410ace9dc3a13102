"""fmpy's validator and fmutool (fmu-manipulation-toolbox: schema and semantic checks) find no
problem in any of the six FMUs (FMI 2.0 and FMI 3.0); each FMU holds what it should."""

import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest
from fmpy import read_model_description
from fmpy.validation import validate_fmu

MODELS = ["Quadrotor", "Lander2D", "Hexacopter"]
ALL_FMUS = MODELS + [f"{name}-fmi3" for name in MODELS]


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


@pytest.mark.parametrize("name", MODELS)
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
        "Hexacopter": {"x", "vz", "az", "qw", "yaw", "motor_state_5", "wind_z"},
    }[name]
    assert expected <= outputs


def test_the_hexacopter_has_a_command_and_a_state_per_rotor_after_the_quadrotors_layout(fmus):
    hexa = read_model_description(str(fmus["Hexacopter"]))
    quad = read_model_description(str(fmus["Quadrotor"]))
    vr = {v.name: v.valueReference for v in hexa.modelVariables}
    inputs = [v.name for v in hexa.modelVariables if v.causality == "input"]
    assert inputs == [f"motor_command_{i}" for i in range(6)] + [
        "wind_input_x",
        "wind_input_y",
        "wind_input_z",
    ] + [f"motor_effectiveness_{i}" for i in range(6)]
    # The effectiveness inputs after the wind's: the earlier value references stay.
    assert [vr[f"motor_effectiveness_{i}"] for i in (0, 5)] == [9, 14]
    assert [vr[f"motor_state_{i}"] for i in (0, 5)] == [119, 124]
    assert hexa.numberOfContinuousStates == 27 and hexa.numberOfEventIndicators == 4
    # The same parameters and start values under the same value references.
    params = {(v.name, v.valueReference) for v in quad.modelVariables if v.causality == "parameter"}
    assert params == {
        (v.name, v.valueReference) for v in hexa.modelVariables if v.causality == "parameter"
    }
    assert hexa.guid != quad.guid
