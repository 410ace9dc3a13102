"""The parameter protocol over the core's tables: list, read, set, refusals that change
nothing, and sets that take effect at the next reset."""

from __future__ import annotations

import struct

from sitl_client import decode_frame, mavlink2, of_type, statustexts


def texts(msgs) -> str:
    return " | ".join(statustexts(msgs))


def param_list(client, target=1) -> list:
    msg = client.mav.param_request_list_encode(target, 1)
    return of_type(client.exchange(client.pack(msg)), "PARAM_VALUE")


def test_the_list_serves_every_model_and_task_parameter_with_unique_short_ids(
    start_sitl, client_for
):
    client = client_for(start_sitl("--task", "waypoints"))
    values = param_list(client)
    ids = [v.param_id for v in values]
    # 30 quadrotor parameters (22 + 7 of the landing gear + turbulence_dt), 18 flight (12 +
    # the rates interface's 6), 4 waypoints, 27 of PX4's rate loop (its rotors are the frame's).
    assert len(values) == values[0].param_count == 30 + 18 + 4 + 27
    assert [v.param_index for v in values] == list(range(len(values)))
    assert len(set(ids)) == len(ids) and all(len(i) <= 16 for i in ids)
    by_id = {v.param_id: v for v in values}
    assert by_id["mass"].param_value == 1.0
    assert by_id["mass"].param_type == mavlink2.MAV_PARAM_TYPE_REAL32
    assert by_id["max_steps"].param_value == 1000.0
    assert by_id["max_steps"].param_type == mavlink2.MAV_PARAM_TYPE_INT32
    assert by_id["wind_enabled"].param_type == mavlink2.MAV_PARAM_TYPE_UINT8
    assert by_id["tgt_chg_intv"].param_value == 0.0  # target_change_interval
    assert by_id["max_num_wps"].param_value == 15.0  # max_num_waypoints
    assert abs(by_id["roll_rate_p"].param_value - 0.15) < 1e-6  # MC_ROLLRATE_P


def test_set_and_read_round_trip_and_refusals_change_nothing(start_sitl, client_for):
    client = client_for(start_sitl())
    reply = client.param_set("mass", 1.25)
    assert [m.get_type() for m in reply] == ["PARAM_VALUE"]
    assert (reply[0].param_id, reply[0].param_value) == ("mass", 1.25)
    read = of_type(client.param_read("mass"), "PARAM_VALUE")[0]
    assert read.param_value == 1.25 and read.param_index == 0
    by_index = client.pack(client.mav.param_request_read_encode(1, 1, b"", 0))
    assert of_type(client.exchange(by_index), "PARAM_VALUE")[0].param_id == "mass"

    refused = client.param_set("mass", -1.0)
    assert [m.get_type() for m in refused][0] == "PARAM_ERROR"
    assert refused[0].error == mavlink2.MAV_PARAM_ERROR_VALUE_OUT_OF_RANGE
    assert "`mass` = -1 kg is out of range: it must be in [0.001, 10000] kg" in texts(refused)
    assert of_type(refused, "PARAM_VALUE")[0].param_value == 1.25

    refused = client.param_set("max_steps", 10.5)
    assert refused[0].error == mavlink2.MAV_PARAM_ERROR_VALUE_OUT_OF_RANGE
    assert "is not an integer" in texts(refused)
    refused = client.param_set("wind_speed_min", 50.0)  # above wind_speed_max = 5
    assert "wind_speed_min" in texts(refused)
    assert of_type(refused, "PARAM_VALUE")[0].param_value == 0.0
    refused = client.param_set("no_such_param", 1.0)
    assert refused[0].error == mavlink2.MAV_PARAM_ERROR_DOES_NOT_EXIST
    assert not of_type(refused, "PARAM_VALUE")
    assert of_type(client.param_read("mass"), "PARAM_VALUE")[0].param_value == 1.25


def test_every_parameter_accepts_its_own_value(start_sitl, client_for):
    """A gym constructor argument is a task parameter: each one can be set over MAVLink."""
    for task in ("hover", "waypoints", "landing"):
        client = client_for(start_sitl("--task", task))
        for p in param_list(client):
            reply = client.param_set(p.param_id, p.param_value)
            assert [m.get_type() for m in reply] == ["PARAM_VALUE"], (task, p.param_id, reply)
            assert reply[0].param_value == p.param_value


def test_a_set_takes_effect_at_the_next_reset(start_sitl, client_for):
    client = client_for(start_sitl())
    client.param_set("max_steps", 5)
    client.param_set("dt", 0.02)
    frames = [decode_frame(client.step([0.5] * 4), 1) for _ in range(5)]
    assert not frames[-1].truncated, "the running episode keeps its parameters"
    assert frames[1].time_usec - frames[0].time_usec == 10_000
    start = decode_frame(client.reset(1), 1)
    frames = [decode_frame(client.step([0.5] * 4), 1) for _ in range(5)]
    assert [f.truncated for f in frames] == [False] * 4 + [True]
    assert frames[0].time_usec - start.time_usec == 20_000
    # 0.02 arrives as float32 but is read as the decimal 0.02 (not 0.0199999996).
    float32 = struct.unpack("<f", struct.pack("<f", 0.02))[0]
    assert of_type(client.param_read("dt"), "PARAM_VALUE")[0].param_value == float32


def test_a_lander_option_changes_the_observation_size(start_sitl, client_for):
    client = client_for(start_sitl("--model", "lander2d"))
    assert len(decode_frame(client.reset(3), 1).obs) == 11
    client.param_set("moving_platform", 1)
    assert len(decode_frame(client.reset(3), 1).obs) == 12
