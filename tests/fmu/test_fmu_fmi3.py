"""The FMI 3.0 FMUs (Quadrotor-fmi3.fmu, Lander2D-fmi3.fmu, Hexacopter-fmi3.fmu) through fmpy:
what they hold, the same Co-Simulation as FMI 2.0 to the last bit, Model Exchange with CVode
against FMI 2.0's, and FMU states that serialize and restore exactly."""

import shutil
import zipfile

import numpy as np
import pytest
from fmpy import extract, read_model_description, simulate_fmu
from fmpy.fmi2 import FMU2Slave
from fmpy.fmi3 import FMU3Slave
from fmu_support import HOVER, ROTORS, hover


def slave(fmu, version: int):
    md = read_model_description(str(fmu))
    directory = extract(str(fmu))
    cls = FMU3Slave if version == 3 else FMU2Slave
    instance = cls(
        guid=md.guid,
        unzipDirectory=directory,
        modelIdentifier=md.coSimulation.modelIdentifier,
        instanceName=f"fmi{version}",
    )
    instance.instantiate()
    vrs = {v.name: v.valueReference for v in md.modelVariables}
    return md, instance, vrs, directory


@pytest.mark.parametrize("name", ["Quadrotor", "Lander2D", "Hexacopter"])
def test_the_fmi3_fmu_holds_a_3_0_description_and_the_x86_64_linux_binary(fmus, name):
    with zipfile.ZipFile(fmus[f"{name}-fmi3"]) as zf:
        assert set(zf.namelist()) == {
            "modelDescription.xml",
            f"binaries/x86_64-linux/{name}.so",
        }
    md = read_model_description(str(fmus[f"{name}-fmi3"]))
    assert md.fmiVersion == "3.0"
    assert md.coSimulation.modelIdentifier == name
    assert md.coSimulation.canGetAndSetFMUstate and md.coSimulation.canSerializeFMUstate
    assert (md.modelExchange is not None) == (name in ROTORS)
    variables = {v.name: v for v in md.modelVariables}
    assert variables["time"].causality == "independent"
    assert all(v.description for v in md.modelVariables)
    if name in ROTORS:
        n = ROTORS[name]
        command = variables["motor_command"]
        assert command.type == "Float64" and command.causality == "input"
        assert [int(d.start) for d in command.dimensions] == [n]
        assert len(variables["motor_state"].dimensions) == 1
        assert md.numberOfContinuousStates == 21 + n and md.numberOfEventIndicators == 4
        assert variables["seed"].type == "Int32"
        assert variables["wind_enabled"].type == "Boolean"


@pytest.mark.parametrize("name", ["Quadrotor", "Lander2D", "Hexacopter"])
def test_fmi3_co_simulation_equals_fmi2_bit_for_bit(fmus, name):
    """Same seed, wind on, the same commands: every output of every step is the same f64."""
    md2, fmu2, vrs2, dir2 = slave(fmus[name], 2)
    md3, fmu3, vrs3, dir3 = slave(fmus[f"{name}-fmi3"], 3)
    fmu2.setupExperiment(startTime=0.0)
    fmu2.enterInitializationMode()
    fmu2.setInteger([vrs2["seed"]], [23])
    fmu2.setBoolean([vrs2["wind_enabled"]], [True])
    fmu2.exitInitializationMode()
    fmu3.enterInitializationMode(startTime=0.0)
    fmu3.setInt32([vrs3["seed"]], [23])
    fmu3.setBoolean([vrs3["wind_enabled"]], [True])
    fmu3.exitInitializationMode()
    commands2 = sorted(n for n in vrs2 if n.startswith("motor_command"))
    outputs2 = [v for v in md2.modelVariables if v.causality == "output" and v.type == "Real"]
    # FMI 3.0 outputs in modelDescription order; arrays expand in element order, like FMI 2.0.
    outputs3 = [v for v in md3.modelVariables if v.causality == "output" and v.type == "Float64"]
    n3 = sum(int(v.dimensions[0].start) if v.dimensions else 1 for v in outputs3)
    assert n3 == len(outputs2)
    commands3 = [vrs3["motor_command"]] if name in ROTORS else [vrs3[c] for c in commands2]
    t = 0.0
    for k in range(300):
        command = [0.5 + 0.1 * np.sin(0.05 * k + i) for i in range(len(commands2))]
        fmu2.setReal([vrs2[c] for c in commands2], command)
        fmu3.setFloat64(commands3, command)
        h = 0.01 if k < 150 else 0.0123
        fmu2.doStep(currentCommunicationPoint=t, communicationStepSize=h)
        result = fmu3.doStep(currentCommunicationPoint=t, communicationStepSize=h)
        assert result[:3] == (False, False, False)
        t += h
        got2 = fmu2.getReal([v.valueReference for v in outputs2])
        got3 = fmu3.getFloat64([v.valueReference for v in outputs3], nValues=n3)
        assert np.array_equal(np.asarray(got2), np.asarray(got3)), (name, k)
    for instance, directory in ((fmu2, dir2), (fmu3, dir3)):
        instance.terminate()
        instance.freeInstance()
        shutil.rmtree(directory, ignore_errors=True)


