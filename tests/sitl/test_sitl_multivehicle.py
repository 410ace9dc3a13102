"""Several vehicles in one SITL: one datagram with commands for many gets one datagram back,
each vehicle is its own core instance with its own seed, and a vector env can leave
HIL_STATE_QUATERNION out of its replies."""

from __future__ import annotations

from sitl_client import decode_frame, mavlink2, of_type, seed_params, statustexts

N = 16


def batch_step(client, controls_by_vehicle) -> list:
    data = b"".join(client.controls(c, k) for k, c in controls_by_vehicle.items())
    return client.exchange(data)


def test_one_datagram_steps_sixteen_vehicles_and_one_comes_back(start_sitl, client_for):
    client = client_for(start_sitl("--vehicles", str(N), "--seed", "40"))
    msgs = batch_step(client, {k: [0.5] * 4 for k in range(1, N + 1)})
    states = of_type(msgs, "HIL_STATE_QUATERNION")
    assert [m.get_srcSystem() for m in states] == list(range(1, N + 1))
    frames = [decode_frame(msgs, k) for k in range(1, N + 1)]
    assert all(f.step == 1 for f in frames)
    # Own seeds: vehicle k started with seed 40 + k - 1, so every target differs.
    targets = {tuple(f.obs[0:3]) for f in frames}
    assert len(targets) == N
    # One reply datagram held everything: nothing else is waiting.
    assert client.drain(0.2) == []

    reply = client.set_interval(mavlink2.MAVLINK_MSG_ID_HIL_STATE_QUATERNION, -1, target=0)
    assert [a.result for a in of_type(reply, "COMMAND_ACK")] == [0] * N
    msgs = batch_step(client, {k: [0.5] * 4 for k in range(1, N + 1)})
    assert [m.get_type() for m in msgs] == ["DEBUG_FLOAT_ARRAY"] * N
    assert [decode_frame(msgs, k).step for k in range(1, N + 1)] == [2] * N
    # Turned back on (interval 0 = default).
    client.set_interval(mavlink2.MAVLINK_MSG_ID_HIL_STATE_QUATERNION, 0, target=0)
    assert len(of_type(batch_step(client, {3: [0.5] * 4}), "HIL_STATE_QUATERNION")) == 1


def test_vehicles_do_not_disturb_each_other(start_sitl, client_for):
    together = client_for(start_sitl("--vehicles", "3", "--seed", "9"))
    alone = client_for(start_sitl("--vehicles", "3", "--seed", "9"))
    for k in range(50):
        a = batch_step(
            together, {1: [0.9, 0.1, 0.5, 0.5], 2: [0.5, 0.5, 0.5, 0.52], 3: [0, 0, 0, 0]}
        )
        b = alone.step([0.5, 0.5, 0.5, 0.52], system_id=2)
        assert decode_frame(a, 2).values == decode_frame(b, 2).values, k


def test_a_reset_of_all_vehicles_gives_vehicle_k_seed_plus_k_minus_1(start_sitl, client_for):
    client = client_for(start_sitl("--vehicles", "4"))
    reset_all = client.command(mavlink2.MAV_CMD_USER_1, [*seed_params(500), 0], target=0)
    msgs = client.exchange(reset_all)
    assert [a.get_srcSystem() for a in of_type(msgs, "COMMAND_ACK")] == [1, 2, 3, 4]
    third = decode_frame(msgs, 3)
    single = decode_frame(client.reset(502, target=1), 1)
    assert third.obs == single.obs and third.step == 0


def test_controls_for_an_unknown_system_id_are_skipped_and_said_so(start_sitl, client_for):
    sitl = start_sitl("--vehicles", "2")
    client = client_for(sitl)
    msgs = batch_step(client, {7: [0.5] * 4, 2: [0.5] * 4})
    # The SITL's own texts come from vehicle 1; vehicle 2 stepped.
    assert [(m.get_type(), m.get_srcSystem()) for m in msgs if m.get_srcSystem() == 2] == [
        ("HIL_STATE_QUATERNION", 2),
        ("DEBUG_FLOAT_ARRAY", 2),
    ]
    assert statustexts(msgs) == ["system 7: no such vehicle (system ids 1..2): step refused"]
    assert sitl.stop() == 0
    assert sitl.stats()["unknown_vehicle"] == 1
