"""The multi-agent envs on backend="sitl": one flyloop-sitl world (docs/protocol.md section
14) gives pettingzoo's API and seed tests, and the native env's observations, rewards, ends
and infos bit for bit (interfaces, randomisation, a collision); bad input names the item on
both backends; a client written from the protocol document alone (raw pymavlink) steps it."""

from __future__ import annotations

import os
import socket
import struct
import time

import numpy as np
import pytest
from pettingzoo.test import parallel_api_test, parallel_seed_test

import flyloop

os.environ.setdefault("MAVLINK20", "1")
from pymavlink.dialects.v20 import common as mavlink2  # noqa: E402

CASES = [
    ("flyloop/MultiHover-v0", "motors"),
    ("flyloop/MultiHover-v0", "rates"),
    ("flyloop/Swap-v1", "motors"),
    ("flyloop/Swap-v1", "rates"),
]
RANDOMIZE = {"mass": (0.8, 1.2), "thrust_coefficient": (9.0, 11.0)}


@pytest.fixture(autouse=True)
def _sitl(sitl_binary):
    """Every test here flies the release SITL binary."""


@pytest.mark.parametrize("env_id", ["flyloop/MultiHover-v0", "flyloop/Swap-v1"])
@pytest.mark.parametrize("interface", ["motors", "rates"])
def test_pettingzoo_api_and_seed_tests_pass_on_the_sitl(env_id, interface):
    env = flyloop.parallel_env(env_id, num_agents=3, backend="sitl", interface=interface)
    try:
        parallel_api_test(env, num_cycles=150)
    finally:
        env.close()
    made = []

    def make():
        made.append(flyloop.parallel_env(env_id, num_agents=3, backend="sitl", interface=interface))
        return made[-1]

    try:
        parallel_seed_test(make, num_cycles=60)
    finally:
        for e in made:
            e.close()


def _info_bytes(info: dict) -> bytes:
    """An info dict as bytes: every value at its own precision."""
    out = []
    for name in sorted(info):
        v = info[name]
        if name == "faults":  # the active faults: a list of dicts
            out.append(name.encode() + repr(v).encode())
            continue
        out.append(name.encode() + np.asarray(v, np.float64).tobytes())
    return b"".join(out)


def _trace(env, seeds, steps, actions):
    """Everything an env returns over episodes with `seeds`, as bytes per step; and whether
    any agent collided."""
    trace, collided = [], False
    for seed in seeds:
        obs, infos = env.reset(seed=seed)
        trace.append(
            b"".join(obs[a].tobytes() + _info_bytes(infos[a]) for a in env.possible_agents)
        )
        rng = np.random.default_rng(seed)
        for _ in range(steps):
            if not env.agents:
                break
            obs, rew, term, trunc, infos = env.step(actions(env, rng))
            collided |= any(i["collided"] for i in infos.values())
            trace.append(
                b"".join(
                    obs[a].tobytes()
                    + np.float64(rew[a]).tobytes()
                    + bytes([term[a], trunc[a]])
                    + _info_bytes(infos[a])
                    for a in sorted(obs)
                )
            )
    return trace, collided


def _random_actions(env, rng):
    space = env.action_space(env.possible_agents[0])
    low, high = space.low, space.high
    return {a: rng.uniform(low, high).astype(np.float32) for a in env.agents}


@pytest.mark.parametrize(("env_id", "interface"), CASES)
def test_native_and_sitl_give_the_same_bits(env_id, interface):
    kwargs = dict(
        num_agents=4,
        interface=interface,
        domain_randomization=RANDOMIZE,
        wind_enabled=True,
        max_steps=60,
    )
    native = flyloop.parallel_env(env_id, **kwargs)
    sitl = flyloop.parallel_env(env_id, backend="sitl", **kwargs)
    try:
        a, _ = _trace(native, (3, 4), 70, _random_actions)
        b, _ = _trace(sitl, (3, 4), 70, _random_actions)
    finally:
        sitl.close()
    assert len(a) > 100
    assert a == b


def test_native_and_sitl_give_the_same_bits_through_a_collision():
    kwargs = dict(num_agents=2, hover_spacing=0.32, collision_penalty=10.0, max_steps=100)

    def climb(env, rng):
        return {a: np.full(4, 0.8, np.float32) for a in env.agents}

    native = flyloop.parallel_env("flyloop/MultiHover-v0", **kwargs)
    sitl = flyloop.parallel_env("flyloop/MultiHover-v0", backend="sitl", **kwargs)
    try:
        a, collided = _trace(native, range(12), 100, climb)
        b, _ = _trace(sitl, range(12), 100, climb)
    finally:
        sitl.close()
    assert collided, "no collision in 12 episodes of two vehicles 2 cm apart"
    assert a == b


