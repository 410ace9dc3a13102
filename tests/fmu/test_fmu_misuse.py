"""Misuse through fmpy, as a user would commit it: each call returns the documented
status, logs why, and nothing crashes the Python process."""

import ctypes
import math
from ctypes import byref
from pathlib import Path

import pytest
from fmpy.fmi1 import FMICallException
from fmpy.fmi2 import FMU2Slave, fmi2CallbackFunctions, fmi2FMUstate
from fmu_support import LoggedSlave

ERROR = 3


@pytest.fixture(params=["Quadrotor", "Hexacopter"])
def quad(fmus, request):
    """A multirotor instance: the quad X's and the hexa X's FMU refuse misuse alike."""
    instance = LoggedSlave(fmus[request.param])
    yield instance
    instance.close()


def test_do_step_before_initialisation_is_an_illegal_call_sequence(quad):
    with pytest.raises(FMICallException) as error:
        quad.slave.doStep(currentCommunicationPoint=0.0, communicationStepSize=0.01)
    assert error.value.status == ERROR
    assert quad.last_message().startswith("fmi2DoStep: Illegal call sequence")
    quad.start()
    quad.slave.doStep(currentCommunicationPoint=0.0, communicationStepSize=0.01)


def test_unknown_value_references_are_refused_by_name(quad):
    quad.start()
    with pytest.raises(FMICallException):
        quad.slave.getReal([12345])
    assert "unknown value reference 12345" in quad.last_message()
    with pytest.raises(FMICallException):
        quad.slave.setReal([999], [1.0])
    assert "unknown value reference 999" in quad.last_message()


def test_nan_input_is_refused_and_the_vehicle_flies_on(quad):
    quad.start()
    vr = quad.vrs["motor_command_0"]
    quad.slave.setReal([vr], [0.5])
    with pytest.raises(FMICallException):
        quad.slave.setReal([vr], [float("nan")])
    # "input" as the causality says; no unit "1" after a plain number.
    assert quad.last_message().endswith(
        "input `motor_command_0` = NaN is out of range: it must be in [0, 1]"
    ), quad.last_message()
    assert quad.slave.getReal([vr]) == [0.5]
    # Huge numbers print compactly, not as 301 digits.
    with pytest.raises(FMICallException):
        quad.slave.setReal([quad.vrs["wind_input_x"]], [1e300])
    assert quad.last_message().endswith(
        "input `wind_input_x` = 1e300 m/s is out of range: it must be in [-100, 100] m/s"
    ), quad.last_message()
    quad.slave.doStep(currentCommunicationPoint=0.0, communicationStepSize=0.1)
    assert all(math.isfinite(v) for v in quad.outputs()), "no NaN got in"


def test_negative_mass_is_refused_naming_parameter_and_bound(quad):
    with pytest.raises(FMICallException):
        quad.slave.setReal([quad.vrs["mass"]], [-1.0])
    assert "`mass` = -1 kg is out of range: it must be in [0.001, 10000] kg" in (
        quad.last_message()
    )
    quad.start()
    assert quad.real("mass") == [1.0]


def test_mismatched_communication_point_and_bad_step_sizes(quad):
    quad.start(stop_time=1.0)
    for t, h, reason in [
        (0.5, 0.1, "does not match the instance's time 0"),
        (0.0, 0.0, "positive finite number"),
        (0.0, -0.1, "positive finite number"),
        (0.0, 2.0, "after the stop time 1"),
    ]:
        with pytest.raises(FMICallException):
            quad.slave.doStep(currentCommunicationPoint=t, communicationStepSize=h)
        assert reason in quad.last_message(), quad.last_message()
    quad.slave.doStep(currentCommunicationPoint=0.0, communicationStepSize=1.0)


def test_wrong_guid_gives_no_instance_and_a_message(fmus):
    good = LoggedSlave(fmus["Lander2D"])
    wrong = FMU2Slave(
        guid="{00000000-0000-0000-0000-000000000000}",
        unzipDirectory=good.directory,
        modelIdentifier="Lander2D",
        instanceName="wrong",
    )
    with pytest.raises(Exception, match="Failed to instantiate"):
        wrong.instantiate(callbacks=good.callbacks)
    assert "GUID {00000000-0000-0000-0000-000000000000} is not one of" in good.last_message()
    wrong.freeLibrary()
    good.close()


def test_null_callbacks_give_no_instance_and_no_crash(fmus):
    instance = LoggedSlave(fmus["Quadrotor"])
    library = Path(instance.directory, "binaries", "linux64", "Quadrotor.so")
    # A raw handle: fmpy's own function objects insist on a callback struct.
    instantiate = ctypes.CDLL(str(library)).fmi2Instantiate
    instantiate.restype = ctypes.c_void_p
    guid = instance.model_description.guid.encode()
    no_logger = fmi2CallbackFunctions()
    for callbacks in (None, byref(no_logger)):
        assert instantiate(b"x", 1, guid, None, callbacks, 0, 0) is None
    instance.close()


def test_double_free_of_a_state_is_refused(quad):
    quad.start()
    state = quad.slave.getFMUstate()
    copy = fmi2FMUstate(state.value)
    quad.slave.freeFMUstate(state)
    assert state.value is None, "the FMU cleared the pointer"
    quad.slave.freeFMUstate(state)  # NULL: ignored, as the standard says
    with pytest.raises(FMICallException):
        quad.slave.fmi2FreeFMUstate(quad.slave.component, byref(copy))
    assert "not a live state of this instance" in quad.last_message()


def test_two_instances_side_by_side_stay_independent(fmus):
    a = LoggedSlave(fmus["Quadrotor"], name="a")
    b = LoggedSlave(fmus["Quadrotor"], name="b")
    try:
        a.slave.setReal([a.vrs["initial_z"]], [3.0])
        a.start()
        b.start()
        a.slave.doStep(currentCommunicationPoint=0.0, communicationStepSize=0.5)
        assert b.real("z") == [1.5]
        assert a.real("z") != [1.5]
        with pytest.raises(FMICallException):
            b.slave.doStep(currentCommunicationPoint=0.5, communicationStepSize=0.5)
        assert all("fmi2DoStep" not in m for _, _, m in a.messages)
        b.slave.doStep(currentCommunicationPoint=0.0, communicationStepSize=0.5)
    finally:
        a.close()
        b.close()
