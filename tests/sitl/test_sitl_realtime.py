"""Real time: the wall clock paces physics, the last command holds, state streams to the
controller, and a silent controller trips the failsafe (motors off, announced)."""

from __future__ import annotations

import time

from sitl_client import local_ned, of_type, statustexts


def test_streams_at_the_configured_rate_and_fails_safe_when_commands_stop(start_sitl, client_for):
    sitl = start_sitl("--realtime", "--failsafe-timeout", "0.3", "--state-rate", "25")
    client = client_for(sitl)
    client.param_set("wind_enabled", 0)
    client.param_set("en_crash_det", 0)  # landing on the ground does not end the episode
    assert of_type(client.reset(1), "COMMAND_ACK")[0].result == 0
    # Nothing streams before the first command: the vehicle waits.
    assert client.drain(0.2) == []
    hover = [(9.81 / 40) ** 0.5] * 4
    start = time.monotonic()
    received = []
    while time.monotonic() - start < 1.0:
        client.send_raw(client.controls(hover))
        received.extend(client.drain(0.02))
    states = of_type(received, "HIL_STATE_QUATERNION")
    elapsed = time.monotonic() - start
    assert 0.6 * 25 * elapsed <= len(states) <= 1.4 * 25 * elapsed, len(states)
    sim_time = (states[-1].time_usec - states[0].time_usec) / 1e6
    wall_time = elapsed * len(states[1:]) / len(states)
    assert abs(sim_time - wall_time) < 0.25 * wall_time, (sim_time, wall_time)
    assert abs(local_ned(states[-1])[2] + 1.5) < 0.05, "hover thrust holds the height"

    # The controller goes silent: motors off after 0.3 s, said in a STATUSTEXT.
    silent = client.drain(1.0)
    texts = statustexts(silent)
    assert any("failsafe" in t and "motors off" in t for t in texts), texts
    heights = [-local_ned(s)[2] for s in of_type(silent, "HIL_STATE_QUATERNION")]
    assert heights[-1] < heights[0] - 0.3, "falling with the motors off"

    # Commands again: failsafe cleared.
    back = []
    for _ in range(10):
        client.send_raw(client.controls(hover))
        back.extend(client.drain(0.02))
    assert any("failsafe cleared" in t for t in statustexts(back))
