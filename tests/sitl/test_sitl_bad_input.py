"""Bad input from the network: thousands of malformed datagrams from another peer while a
client keeps stepping. Every step is still answered exactly as in an undisturbed run, and every
kind of bad input is counted."""

from __future__ import annotations

import math
import random
import struct

from sitl_client import Client, decode_frame, mavlink2, of_type, statustexts

STEPS = 300
JUNK_PER_STEP = 10


def motors(k: int) -> list[float]:
    return [0.5 + 0.03 * math.sin(k / 5), 0.5, 0.5 - 0.03 * math.sin(k / 5), 0.5]


def contents(msgs) -> list:
    return [m.to_dict() for m in msgs]


def junk_datagrams(fuzzer: Client, rng: random.Random):
    """Yields malformed or refused datagrams of every kind, forever."""
    good = fuzzer.controls([0.5] * 4, system_id=1)
    while True:
        kind = rng.randrange(9)
        if kind == 0:  # random bytes
            yield bytes(rng.randrange(256) for _ in range(rng.randrange(1, 300)))
        elif kind == 1:  # a valid frame cut short
            yield good[: rng.randrange(1, len(good))]
        elif kind == 2:  # one flipped bit: a bad checksum (or a bad header)
            b = bytearray(good)
            b[rng.randrange(10, len(b))] ^= 1 << rng.randrange(8)
            yield bytes(b)
        elif kind == 3:  # MAVLink 1
            payload = bytes(rng.randrange(256) for _ in range(9))
            yield bytes([0xFE, 9, 0, 1, 1, 0]) + payload + b"\x00\x00"
        elif kind == 4:  # a message id outside the common dialect
            b = bytearray(good)
            b[7:10] = struct.pack("<I", 0xABCDE)[:3]
            yield bytes(b)
        elif kind == 5:  # NaN / inf controls for the stepped vehicle: refused
            bad = rng.choice([math.nan, math.inf, -math.inf])
            yield fuzzer.controls([0.5, bad, 0.5, 0.5], system_id=1)
        elif kind == 6:  # controls for a system id no vehicle has
            yield fuzzer.controls([0.5] * 4, system_id=rng.choice([0, 3, 200, 255]))
        elif kind == 7:  # out-of-range controls for the other vehicle: clamped, stepped
            yield fuzzer.controls([rng.uniform(-1e6, 1e6) for _ in range(4)], system_id=2)
        else:  # several frames in one datagram, good and bad mixed, for vehicle 2
            yield fuzzer.controls([0.5] * 4, system_id=2) + bytes([0xFD, 3]) + good[:5]


def test_malformed_datagrams_never_disturb_the_stepping_client(start_sitl, client_for):
    reference = client_for(start_sitl("--vehicles", "2", "--seed", "8"))
    expected = [contents(reference.step(motors(k))) for k in range(STEPS)]

    sitl = start_sitl("--vehicles", "2", "--seed", "8", "--log-level", "debug")
    client = client_for(sitl)
    fuzzer = client_for(sitl)
    rng = random.Random(1234)
    junk = junk_datagrams(fuzzer, rng)
    for k in range(STEPS):
        for _ in range(JUNK_PER_STEP):
            fuzzer.send_raw(next(junk))
        assert contents(client.step(motors(k))) == expected[k], f"step {k}"
    # The fuzzer got answers only where one is due: refused controls (NaN, unknown system
    # ids; rate-limited texts) and vehicle 2's steps.
    answers = fuzzer.drain(0.5)
    warnings = statustexts(answers)
    assert warnings and all("step refused" in t for t in warnings)
    assert any("no such vehicle" in t for t in warnings)
    assert {m.get_srcSystem() for m in of_type(answers, "DEBUG_FLOAT_ARRAY")} == {2}

    assert sitl.stop() == 0
    stats = sitl.stats()
    for counter in (
        "truncated",
        "bad_crc",
        "mavlink1",
        "unknown_message",
        "garbage",
        "refused_controls",
        "clamped_controls",
        "unknown_vehicle",
    ):
        assert stats[counter] > 0, counter
    assert stats["datagrams"] == STEPS * (JUNK_PER_STEP + 1)
    assert "frame skipped" in sitl.stderr()  # reported at debug level


def test_a_nan_control_is_refused_with_a_statustext_and_no_step(start_sitl, client_for):
    client = client_for(start_sitl())
    first = decode_frame(client.step([0.5] * 4), 1)
    refused = client.step([0.5, 0.5, math.nan, 0.5])
    assert [m.get_type() for m in refused] == ["STATUSTEXT"]
    assert refused[0].text == "vehicle 1: controls[2] = nan: step refused".replace("nan", "NaN")
    assert refused[0].severity == mavlink2.MAV_SEVERITY_WARNING
    assert decode_frame(client.step([0.5] * 4), 1).step == first.step + 1
    # Channels past the task's four are not used, so a NaN there is harmless.
    assert decode_frame(client.step([0.5] * 4 + [math.nan]), 1).step == first.step + 2


def test_controls_in_mavlink_1_are_refused_with_a_statustext(start_sitl, client_for):
    from pymavlink.dialects.v10 import common as mavlink1

    sitl = start_sitl()
    client = client_for(sitl)
    mav = mavlink1.MAVLink(None, srcSystem=1)
    v1 = mav.hil_actuator_controls_encode(10_000, [0.5] * 16, 0, 1).pack(mav)
    assert v1[0] == 0xFE  # a MAVLink 1 frame, as pymavlink's mavutil sends by default
    assert statustexts(client.exchange(v1)) == [
        "system 1: controls in MAVLink 1, which this SITL does not read "
        "(pymavlink: set MAVLINK20=1): step refused"
    ]
    assert sitl.stop() == 0
    stats = sitl.stats()
    assert (stats["mavlink1"], stats["steps"], stats["refusal_texts"]) == (1, 0, 1)
