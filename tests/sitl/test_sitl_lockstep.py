"""Lockstep over real UDP with pymavlink: a PD controller flies the quadrotor to its target and
holds it; every HIL_STATE_QUATERNION agrees with the core's state carried in the task frame,
converted ENU/FLU -> NED/FRD here independently of the SITL; runs are reproducible."""

from __future__ import annotations

import math

from sitl_client import (
    HOME,
    RESET_COMMAND,
    decode_frame,
    hover_info,
    local_ned,
    of_type,
    seed_params,
)

H = math.sqrt(0.5)
G = 9.81


def qmul(a, b):
    aw, ax, ay, az = a
    bw, bx, by, bz = b
    return (
        aw * bw - ax * bx - ay * by - az * bz,
        aw * bx + ax * bw + ay * bz - az * by,
        aw * by - ax * bz + ay * bw + az * bx,
        aw * bz + ax * by - ay * bx + az * bw,
    )


def ned_quaternion(q_enu_flu):
    """Body FRD -> world NED from body FLU -> world ENU (w >= 0)."""
    q = qmul(qmul((0.0, H, H, 0.0), q_enu_flu), (0.0, 1.0, 0.0, 0.0))
    return q if q[0] >= 0 else tuple(-v for v in q)


def euler(q):
    w, x, y, z = q
    roll = math.atan2(2 * (w * x + y * z), 1 - 2 * (x * x + y * y))
    pitch = math.asin(max(-1.0, min(1.0, 2 * (w * y - z * x))))
    yaw = math.atan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z))
    return roll, pitch, yaw


def pd_motors(state, target_ned):
    """A small cascaded PD: position -> tilt -> motor mix (PX4 quad-X: FR, RL, FL, RR)."""
    n, e, d = local_ned(state)
    vn, ve, vd = state.vx / 100, state.vy / 100, state.vz / 100
    roll, pitch, yaw = euler(state.attitude_quaternion)
    tn, te, td = target_ned
    an, ae, ad = 1.2 * (tn - n) - 1.8 * vn, 1.2 * (te - e) - 1.8 * ve, 2.0 * (td - d) - 2.5 * vd

    def clamp(v, limit):
        return max(-limit, min(limit, v))

    forward = math.cos(yaw) * an + math.sin(yaw) * ae
    right = -math.sin(yaw) * an + math.cos(yaw) * ae
    pitch_wanted, roll_wanted = clamp(-forward / G, 0.35), clamp(right / G, 0.35)
    u_roll = 0.06 * (roll_wanted - roll) - 0.02 * state.rollspeed
    u_pitch = 0.06 * (pitch_wanted - pitch) - 0.02 * state.pitchspeed
    u_yaw = -0.02 * state.yawspeed
    hover = math.sqrt(G / 40)  # T = 10 N m^2 per motor, 1 kg
    tilt = math.sqrt(max(0.5, math.cos(roll) * math.cos(pitch)))
    h = hover * (1 + 0.5 * clamp(-ad / G, 0.5)) / tilt
    mix = [
        h - u_roll + u_pitch + u_yaw,
        h + u_roll - u_pitch + u_yaw,
        h + u_roll + u_pitch - u_yaw,
        h - u_roll - u_pitch - u_yaw,
    ]
    return [min(1.0, max(0.0, m)) for m in mix]


def check_state_matches_frame(state, frame):
    """HIL_STATE_QUATERNION (spec units, NED/FRD) against the core's ENU/FLU values."""
    info = hover_info(frame)
    x, y, z = info["position"]
    n, e, d = local_ned(state)
    assert abs(n - y) < 0.012 and abs(e - x) < 0.012, (n, e, x, y)
    assert abs(state.alt - round((HOME[2] + z) * 1000)) <= 1
    assert abs(d + z) < 0.002
    vx, vy, vz = frame.obs[3:6]  # world ENU velocity
    expected = (vy * 100, vx * 100, -vz * 100)
    assert all(
        abs(a - b) <= 0.51 for a, b in zip((state.vx, state.vy, state.vz), expected, strict=True)
    )
    q = ned_quaternion(frame.obs[9:13])
    assert all(abs(a - b) < 2e-6 for a, b in zip(state.attitude_quaternion, q, strict=True))
    wx, wy, wz = frame.obs[13:16]  # body FLU rates
    assert (state.rollspeed, state.pitchspeed, state.yawspeed) == (wx, -wy, -wz)
    assert state.time_usec == frame.time_usec


