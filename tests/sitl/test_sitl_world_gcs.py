"""A ground station on a multi-agent world (`--task multi_hover|swap --vehicles N`): each
vehicle is its own MAVLink system (ids 1..N) streaming the single-vehicle telemetry while a
controller steps the world; SET_MESSAGE_INTERVAL per system; collisions and faults as
STATUSTEXT from the vehicle; the parameter protocol per system id; and HEARTBEAT's MAV_TYPE
from the frame's rotor count. The lockstep replies do not change (the native = SITL tests
in python/tests/test_multi_agent_sitl.py run with the ground-station link off)."""

from __future__ import annotations

import pytest
from mavproxy_peer import MavProxy
from sitl_client import (
    LOCKSTEP,
    Client,
    GroundStation,
    free_udp_port,
    local_ned,
    mavlink2,
    of_type,
    statustexts,
)


def world_step(client: Client, n: int, controls) -> list:
    """One world step: every vehicle's command (system ids 1..n) in one datagram, unnamed
    (time_usec 0: always a new step)."""
    padded = list(controls) + [0.0] * (16 - len(controls))
    msg = mavlink2.MAVLink_hil_actuator_controls_message(0, padded, 0, LOCKSTEP)
    data = b"".join(client.pack(msg, s) for s in range(1, n + 1))
    return client.exchange(data)


@pytest.fixture
def world(start_sitl, client_for, tmp_path):
    """Starts a world `task` of `n` vehicles (a `--config` file of `config` if given) with a
    ground station; returns it, the SITL and a controller client."""

    def start(task: str, n: int, config: str | None = None, *args: str):
        if config is not None:
            path = tmp_path / "world.toml"
            path.write_text(config)
            args = (*args, "--config", str(path))
        gcs = GroundStation()
        sitl = start_sitl("--task", task, "--vehicles", str(n), *args,
                          gcs=f"127.0.0.1:{gcs.port}")  # fmt: skip
        return gcs, sitl, client_for(sitl)

    return start


def by_system(msgs: list, name: str) -> dict[int, list]:
    out: dict[int, list] = {}
    for m in of_type(msgs, name):
        out.setdefault(m.get_srcSystem(), []).append(m)
    return out


def texts_from(msgs: list, system: int) -> list[str]:
    return statustexts([m for m in msgs if m.get_srcSystem() == system])


@pytest.mark.parametrize(
    ("frame", "mav_type"),
    [
        (None, mavlink2.MAV_TYPE_QUADROTOR),
        ("hexa_x", mavlink2.MAV_TYPE_HEXAROTOR),
        ("octo_x", mavlink2.MAV_TYPE_OCTOROTOR),
    ],
)
def test_heartbeat_says_what_the_vehicle_is(start_sitl, tmp_path, frame, mav_type):
    args = []
    if frame:
        config = tmp_path / "frame.toml"
        config.write_text(f'[frame]\nname = "{frame}"\n')
        args = ["--config", str(config)]
    gcs = GroundStation()
    start_sitl(*args, gcs=f"127.0.0.1:{gcs.port}")
    beats = of_type(gcs.listen(1.2), "HEARTBEAT")
    assert beats and {b.type for b in beats} == {mav_type}


def test_a_ground_station_sees_every_vehicle_of_the_world_move(world):
    n = 3
    gcs, _, client = world("swap", n, None, "--seed", "4")
    msgs = gcs.listen(1.2)
    beats = by_system(msgs, "HEARTBEAT")
    assert sorted(beats) == [1, 2, 3]
    for b in (b for bs in beats.values() for b in bs):
        assert b.type == mavlink2.MAV_TYPE_QUADROTOR
        assert (b.base_mode, b.system_status) == (0, mavlink2.MAV_STATE_STANDBY)
    for name in ("ATTITUDE", "GLOBAL_POSITION_INT", "LOCAL_POSITION_NED", "SYS_STATUS"):
        assert sorted(by_system(msgs, name)) == [1, 2, 3], name
    start = {s: m[-1] for s, m in by_system(msgs, "LOCAL_POSITION_NED").items()}

    # A controller steps the world: every system's telemetry follows its own vehicle.
    client.reset(4, target=0)
    for _ in range(60):
        reply = world_step(client, n, [0.62, 0.62, 0.62, 0.62])
    truth = {m.get_srcSystem(): m for m in of_type(reply, "HIL_STATE_QUATERNION")}
    assert sorted(truth) == [1, 2, 3]
    msgs = gcs.listen(1.3)
    for s in (1, 2, 3):
        ned = by_system(msgs, "LOCAL_POSITION_NED")[s][-1]
        assert ned.time_boot_ms == 600
        assert start[s].z - ned.z > 0.3, (s, start[s], ned)  # it climbed
        north, east, down = local_ned(truth[s])
        assert abs(ned.x - north) < 0.01 and abs(ned.y - east) < 0.01
        assert abs(ned.z - down) < 0.01
        position = by_system(msgs, "GLOBAL_POSITION_INT")[s][-1]
        assert (position.lat, position.lon) == (truth[s].lat, truth[s].lon)
        beat = by_system(msgs, "HEARTBEAT")[s][-1]
        assert beat.base_mode == mavlink2.MAV_MODE_FLAG_SAFETY_ARMED
        assert beat.system_status == mavlink2.MAV_STATE_ACTIVE


