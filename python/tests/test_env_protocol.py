"""The short-path MAVLink coding of the step messages against pymavlink's own."""

from __future__ import annotations

import numpy as np
import pytest

from flyloop.protocol import (
    CLIENT_COMPONENT_ID,
    LOCKSTEP_FLAG,
    Datagram,
    Decoder,
    Encoder,
    ProtocolError,
    mavlink2,
    seed_params,
)


def pymavlink_packer(system_id: int, seq: int):
    mav = mavlink2.MAVLink(None, srcSystem=system_id, srcComponent=CLIENT_COMPONENT_ID)
    mav.seq = seq
    return mav


@pytest.mark.parametrize(
    "controls", [[0.5, 0.25, 1.0, 0.0], [0.0, 0.0, 0.0, 0.0], [-1.0, 0.7], [1e-30, 3.0, 0, 0]]
)
def test_controls_are_byte_for_byte_pymavlinks(controls):
    enc = Encoder()
    enc.sequence = 41
    ours = enc.controls(7, np.array(controls, np.float32))
    padded = [float(np.float32(c)) for c in controls] + [0.0] * (16 - len(controls))
    msg = mavlink2.MAVLink_hil_actuator_controls_message(0, padded, 0, LOCKSTEP_FLAG)
    assert ours == bytes(msg.pack(pymavlink_packer(7, 41)))
    assert enc.sequence == 42
    decoded = mavlink2.MAVLink(None).decode(bytearray(ours))
    assert decoded.get_srcSystem() == 7 and decoded.flags == LOCKSTEP_FLAG
    assert decoded.controls[: len(controls)] == pytest.approx(controls)


def frame(system_id: int, array_id: int, values) -> bytes:
    data = list(values) + [0.0] * (58 - len(values))
    msg = mavlink2.MAVLink_debug_float_array_message(123456, b"hover", array_id, data)
    return bytes(msg.pack(pymavlink_packer(system_id, 3)))


def test_task_frames_decode_to_pymavlinks_values_trailing_zeros_included():
    values = np.arange(1, 52, dtype=np.float32) / 7
    values[-5:] = 0.0  # MAVLink 2 drops trailing zero bytes: the decoder pads them back
    data = frame(2, 1, values) + frame(3, 2, [1.5]) + frame(2, 2, [])
    out = Decoder().decode(data, Datagram())
    np.testing.assert_array_equal(out.arrays[(2, 1)][:51], values)
    np.testing.assert_array_equal(out.arrays[(2, 1)][51:], 0.0)
    assert out.arrays[(3, 2)][0] == 1.5 and not out.arrays[(2, 2)].any()
    assert out.times[2] == 123456 and out.names[2] == "hover"
    assert out.messages == []


def test_other_messages_go_through_pymavlink():
    ack = mavlink2.MAVLink_command_ack_message(mavlink2.MAV_CMD_USER_1, 0, 0, 0, 255, 190)
    data = bytes(ack.pack(pymavlink_packer(1, 0))) + frame(1, 1, [0.5])
    out = Decoder().decode(data, Datagram())
    assert [m.get_type() for m in out.messages] == ["COMMAND_ACK"]
    assert out.messages[0].command == mavlink2.MAV_CMD_USER_1
    assert (1, 1) in out.arrays


def test_damaged_datagrams_are_protocol_errors():
    good = frame(1, 1, [1.0, 2.0])
    bad_crc = good[:-1] + bytes([good[-1] ^ 0xFF])
    with pytest.raises(ProtocolError, match="CRC"):
        Decoder().decode(bad_crc, Datagram())
    with pytest.raises(ProtocolError, match="ends inside"):
        Decoder().decode(good[:-3], Datagram())
    with pytest.raises(ProtocolError, match="not MAVLink 2"):
        Decoder().decode(b"\xfe" + good[1:], Datagram())


def test_seeds_travel_in_four_16_bit_pieces():
    assert seed_params(0xDEAD_BEEF_CAFE_F00D) == [0xF00D, 0xCAFE, 0xBEEF, 0xDEAD]
    reset = Encoder().reset(2**64 - 1, 4)
    msg = mavlink2.MAVLink(None).decode(bytearray(reset))
    assert msg.target_system == 4 and msg.command == mavlink2.MAV_CMD_USER_1
    assert [msg.param1, msg.param2, msg.param3, msg.param4, msg.param5] == [65535.0] * 4 + [0.0]


def test_a_batch_of_controls_is_pymavlinks_frames_back_to_back():
    enc = Encoder()
    enc.sequence = 254
    rows = [[0.1, 0.2, 0.3, 0.4], [0.0, 0.0, 0.0, 0.0], [1.0, -1.0, 0.5, 0.0]]
    ours = enc.controls_batch([1, 2, 3], np.array(rows, np.float32).tolist())
    want = b""
    for k, row in enumerate(rows):
        padded = [float(np.float32(c)) for c in row] + [0.0] * 12
        msg = mavlink2.MAVLink_hil_actuator_controls_message(0, padded, 0, LOCKSTEP_FLAG)
        want += bytes(msg.pack(pymavlink_packer(k + 1, (254 + k) % 256)))
    assert ours == want and enc.sequence == 1
