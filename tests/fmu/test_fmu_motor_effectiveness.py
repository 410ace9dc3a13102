"""The multirotor FMUs' fault inputs (issue 35): `motor_effectiveness_i` (FMI 3.0: the array
`motor_effectiveness`), default 1, in [0, 1]. A motor at 0.5 in Quadrotor.fmu or
Hexacopter.fmu (FMI 2.0 and 3.0) flies the core's own faulted episode bit for bit —
QuadHover-v0 on the native backend with faults=[motor_effectiveness 0.5 on that motor from
t = 0], fed the same commands (positions as float32, as the env's info carries them); every
motor back at 1 is the healthy vehicle's bits; a value past [0, 1] is refused naming it."""

import math
import shutil

import flyloop  # noqa: F401  (registers the ids)
import gymnasium as gym
import numpy as np
import pytest
from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave
from fmpy.fmi3 import FMU3Slave
from fmu_support import ROTORS

STEPS = 100
DT = 0.01  # the task's control step, s
WEAK = 1  # the weak motor's index in the FMU (PX4's instance numbering in the env: 2)
FRAMES = {"Quadrotor": "quad_x", "Hexacopter": "hexa_x"}


def hover(model: str) -> float:
    """The core's hover_motor_state for the default vehicle, in its operation order."""
    return math.sqrt(1.0 * 9.81 / (ROTORS[model] * 10.0))


def commands(model: str) -> np.ndarray:
    rng = np.random.default_rng(9)
    c = hover(model) + rng.uniform(-0.02, 0.02, (STEPS, ROTORS[model]))
    return c.astype(np.float32)


def gym_episode(model: str, faults) -> np.ndarray:
    env = gym.make(
        "flyloop/QuadHover-v0",
        backend="native",
        frame=FRAMES[model],
        start_attitude_range=0.0,
        use_wind=False,
        max_steps=STEPS,
        # A weak motor tips the vehicle over: the comparison runs on past the task's ends.
        enable_crash_detection=False,
        enable_out_of_bounds_detection=False,
        faults=faults,
    )
    try:
        _, info = env.reset(seed=4)
        positions = [info["position"]]
        for command in commands(model):
            _, _, terminated, _, info = env.step(command)
            positions.append(info["position"])
            assert not terminated, "the episode must stay in the air and in bounds"
    finally:
        env.close()
    return np.array(positions, dtype=np.float32)


def fmu_episode(fmus, model: str, version: int, start_z: float, effectiveness) -> np.ndarray:
    """The FMU fed the gym's commands (one doStep of DT each) with `effectiveness` per motor
    (None: the inputs never set)."""
    path = fmus[model if version == 2 else f"{model}-fmi3"]
    md = read_model_description(str(path))
    directory = extract(str(path))
    cls = FMU3Slave if version == 3 else FMU2Slave
    fmu = cls(
        guid=md.guid,
        unzipDirectory=directory,
        modelIdentifier=md.coSimulation.modelIdentifier,
        instanceName=f"weak{version}",
    )
    vrs = {v.name: v.valueReference for v in md.modelVariables}
    n = ROTORS[model]
    real = fmu.setReal if version == 2 else fmu.setFloat64
    get = fmu.getReal if version == 2 else fmu.getFloat64
    fmu.instantiate()
    if version == 2:
        fmu.setupExperiment(startTime=0.0)
        fmu.enterInitializationMode()
    else:
        fmu.enterInitializationMode(startTime=0.0)
    fmu.setBoolean([vrs["wind_enabled"]], [False])
    real([vrs["initial_motor"], vrs["initial_z"]], [hover(model), start_z])
    fmu.exitInitializationMode()
    if version == 2:
        command_vrs = [vrs[f"motor_command_{i}"] for i in range(n)]
        if effectiveness is not None:
            real([vrs[f"motor_effectiveness_{i}"] for i in range(n)], effectiveness)
    else:
        command_vrs = [vrs["motor_command"]]
        if effectiveness is not None:
            real([vrs["motor_effectiveness"]], effectiveness)
    xyz = [vrs[a] for a in ("x", "y", "z")]
    positions = [get(xyz)]
    try:
        for k, command in enumerate(commands(model).astype(np.float64)):
            real(command_vrs, list(command))
            fmu.doStep(currentCommunicationPoint=k * DT, communicationStepSize=DT)
            positions.append(get(xyz))
    finally:
        fmu.terminate()
        fmu.freeInstance()
        shutil.rmtree(directory, ignore_errors=True)
    return np.array(positions, dtype=np.float64).astype(np.float32)


@pytest.mark.parametrize("version", [2, 3])
@pytest.mark.parametrize("model", sorted(ROTORS))
def test_a_motor_at_half_effectiveness_flies_the_cores_faulted_episode_bit_for_bit(
    fmus, model, version
):
    n = ROTORS[model]
    fault = [{"kind": "motor_effectiveness", "motor": WEAK + 1, "effectiveness": 0.5, "at": 0.0}]
    faulted = gym_episode(model, fault)
    healthy = gym_episode(model, None)
    start_z = float(faulted[0][2])
    weak = [1.0] * n
    weak[WEAK] = 0.5
    fmu = fmu_episode(fmus, model, version, start_z, weak)
    differing = np.flatnonzero((fmu != faulted).any(axis=1))
    if differing.size:
        k = differing[0]
        pytest.fail(f"first differing step {k}: fmu {fmu[k]}, core {faulted[k]}")
    # The weak motor changed the flight (the comparison is not of the healthy vehicle).
    assert np.abs(faulted[-1] - healthy[-1]).max() > 0.05
    # Every motor at 1 is the healthy vehicle, as if the inputs were never set.
    assert np.array_equal(fmu_episode(fmus, model, version, start_z, [1.0] * n), healthy)
    assert np.array_equal(fmu_episode(fmus, model, version, start_z, None), healthy)


@pytest.mark.parametrize("value", [1.5, -0.1])
def test_an_effectiveness_outside_0_1_is_refused_naming_the_input(fmus, value):
    from fmu_support import LoggedSlave

    fmu = LoggedSlave(fmus["Quadrotor"])
    try:
        fmu.start()
        vr = fmu.vrs["motor_effectiveness_2"]
        with pytest.raises(Exception, match="fmi2SetReal"):
            fmu.slave.setReal([vr], [value])
        text = " ".join(m[2] for m in fmu.messages)
        assert "motor_effectiveness_2" in text and "[0, 1]" in text, text
        assert fmu.slave.getReal([vr]) == [1.0]
    finally:
        fmu.close()