def test_mavproxy_detects_every_vehicle_of_the_world(start_sitl, client_for, tmp_path):
    port = free_udp_port()
    mavproxy = MavProxy(tmp_path, f"--master=udpin:127.0.0.1:{port}", "--nowait")
    try:
        mavproxy.wait_for("Connect udpin", timeout=30)
        sitl = start_sitl("--task", "swap", "--vehicles", "3", gcs=f"127.0.0.1:{port}")
        for s in (1, 2, 3):
            mavproxy.wait_for(f"Detected vehicle {s}:1 on link 0", timeout=30)
        assert "ARMED" not in mavproxy.console()  # nothing flies yet
        client = client_for(sitl)
        client.reset(1, target=0)
        world_step(client, 3, [0.5] * 4)
        mavproxy.wait_for("ARMED", timeout=10)  # a controller flies the world
    finally:
        mavproxy.kill()


def test_message_intervals_and_requests_are_per_system(world):
    gcs, _, _ = world("multi_hover", 3)
    gcs.listen(0.3)
    gcs.command(mavlink2.MAV_CMD_SET_MESSAGE_INTERVAL, [mavlink2.MAVLINK_MSG_ID_ATTITUDE, -1],
                target=2)  # fmt: skip
    acks = by_system(gcs.listen(1.0), "COMMAND_ACK")
    assert sorted(acks) == [2] and acks[2][0].result == mavlink2.MAV_RESULT_ACCEPTED
    counts = {s: len(m) for s, m in by_system(gcs.listen(1.0), "ATTITUDE").items()}
    assert 2 not in counts and counts[1] >= 8 and counts[3] >= 8, counts  # 10 Hz
    gcs.command(mavlink2.MAV_CMD_SET_MESSAGE_INTERVAL, [mavlink2.MAVLINK_MSG_ID_ATTITUDE, 50_000],
                target=0)  # fmt: skip
    gcs.listen(0.1)
    counts = {s: len(m) for s, m in by_system(gcs.listen(1.0), "ATTITUDE").items()}
    assert min(counts.values()) >= 15 and sorted(counts) == [1, 2, 3], counts  # 20 Hz
    # Requests are answered by the system asked.
    gcs.command(mavlink2.MAV_CMD_REQUEST_MESSAGE, [mavlink2.MAVLINK_MSG_ID_AUTOPILOT_VERSION],
                target=2)  # fmt: skip
    msgs = gcs.listen(0.3)
    versions = of_type(msgs, "AUTOPILOT_VERSION")
    assert [(v.get_srcSystem(), v.uid) for v in versions] == [(2, 2)]
    assert [a.get_srcSystem() for a in of_type(msgs, "COMMAND_ACK")] == [2]
    # A system the world does not have is not answered.
    gcs.command(mavlink2.MAV_CMD_SET_MESSAGE_INTERVAL, [mavlink2.MAVLINK_MSG_ID_ATTITUDE, -1],
                target=7)  # fmt: skip
    assert of_type(gcs.listen(0.3), "COMMAND_ACK") == []


