"""The ground-station link as its own peer: telemetry streams, requests, honest HEARTBEAT
flags, and a real MAVProxy that detects the vehicle, shows its attitude and says ARMED only
while a controller flies it."""

from __future__ import annotations

import math
import time

from mavproxy_peer import MavProxy
from sitl_client import GroundStation, decode_frame, free_udp_port, mavlink2, of_type


def test_the_ground_station_gets_heartbeats_and_telemetry(start_sitl, client_for):
    gcs = GroundStation()
    sitl = start_sitl("--home", "10.5,-20.25,30", gcs=f"127.0.0.1:{gcs.port}")
    msgs = gcs.listen(1.2)
    beats = of_type(msgs, "HEARTBEAT")
    assert beats and beats[0].get_srcSystem() == 1 and beats[0].get_srcComponent() == 1
    assert beats[0].type == mavlink2.MAV_TYPE_QUADROTOR
    assert beats[0].autopilot == mavlink2.MAV_AUTOPILOT_GENERIC
    assert 1 <= len(beats) <= 3
    assert len(of_type(msgs, "ATTITUDE")) >= 8  # 10 Hz
    home = of_type(msgs, "HOME_POSITION")[0]
    assert (home.latitude, home.longitude, home.altitude) == (105_000_000, -202_500_000, 30_000)
    position = of_type(msgs, "GLOBAL_POSITION_INT")[-1]
    assert (position.lat, position.lon, position.relative_alt) == (105_000_000, -202_500_000, 1500)
    assert of_type(msgs, "SYS_STATUS")[0].battery_remaining == -1  # no battery model
    assert of_type(msgs, "LOCAL_POSITION_NED")[-1].z == -1.5
    assert sitl.gcs_local[1] == gcs.sitl_address[1]

    # The ground station sees what the controller flies.
    client = client_for(sitl)
    for _ in range(30):
        msgs = client.step([0.52, 0.48, 0.5, 0.5])
    state = of_type(msgs, "HIL_STATE_QUATERNION")[0]
    attitude = of_type(gcs.listen(0.3), "ATTITUDE")[-1]
    w, x, y, z = state.attitude_quaternion
    roll = math.atan2(2 * (w * x + y * z), 1 - 2 * (x * x + y * y))
    assert abs(attitude.roll - roll) < 1e-6 and attitude.time_boot_ms == 300


def test_requests_and_intervals_on_the_ground_station_link(start_sitl):
    gcs = GroundStation()
    start_sitl("--model", "lander2d", gcs=f"127.0.0.1:{gcs.port}")
    gcs.listen(0.3)
    gcs.command(mavlink2.MAV_CMD_REQUEST_MESSAGE, [mavlink2.MAVLINK_MSG_ID_AUTOPILOT_VERSION])
    msgs = gcs.listen(0.3)
    ack = of_type(msgs, "COMMAND_ACK")[0]
    assert (ack.command, ack.result) == (mavlink2.MAV_CMD_REQUEST_MESSAGE, 0)
    version = of_type(msgs, "AUTOPILOT_VERSION")[0]
    assert version.capabilities & mavlink2.MAV_PROTOCOL_CAPABILITY_MAVLINK2
    assert (
        of_type(msgs, "SYS_STATUS") == [] or of_type(msgs, "SYS_STATUS")[0].battery_remaining == 100
    )

    gcs.command(mavlink2.MAV_CMD_SET_MESSAGE_INTERVAL, [mavlink2.MAVLINK_MSG_ID_ATTITUDE, -1])
    gcs.listen(0.1)
    assert of_type(gcs.listen(0.5), "ATTITUDE") == []
    gcs.command(mavlink2.MAV_CMD_SET_MESSAGE_INTERVAL, [mavlink2.MAVLINK_MSG_ID_ATTITUDE, 50_000])
    assert len(of_type(gcs.listen(1.0), "ATTITUDE")) >= 15  # 20 Hz
    gcs.command(mavlink2.MAV_CMD_REQUEST_MESSAGE, [4242])
    assert of_type(gcs.listen(0.3), "COMMAND_ACK")[0].result == mavlink2.MAV_RESULT_UNSUPPORTED
    # The lander's battery is reported in percent.
    status = of_type(gcs.listen(1.1), "SYS_STATUS")[0]
    assert status.battery_remaining == 100 and status.voltage_battery == 16_800