def test_a_pd_controller_flies_to_the_target_and_holds_it(start_sitl, client_for):
    sitl = start_sitl("--seed", "3")
    client = client_for(sitl)
    assert of_type(client.param_set("wind_enabled", 0), "PARAM_VALUE")[0].param_value == 0.0
    msgs = client.reset(11)
    assert of_type(msgs, "COMMAND_ACK")[0].result == 0
    frame = decode_frame(msgs, 1)
    assert (frame.step, frame.reward, frame.terminated) == (0, 0.0, False)
    tx, ty, tz = hover_info(frame)["target_position"]
    target_ned = (ty, tx, -tz)
    state = of_type(msgs, "HIL_STATE_QUATERNION")[0]
    check_state_matches_frame(state, frame)
    start_error = math.dist(local_ned(state), target_ned)
    errors = []
    for k in range(800):
        msgs = client.step(pd_motors(state, target_ned))
        assert len(msgs) == 2, msgs
        state = of_type(msgs, "HIL_STATE_QUATERNION")[0]
        frame = decode_frame(msgs, 1)
        assert frame.step == k + 1 and state.time_usec == (k + 1) * 10_000
        assert not frame.terminated
        check_state_matches_frame(state, frame)
        errors.append(math.dist(local_ned(state), target_ned))
        # The task's distance agrees with the MAVLink position.
        assert abs(hover_info(frame)["distance_to_target"][0] - errors[-1]) < 0.02
    assert start_error > 1.0
    assert max(errors[-300:]) < 0.05, max(errors[-300:])
    assert frame.reward > 0.95


def test_a_level_start_facing_east_is_yaw_90_in_ned(start_sitl, client_for):
    client = client_for(start_sitl())
    assert of_type(client.param_set("start_att_rng", 0), "PARAM_VALUE")[0].param_value == 0.0
    client.param_set("wind_enabled", 0)  # no drag at rest
    msgs = client.reset(4)
    state = of_type(msgs, "HIL_STATE_QUATERNION")[0]
    assert all(
        abs(a - b) < 1e-7 for a, b in zip(state.attitude_quaternion, (H, 0, 0, H), strict=True)
    )
    roll, pitch, yaw = euler(state.attitude_quaternion)
    assert abs(roll) < 1e-7 and abs(pitch) < 1e-7 and abs(yaw - math.pi / 2) < 1e-6
    # At rest with hover thrust the accelerometer reads -1 g along body z (down).
    assert (state.xacc, state.yacc) == (0, 0) and abs(state.zacc + 1000) <= 1
    assert (state.lat, state.lon, state.alt) == (473977420, 85455940, 489500)


def open_loop_run(client, seed: int, steps: int) -> list[bytes]:
    """Reply datagrams of a reset and `steps` steps of a fixed, varying motor pattern."""
    replies = []
    client.send_raw(client.command(RESET_COMMAND, [*seed_params(seed), 0.0]))
    replies.append(client.receive()[0])
    for k in range(steps):
        wobble = 0.05 * math.sin(k / 7)
        client.send_raw(client.controls([0.5 + wobble, 0.5 - wobble, 0.49, 0.51]))
        replies.append(client.receive()[0])
    return replies


def test_the_same_seed_gives_the_same_byte_stream(start_sitl, client_for):
    runs = []
    for seed in (77, 77, 78):
        sitl = start_sitl("--seed", "5")
        runs.append(open_loop_run(client_for(sitl), seed, 300))
        sitl.stop()
    assert runs[0] == runs[1]
    assert sum(len(r) for r in runs[0]) > 300 * 200
    assert runs[0][0] != runs[2][0] and runs[0][-1] != runs[2][-1]


def payload(msgs) -> list:
    """Message contents without the ones that differ between episodes (seq, time)."""
    out = []
    for m in msgs:
        d = m.to_dict()
        d.pop("time_usec", None)
        out.append(d)
    return out


def test_a_reset_with_a_seed_reproduces_the_first_steps(start_sitl, client_for):
    client = client_for(start_sitl())
    episodes = []
    for _ in range(2):
        msgs = client.reset(2024)
        episode = [
            payload(of_type(msgs, "HIL_STATE_QUATERNION") + of_type(msgs, "DEBUG_FLOAT_ARRAY"))
        ]
        for k in range(60):
            episode.append(payload(client.step([0.6, 0.4, 0.5, 0.5 + 0.001 * k])))
        episodes.append(episode)
    assert episodes[0] == episodes[1]
    other = payload(of_type(client.reset(2025), "DEBUG_FLOAT_ARRAY"))
    assert other != episodes[0][0][1:]