def test_native_and_sitl_give_the_same_bits_with_faults():
    """The fault tables parallel_env writes into the SITL's --config reach the world as they
    reach the in-process core (regression: the SITL refused `faults` as a non-number)."""
    kwargs = dict(
        num_agents=3,
        max_steps=80,
        faults=[{"kind": "motor_off", "motor": 2, "at": 0.2, "agent": "drone_1"}],
        fault_randomization={"kinds": ["motor_effectiveness"], "at": (0.0, 0.5),
                             "effectiveness": (0.5, 1.0)},
    )  # fmt: skip
    native = flyloop.parallel_env("flyloop/MultiHover-v0", **kwargs)
    sitl = flyloop.parallel_env("flyloop/MultiHover-v0", backend="sitl", **kwargs)
    try:
        a, _ = _trace(native, (5, 6), 80, _random_actions)
        b, _ = _trace(sitl, (5, 6), 80, _random_actions)
        sitl.reset(seed=5)
        for _ in range(40):  # past the written fault's 0.2 s
            _, _, _, _, infos = sitl.step({ag: np.full(4, 0.6, np.float32) for ag in sitl.agents})
    finally:
        sitl.close()
    assert len(a) > 100
    assert a == b
    fired = [f["fault"] for f in infos["drone_1"]["faults"]]
    assert "motor_off:2" in fired, infos["drone_1"]["faults"]


@pytest.mark.parametrize("backend", ["native", "sitl"])
def test_bad_input_names_the_item(backend):
    env = flyloop.parallel_env("flyloop/Swap-v1", num_agents=3, backend=backend)
    try:
        env.reset(seed=0)
        with pytest.raises(KeyError, match="drone_2"):
            env.step({a: np.zeros(4, np.float32) for a in ("drone_0", "drone_1")})
        bad = {a: np.full(4, 0.5, np.float32) for a in env.agents}
        bad["drone_1"][2] = np.nan
        with pytest.raises(ValueError, match=r"actions\[1, 2\] = NaN \(world 0, agent 1\)"):
            env.step(bad)
        obs, *_ = env.step({a: np.full(4, 0.5, np.float32) for a in env.agents})
        assert set(obs) == {"drone_0", "drone_1", "drone_2"}, "a refused step changes nothing"
    finally:
        env.close()
    too_many = 300 if backend == "sitl" else 70_000
    with pytest.raises(ValueError, match="num_agents"):
        flyloop.parallel_env("flyloop/Swap-v1", num_agents=too_many, backend=backend)
    with pytest.raises(ValueError, match="swap_radius"):
        flyloop.parallel_env("flyloop/Swap-v1", num_agents=3, backend=backend, swap_radius=-1.0)


def test_a_ground_station_sees_the_agents_of_a_sitl_env():
    """`gcs=` shows a ground station every agent as its own system, moving as the env steps;
    the env's bits are those of the native backend with the link on."""
    gcs = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    gcs.bind(("127.0.0.1", 0))
    gcs.settimeout(0.2)
    kwargs = dict(num_agents=3, max_steps=60)
    native = flyloop.parallel_env("flyloop/Swap-v1", **kwargs)
    sitl = flyloop.parallel_env(
        "flyloop/Swap-v1", backend="sitl", gcs=f"127.0.0.1:{gcs.getsockname()[1]}", **kwargs
    )

    def climb(env, rng):
        return {a: np.full(4, 0.6, np.float32) for a in env.agents}

    try:
        a, _ = _trace(native, (3,), 40, climb)
        b, _ = _trace(sitl, (3,), 40, climb)
        msgs, parser = [], mavlink2.MAVLink(None)
        end = time.monotonic() + 1.5
        while time.monotonic() < end:
            try:
                msgs += parser.parse_buffer(gcs.recv(65536)) or []
            except TimeoutError:
                pass
        positions, _ = sitl.positions()
    finally:
        sitl.close()
        gcs.close()
    assert a == b
    beats = {m.get_srcSystem() for m in msgs if m.get_type() == "HEARTBEAT"}
    assert beats == {1, 2, 3}
    local = {m.get_srcSystem(): m for m in msgs if m.get_type() == "LOCAL_POSITION_NED"}
    assert sorted(local) == [1, 2, 3]
    for s, m in local.items():  # the last step's place, NED from home (the env's is ENU)
        assert m.time_boot_ms == 400
        assert abs(m.x - positions[s - 1][1]) < 1e-4 and abs(m.y - positions[s - 1][0]) < 1e-4
        assert abs(m.z + positions[s - 1][2]) < 1e-4


