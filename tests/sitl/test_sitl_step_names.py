"""How a lockstep command's time_usec names its step, over real UDP with pymavlink
(docs/protocol.md 3.1 and 12):

- a client naming each step by the simulation time it starts at (PX4's convention for
  HIL_ACTUATOR_CONTROLS) steps every time and gets the bytes a client naming it by the time
  it ends at gets;
- only a command equal to the last step's name is a repeat: its cached reply, no step;
- a late duplicate is refused with a STATUSTEXT and counted;
- a flood of refused commands is answered with at most 5 STATUSTEXTs per second.
"""

from __future__ import annotations

import time

from sitl_client import mavlink2, seed_params, statustexts

STEPS = 400
DT_US = 10_000  # the hover task's control period
TEXTS_PER_SECOND = 5  # the SITL's rate limit of refusal texts per peer


def frame_time(msgs: list) -> int:
    return next(m.time_usec for m in msgs if m.get_type() == "DEBUG_FLOAT_ARRAY")


def motors(k: int) -> list[float]:
    return [0.49 + 0.003 * (k % 11), 0.5, 0.5, 0.5 - 0.002 * (k % 5)]


def test_start_named_and_end_named_steps_give_the_same_bytes(start_sitl, client_for):
    by_start = client_for(start_sitl("--seed", "21"))
    by_end = client_for(start_sitl("--seed", "21"))
    heard = {by_start: 0, by_end: 0}  # the clock in each client's last reply
    trajectories: dict = {by_start: [], by_end: []}
    for k in range(STEPS):
        if k == STEPS // 2:  # a reset in the middle; the clock runs on
            for c in heard:
                data = c.command(mavlink2.MAV_CMD_USER_1, [*seed_params(7), 0.0])
                c.send_raw(data)
                raw, msgs = c.receive()
                trajectories[c].append(raw)
                heard[c] = frame_time(msgs)
        for c, name in ((by_start, heard[by_start]), (by_end, heard[by_end] + DT_US)):
            c.send_raw(c.controls(motors(k), time_usec=name))
            raw, msgs = c.receive()
            trajectories[c].append(raw)
            heard[c] = frame_time(msgs)
        assert heard[by_start] == heard[by_end] == (k + 1) * DT_US, k
    assert trajectories[by_start] == trajectories[by_end]  # bit for bit, every datagram


def test_a_repeat_is_answered_from_the_cache_without_stepping(start_sitl, client_for):
    sitl = start_sitl()
    client = client_for(sitl)
    client.step([0.5] * 4)  # unnamed first step: clock 10,000 us
    command = client.controls([0.52, 0.5, 0.5, 0.5], time_usec=DT_US)  # named by its start
    client.send_raw(command)
    first, msgs = client.receive()
    assert frame_time(msgs) == 2 * DT_US
    for _ in range(3):
        client.send_raw(command)
        assert client.receive()[0] == first  # the cached bytes
    # The clock did not move: the next start-named step ends at 30,000 us.
    assert frame_time(client.exchange(client.controls([0.5] * 4, time_usec=2 * DT_US))) == 3 * DT_US
    assert sitl.stop() == 0
    stats = sitl.stats()
    assert (stats["steps"], stats["repeated_steps"], stats["stale_controls"]) == (3, 3, 0)


def test_a_late_duplicate_gets_a_statustext_and_is_counted(start_sitl, client_for):
    sitl = start_sitl()
    client = client_for(sitl)
    for k in range(1, 4):
        client.exchange(client.controls([0.5] * 4, time_usec=k * DT_US))
    late = client.exchange(client.controls([0.5] * 4, time_usec=DT_US))
    assert statustexts(late) == [
        "vehicle 1: time_usec 10000 is older than the clock, 30000 us (a late duplicate): "
        "step refused"
    ]
    assert all(m.severity == mavlink2.MAV_SEVERITY_WARNING for m in late)
    assert frame_time(client.exchange(client.controls([0.5] * 4, time_usec=4 * DT_US))) == 40_000
    assert sitl.stop() == 0
    stats = sitl.stats()
    assert (stats["steps"], stats["stale_controls"], stats["refusal_texts"]) == (4, 1, 1)


def test_a_flood_of_refused_commands_gets_rate_limited_statustexts(start_sitl, client_for):
    sitl = start_sitl()
    client = client_for(sitl)
    client.exchange(client.controls([0.5] * 4, time_usec=DT_US))
    client.exchange(client.controls([0.5] * 4, time_usec=2 * DT_US))
    late = client.controls([0.5] * 4, time_usec=DT_US)
    unflagged = client.pack(client.mav.hil_actuator_controls_encode(0, [0.5] * 16, 0, 0), 1)
    n = 2_000
    start = time.monotonic()
    for k in range(n):
        client.send_raw(late if k % 2 else unflagged)
    elapsed = time.monotonic() - start
    texts = statustexts(client.drain(1.0))
    windows = int(elapsed) + 1  # one-second windows the flood touched
    assert TEXTS_PER_SECOND <= len(texts) <= TEXTS_PER_SECOND * windows, (len(texts), elapsed)
    assert all(t.endswith("step refused") or "more refused since" in t for t in texts)
    assert sitl.stop() == 0
    stats = sitl.stats()
    assert stats["stale_controls"] == n // 2 and stats["unflagged_controls"] == n // 2, stats
    assert stats["refusal_texts"] == len(texts), stats
    assert stats["refusal_texts"] + stats["refusal_texts_held"] == n, stats
    assert stats["steps"] == 2, stats
    print(f"flood: {n} refused in {elapsed:.3f} s, {len(texts)} texts back")