def test_fmi3_state_serializes_and_restores_exactly(fmus):
    md, fmu, vrs, directory = slave(fmus["Quadrotor-fmi3"], 3)
    fmu.enterInitializationMode(startTime=0.0)
    fmu.setBoolean([vrs["wind_enabled"]], [True])
    fmu.setInt32([vrs["seed"]], [5])
    fmu.setFloat64([vrs["initial_motor"]], [HOVER])
    fmu.exitInitializationMode()
    outputs = [vrs[n] for n in ("x", "y", "z", "qw", "wind_x")]

    def run(t0: float) -> list[float]:
        seen = []
        for k in range(100):
            fmu.setFloat64([vrs["motor_command"]], [HOVER + 0.0005 * k] * 4)
            fmu.doStep(currentCommunicationPoint=t0 + 0.01 * k, communicationStepSize=0.01)
            seen += fmu.getFloat64(outputs)
        return seen

    run(0.0)
    state = fmu.getFMUState()
    serialized = fmu.serializeFMUState(state)
    fmu.freeFMUState(state)
    first = run(1.0)
    restored = fmu.deserializeFMUState(serialized)
    fmu.setFMUState(restored)
    assert run(1.0) == first
    fmu.freeFMUState(restored)
    fmu.terminate()
    fmu.freeInstance()
    shutil.rmtree(directory, ignore_errors=True)


CALM3 = {
    "wind_enabled": False,
    "initial_z": 10.0,
    "initial_roll": 0.2,
    "initial_vx": 0.5,
    "initial_wx": 0.5,
    "initial_motor": HOVER,
}


@pytest.mark.parametrize("model", ROTORS)
def test_fmi3_model_exchange_with_cvode_follows_fmi2_model_exchange(fmus, model):
    """fmpy's CVode on the FMI 3.0 and the FMI 2.0 Model Exchange: the same right-hand side,
    so the same path to the solver's accuracy. The motors hold the vehicle's hover state (the
    command starts at initial_motor) and the vehicle, rolling, loses lift and falls from 10 m."""
    runs = [
        simulate_fmu(
            str(fmus[name]),
            fmi_type="ModelExchange",
            solver="CVode",
            relative_tolerance=1e-10,
            stop_time=1.0,
            output_interval=0.01,
            start_values={**CALM3, "initial_motor": hover(model)},
            output=["x", "y", "z", "qw"],
        )
        for name in (model, f"{model}-fmi3")
    ]
    fmi2, fmi3 = runs
    assert len(fmi3) == len(fmi2) > 100
    for name in ("x", "y", "z", "qw"):
        assert np.max(np.abs(fmi3[name] - fmi2[name])) < 1e-8, name
    assert fmi3["z"][-1] < 9.8 and np.ptp(fmi3["qw"]) > 1e-3