def test_mavproxy_detects_the_vehicle_and_shows_its_attitude(start_sitl, client_for, tmp_path):
    port = free_udp_port()
    mavproxy = MavProxy(tmp_path, f"--master=udpin:127.0.0.1:{port}", "--nowait")
    try:
        mavproxy.wait_for("Connect udpin", timeout=30)
        sitl = start_sitl("--seed", "6", gcs=f"127.0.0.1:{port}")
        frame = decode_frame(client_for(sitl).reset(6), 1)
        mavproxy.wait_for("Detected vehicle 1:1 on link 0", timeout=30)
        mavproxy.wait_for("online system 1", timeout=30)
        time.sleep(0.5)  # a few ATTITUDE messages at 10 Hz
        mavproxy.type("status ATTITUDE")
        line = mavproxy.wait_for("ATTITUDE {", timeout=10)
    finally:
        mavproxy.kill()
    fields = dict(
        kv.split(" : ") for kv in line.split("ATTITUDE {", 1)[1].strip().rstrip("}").split(", ")
    )
    # The start attitude of seed 6, from the task frame's quaternion (ENU/FLU): yaw_ned =
    # 90 deg - yaw_enu.
    w, x, y, z = frame.obs[9:13]
    yaw_enu = math.atan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z))
    assert abs(float(fields["yaw"]) - (math.pi / 2 - yaw_enu)) < 1e-5, fields
    assert abs(float(fields["roll"])) < 0.11 and abs(float(fields["pitch"])) < 0.11


def armed_and_state(gcs: GroundStation, seconds: float = 1.3) -> tuple[bool, int]:
    """The last HEARTBEAT's armed flag and system status (HEARTBEAT comes at 1 Hz)."""
    beat = of_type(gcs.listen(seconds), "HEARTBEAT")[-1]
    assert beat.base_mode & ~mavlink2.MAV_MODE_FLAG_SAFETY_ARMED == 0, beat  # no other flag
    return bool(beat.base_mode & mavlink2.MAV_MODE_FLAG_SAFETY_ARMED), beat.system_status


def test_heartbeat_says_armed_only_while_a_controller_flies(start_sitl, client_for, tmp_path):
    # Regression: a lockstep SITL nobody stepped said SAFETY_ARMED and MAV_STATE_ACTIVE.
    config = tmp_path / "short.toml"
    config.write_text("max_steps = 20\n")
    gcs = GroundStation()
    sitl = start_sitl("--config", str(config), gcs=f"127.0.0.1:{gcs.port}")
    standby, active = mavlink2.MAV_STATE_STANDBY, mavlink2.MAV_STATE_ACTIVE
    assert armed_and_state(gcs) == (False, standby)  # nothing flies it
    client = client_for(sitl)
    for _ in range(5):
        client.step([0.5] * 4)
    assert armed_and_state(gcs) == (True, active)  # a controller flies it
    for _ in range(15):
        frame = decode_frame(client.step([0.5] * 4), 1)
    assert frame.truncated  # the episode's time limit
    assert armed_and_state(gcs) == (False, standby)
    client.reset(3)
    client.step([0.5] * 4)
    assert armed_and_state(gcs) == (True, active)
    client.reset(4)  # a new episode no controller has stepped yet
    assert armed_and_state(gcs) == (False, standby)


def test_mavproxy_says_armed_only_while_a_controller_flies(start_sitl, client_for, tmp_path):
    port = free_udp_port()
    mavproxy = MavProxy(tmp_path, f"--master=udpin:127.0.0.1:{port}", "--nowait")
    try:
        mavproxy.wait_for("Connect udpin", timeout=30)
        sitl = start_sitl(gcs=f"127.0.0.1:{port}")
        mavproxy.wait_for("online system 1", timeout=30)
        # No flight modes, nothing armed: base_mode 0, which MAVProxy prints in hex.
        mavproxy.wait_for("Mode(0x00000000)", timeout=10)
        time.sleep(2.5)  # more heartbeats
        assert "ARMED" not in mavproxy.console()
        client = client_for(sitl)
        client.reset(1)
        client.step([0.5] * 4)
        mavproxy.wait_for("ARMED", timeout=10)
        client.reset(2)
        mavproxy.wait_for("DISARMED", timeout=10)
    finally:
        mavproxy.kill()
