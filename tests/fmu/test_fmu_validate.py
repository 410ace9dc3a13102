"""fmpy's validator finds no problem in either FMU; each FMU holds what it should."""

import zipfile

import pytest
from fmpy import read_model_description
from fmpy.validation import validate_fmu


@pytest.mark.parametrize("name", ["Quadrotor", "Lander2D"])
def test_fmpy_validate_reports_no_problems(fmus, name):
    assert validate_fmu(str(fmus[name])) == []


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
