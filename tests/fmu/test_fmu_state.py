"""FMU states through fmpy: get at t1, run to t2, set, run to t2 again gives identical
outputs; the same through serialize/deserialize; garbage bytes give fmi2Error."""

import pytest
from fmpy.fmi1 import FMICallException
from fmu_support import HOVER, LoggedSlave

INPUT = {
    "Quadrotor": "motor_command_1",
    "Hexacopter": "motor_command_1",
    "Lander2D": "motor_command_right",
}


def run(instance: LoggedSlave, model: str, t: float, end: float, h: float):
    """Steps from t to end, changing the command every step; returns the outputs."""
    rows = []
    n = 0
    while t < end - 1e-9:
        instance.slave.setReal([instance.vrs[INPUT[model]]], [HOVER + 0.1 * ((n % 7) - 3) / 3])
        instance.slave.doStep(currentCommunicationPoint=t, communicationStepSize=h)
        n += 1
        t = round(t + h, 12)
        rows.append(instance.outputs())
    return rows


@pytest.fixture(params=list(INPUT))
def started(request, fmus):
    model = request.param
    instance = LoggedSlave(fmus[model])
    instance.slave.setupExperiment(startTime=0.0)
    instance.slave.enterInitializationMode()
    instance.slave.setInteger([instance.vrs["seed"]], [42])
    instance.slave.exitInitializationMode()
    yield model, instance
    instance.close()


def test_set_state_repeats_the_run_exactly(started):
    model, instance = started
    run(instance, model, 0.0, 1.0, 0.05)
    state = instance.slave.getFMUstate()
    first = run(instance, model, 1.0, 2.0, 0.05)
    instance.slave.setFMUstate(state)
    second = run(instance, model, 1.0, 2.0, 0.05)
    assert len(first) == 20
    assert first == second
    assert first[0] != first[-1]
    instance.slave.freeFMUstate(state)


def test_serialized_state_repeats_the_run_exactly_in_another_instance(started, fmus):
    model, instance = started
    run(instance, model, 0.0, 0.5, 0.02)
    state = instance.slave.getFMUstate()
    data = instance.slave.serializeFMUstate(state)
    first = run(instance, model, 0.5, 1.5, 0.02)
    restored = instance.slave.deSerializeFMUstate(data)
    instance.slave.setFMUstate(restored)
    assert run(instance, model, 0.5, 1.5, 0.02) == first
    other = LoggedSlave(fmus[model], name="other")
    try:
        other.slave.setFMUstate(other.slave.deSerializeFMUstate(data))
        assert run(other, model, 0.5, 1.5, 0.02) == first
    finally:
        other.close()


@pytest.mark.parametrize(
    "garbage",
    [b"not a state", b"", b"FLYFMI01" + b"\xff" * 40, bytes(range(256)) * 4],
)
def test_garbage_bytes_for_deserialize_give_fmi2_error(started, garbage):
    model, instance = started
    with pytest.raises(FMICallException) as error:
        instance.slave.deSerializeFMUstate(garbage)
    assert error.value.status == 3
    assert instance.last_message().startswith("fmi2DeSerializeFMUstate: FMU state refused")
    # The instance goes on as before.
    run(instance, model, 0.0, 0.1, 0.05)


def test_damaged_state_bytes_give_fmi2_error(started):
    _model, instance = started
    data = bytearray(instance.slave.serializeFMUstate(instance.slave.getFMUstate()))
    data[len(data) // 2] ^= 0x01
    with pytest.raises(FMICallException):
        instance.slave.deSerializeFMUstate(bytes(data))
    assert "checksum" in instance.last_message()
