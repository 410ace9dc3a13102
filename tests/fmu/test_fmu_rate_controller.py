"""RateController.fmu in fmpy: it validates (FMI 2.0 and 3.0), and closed on Quadrotor.fmu by
name (the plant's wx wy wz in, motor_command_i out) through fmpy's own FMU classes with a
4 ms master step, a hover setpoint holds the height and a roll rate turns the vehicle."""

import fmpy
from fmpy.fmi2 import FMU2Slave
from fmpy.validation import validate_fmu

STEP = 0.004


def test_rate_controller_validates_in_fmpy(fmus):
    for name in ("RateController", "RateController-fmi3"):
        assert validate_fmu(str(fmus[name])) == [], name


def _instance(path, name):
    md = fmpy.read_model_description(str(path))
    unzipped = fmpy.extract(str(path))
    fmu = FMU2Slave(
        guid=md.guid,
        unzipDirectory=unzipped,
        modelIdentifier=md.coSimulation.modelIdentifier,
        instanceName=name,
    )
    fmu.instantiate()
    fmu.setupExperiment(startTime=0.0)
    fmu.enterInitializationMode()
    fmu.exitInitializationMode()
    return fmu, {v.name: v.valueReference for v in md.modelVariables}


def _fly(fmus, setpoint, seconds):
    plant, pv = _instance(fmus["Quadrotor"], "plant")
    ctrl, cv = _instance(fmus["RateController"], "rates")
    rates = ["wx", "wy", "wz"]
    motors = [f"motor_command_{i}" for i in range(4)]
    ctrl.setReal([cv[n] for n in setpoint], list(setpoint.values()))
    t = 0.0
    for _ in range(round(seconds / STEP)):
        ctrl.setReal([cv[n] for n in rates], plant.getReal([pv[n] for n in rates]))
        plant.setReal([pv[n] for n in motors], ctrl.getReal([cv[n] for n in motors]))
        plant.doStep(t, STEP)
        ctrl.doStep(t, STEP)
        t += STEP
    out = dict(
        zip(("z", "roll", "wx"), plant.getReal([pv["z"], pv["roll"], pv["wx"]]), strict=True)
    )
    for fmu in (plant, ctrl):
        fmu.terminate()
        fmu.freeInstance()
    return out


def test_rate_controller_closes_the_loop_on_the_quadrotor(fmus):
    # Quadrotor.fmu's default start: 1.5 m, motors at 0; the hover thrust of the default quad.
    hover = _fly(fmus, {"thrust": 0.5567}, 0.0)
    assert hover["z"] == 1.5
    level = _fly(fmus, {"thrust": 0.62}, 2.0)
    assert level["z"] > 1.5, level  # more than hover thrust climbs
    assert abs(level["roll"]) < 1e-6, level  # no rate asked: stays level
    # PX4's roll rate is body FRD x = FLU x: a positive setpoint turns wx positive.
    rolling = _fly(fmus, {"thrust": 0.62, "roll_rate": 0.5}, 0.5)
    assert 0.35 < rolling["wx"] < 0.65, rolling