def test_a_collision_is_said_by_both_vehicles(world):
    config = "hover_spacing = 0.32\ncollision_penalty = 10.0\nmax_steps = 100\n"
    gcs, _, client = world("multi_hover", 2, config)
    gcs.listen(0.2)
    texts: dict[int, list[str]] = {1: [], 2: []}
    for seed in range(12):
        client.reset(seed, target=0)
        for _ in range(100):
            reply = world_step(client, 2, [0.8] * 4)
            if any(m.get_type() == "DEBUG_FLOAT_ARRAY" and m.array_id == 1 and m.data[1]
                   for m in reply):  # fmt: skip
                break
        msgs = gcs.listen(0.2)
        for s in (1, 2):
            texts[s] += [t for t in texts_from(msgs, s) if t.startswith("collision")]
        if texts[1]:
            break
    assert texts[1], "no collision in 12 episodes of two vehicles 2 cm apart"
    assert texts[1] == texts[2]
    assert texts[1][0].startswith("collision of vehicles 1 and 2 at t=")
    assert "closing at" in texts[1][0]
    severities = {m.severity for m in of_type(msgs, "STATUSTEXT")}
    assert mavlink2.MAV_SEVERITY_CRITICAL in severities


def test_a_fault_is_said_by_its_vehicle(world):
    config = '[[faults]]\nkind = "motor_off"\nmotor = 2\nat = 0.2\nagent = 1\n'
    gcs, _, client = world("multi_hover", 3, config)
    gcs.listen(0.2)
    client.reset(5, target=0)
    for _ in range(30):  # past 0.2 s
        world_step(client, 3, [0.6] * 4)
    msgs = gcs.listen(0.3)
    assert texts_from(msgs, 2) == ["fault fired: motor_off:2 at 0.200 s"]
    assert texts_from(msgs, 1) == [] and texts_from(msgs, 3) == []


def test_parameters_per_system(world):
    n = 3
    gcs, _, client = world("swap", n)
    gcs.listen(0.2)
    gcs.send(gcs.mav.param_request_list_encode(2, 1))
    values = of_type(gcs.listen(0.5), "PARAM_VALUE")
    assert values and {v.get_srcSystem() for v in values} == {2}
    count = values[0].param_count
    assert len(values) == count and sorted(v.param_index for v in values) == list(range(count))
    named = {v.param_id: v for v in values}
    assert named["num_agents"].param_value == 3.0
    assert named["mass"].param_type == mavlink2.MAV_PARAM_TYPE_REAL32
    assert "swap_radius" in named and "wind_enabled" in named

    def set_param(name: str, value: float, target: int) -> list:
        gcs.send(gcs.mav.param_set_encode(target, 1, name.encode(), value,
                                          mavlink2.MAV_PARAM_TYPE_REAL32))  # fmt: skip
        return gcs.listen(0.3)

    # One world, one table: a set through any system id is every vehicle's.
    msgs = set_param("mass", 1.2, 1)
    reported = by_system(msgs, "PARAM_VALUE")
    assert sorted(reported) == [1, 2, 3]
    assert all(abs(r[0].param_value - 1.2) < 1e-6 for r in reported.values())
    gcs.send(gcs.mav.param_request_read_encode(3, 1, b"mass", -1))
    read = of_type(gcs.listen(0.3), "PARAM_VALUE")
    assert [(r.get_srcSystem(), round(r.param_value, 6)) for r in read] == [(3, 1.2)]

    # Refused with the single-vehicle checks: PARAM_ERROR, a text naming the bound, the
    # unchanged value.
    msgs = set_param("mass", -1.0, 2)
    error = of_type(msgs, "PARAM_ERROR")[0]
    assert error.get_srcSystem() == 2 and error.error == mavlink2.MAV_PARAM_ERROR_VALUE_OUT_OF_RANGE
    text = texts_from(msgs, 2)[0]
    assert "`mass`" in text, text
    assert all(abs(v.param_value - 1.2) < 1e-6 for v in of_type(msgs, "PARAM_VALUE"))
    msgs = set_param("num_agents", 5.0, 1)
    assert "num_agents" in texts_from(msgs, 1)[0]
    msgs = set_param("no_such_thing", 1.0, 1)
    assert of_type(msgs, "PARAM_ERROR")[0].error == mavlink2.MAV_PARAM_ERROR_DOES_NOT_EXIST

    # The new mass flies from the world's next reset on: the same seed climbs less.

    def climb(seed: int) -> float:
        client.reset(seed, target=0)
        for _ in range(30):
            reply = world_step(client, n, [0.7] * 4)
        return local_ned(of_type(reply, "HIL_STATE_QUATERNION")[0])[2]

    heavy = climb(9)
    set_param("mass", 1.0, 0)
    light = climb(9)
    assert light < heavy - 0.01, (light, heavy)  # down is positive: lighter climbs higher