def _world(sitl_binary, agents=2):
    from flyloop.sitl_process import SitlProcess

    args = ["--task", "swap", "--vehicles", str(agents), "--gcs", "off", "--seed", "5"]
    return SitlProcess(sitl_binary, args)


def _messages(data: bytes):
    return mavlink2.MAVLink(None).parse_buffer(data) or []


def test_a_client_written_from_the_protocol_document_steps_the_world(sitl_binary):
    """Section 14 by hand: one datagram of N commands steps the world once; commands split
    over datagrams wait (a STATUSTEXT names the missing vehicle); a re-sent step gets the
    same bytes; a reset addressed to one vehicle is denied."""
    proc = _world(sitl_binary)
    sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    sock.settimeout(5.0)
    mav = mavlink2.MAVLink(None, srcSystem=255)
    try:
        seed = 42
        pieces = [float((seed >> s) & 0xFFFF) for s in (0, 16, 32, 48)]
        sock.sendto(
            mav.command_long_encode(0, 1, 31010, 0, *pieces, 0, 0, 0).pack(mav), proc.address
        )
        reset = _messages(sock.recv(65536))
        assert reset[0].get_type() == "COMMAND_ACK" and reset[0].result == 0
        frames = [m for m in reset if m.get_type() == "DEBUG_FLOAT_ARRAY"]
        states = [m for m in reset if m.get_type() == "HIL_STATE_QUATERNION"]
        assert len(states) == 2 and {m.get_srcSystem() for m in frames} == {1, 2}
        assert all(m.name == "swap" and m.data[3] == 0.0 for m in frames if m.array_id == 1)

        def controls(system_id, step):
            mav.srcSystem = system_id
            return mav.hil_actuator_controls_encode(step, [0.5] * 4 + [0.0] * 12, 0, 1).pack(mav)

        both = controls(1, 10_000) + controls(2, 10_000)
        sock.sendto(both, proc.address)
        first = sock.recv(65536)
        stepped = [m for m in _messages(first) if m.get_type() == "DEBUG_FLOAT_ARRAY"]
        heads = [m for m in stepped if m.array_id == 1]
        assert [m.get_srcSystem() for m in heads] == [1, 2]
        assert all(m.time_usec == 10_000 and m.data[3] == 1.0 for m in heads)
        # n_obs, n_info, then after the info: active and the reward's f64 bits.
        values = [
            np.concatenate([m.data for m in stepped if m.get_srcSystem() == s]) for s in (1, 2)
        ]
        for v in values:
            n_obs, n_info = int(v[4]), int(v[5])
            extra = v[6 + n_obs + n_info : 6 + n_obs + n_info + 5]
            bits = sum(int(p) << s for p, s in zip(extra[1:], (0, 16, 32, 48), strict=True))
            reward = struct.unpack("<d", bits.to_bytes(8, "little"))[0]
            assert extra[0] == 1.0 and np.float32(reward) == np.float32(v[0])

        sock.sendto(both, proc.address)  # a lost reply: the step is sent again
        assert sock.recv(65536) == first, "a repeated step gets the cached reply, not a step"

        sock.sendto(controls(2, 20_000), proc.address)
        held = _messages(sock.recv(65536))
        # A text longer than STATUSTEXT's 50 characters comes in chunks (one id).
        assert {m.get_type() for m in held} == {"STATUSTEXT"}
        text = "".join(m.text for m in held)
        assert text == "world: step held, waiting for the commands of vehicles 1 (1 of 2 in)"
        sock.sendto(controls(1, 20_000), proc.address)
        done = [m for m in _messages(sock.recv(65536)) if m.get_type() == "DEBUG_FLOAT_ARRAY"]
        assert {m.time_usec for m in done} == {20_000}
        assert {m.get_srcSystem() for m in done} == {1, 2}

        mav.srcSystem = 255
        sock.sendto(
            mav.command_long_encode(1, 1, 31010, 0, *pieces, 0, 0, 0).pack(mav), proc.address
        )
        denied = _messages(sock.recv(65536))
        assert denied[0].get_type() == "COMMAND_ACK" and denied[0].result == 2  # DENIED
        assert "send it to target_system 0, not 1" in "".join(m.text for m in denied[1:])
    finally:
        sock.close()
        code = proc.stop()
    assert code == 0
