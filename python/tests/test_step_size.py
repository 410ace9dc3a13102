"""The control period does not change the vehicle: QuadHover at dt = 0.01 and dt = 0.02 s,
flown by the same actions held per 0.02 s, gives the same observations bit for bit at every
0.02 s (the core integrates on its fixed 5 ms physics grid and samples the wind on its own
grid), over the SITL and in-process. Lander2D likewise on a 5 ms physics grid
(`physics_step`, through `model_params`): rapier steps, thrust noise and battery drain on the
grid whatever dt is."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest

import flyloop  # noqa: F401  (registers the envs)

SECONDS = 6.0  # a lift-off from the ground, a climb and a drift in the wind


def actions(n: int) -> np.ndarray:
    """One action per 0.02 s: a seeded walk around hover, first on the ground (motors low)."""
    rng = np.random.default_rng(3)
    a = np.clip(0.5 + 0.02 * rng.standard_normal((n, 4)).cumsum(axis=0) / 10, 0.3, 0.7)
    a[:25] = 0.2  # half a second at rest on its feet, then it lifts off
    return a.astype(np.float32)


def every_20ms(backend: str, dt: float) -> list[np.ndarray]:
    env = gym.make(
        "flyloop/QuadHover-v0",
        dt=dt,
        max_steps=10_000,
        start_height=0.0,
        enable_crash_detection=False,
        enable_out_of_bounds_detection=False,
        backend=backend,
    )
    try:
        obs, _ = env.reset(seed=21)
        out = [obs]
        per = round(0.02 / dt)
        for a in actions(round(SECONDS / 0.02)):
            for _ in range(per):
                obs, _, terminated, truncated, _ = env.step(a)
                assert not (terminated or truncated)
            out.append(obs)
        return out
    finally:
        env.close()


@pytest.mark.parametrize("backend", ["native", "sitl"])
def test_quadhover_at_dt_10ms_and_20ms_is_the_same_at_every_20ms(backend):
    coarse = every_20ms(backend, 0.02)
    fine = every_20ms(backend, 0.01)
    assert len(coarse) == len(fine) == 301
    for k, (a, b) in enumerate(zip(fine, coarse, strict=True)):
        assert a.tobytes() == b.tobytes(), f"t = {0.02 * k:.2f} s"
    # Not a still picture: it moved from its start and felt the wind.
    assert np.abs(coarse[-1][:3] - coarse[0][:3]).max() > 0.2


def lander_actions(n: int) -> np.ndarray:
    """One action per 0.02 s: near hover (-0.02 is 7.35 N a motor), a seeded walk in the
    collective and a weave between the motors."""
    rng = np.random.default_rng(5)
    k = np.arange(n)
    collective = -0.02 + np.clip(0.01 * rng.standard_normal(n).cumsum(), -0.1, 0.1)
    weave = 0.2 * np.cos(0.3 * k)
    return np.stack([collective + weave, collective - weave], axis=1).astype(np.float32)


def lander_every_20ms(backend: str, dt: float) -> list[tuple[np.ndarray, np.ndarray]]:
    env = gym.make(
        "flyloop/Lander2D-v1",
        dt=dt,
        max_steps=10_000,
        model_params={"physics_step": 0.005},
        backend=backend,
    )
    try:
        obs, info = env.reset(seed=21)
        out = [(obs, np.asarray(info["position"]))]
        per = round(0.02 / dt)
        for a in lander_actions(round(4.0 / 0.02)):
            for _ in range(per):
                obs, _, terminated, truncated, info = env.step(a)
                assert not (terminated or truncated)
            out.append((obs, np.asarray(info["position"])))
        return out
    finally:
        env.close()


@pytest.mark.parametrize("backend", ["native", "sitl"])
def test_lander_at_dt_10ms_and_20ms_is_the_same_at_every_20ms(backend):
    coarse = lander_every_20ms(backend, 0.02)
    fine = lander_every_20ms(backend, 0.01)
    assert len(coarse) == len(fine) == 201
    for k, ((obs_f, pos_f), (obs_c, pos_c)) in enumerate(zip(fine, coarse, strict=True)):
        assert obs_f.tobytes() == obs_c.tobytes(), f"t = {0.02 * k:.2f} s"
        assert pos_f.tobytes() == pos_c.tobytes(), f"t = {0.02 * k:.2f} s"
    # Not a still picture: the wind and the weave moved it, and the motors drew charge.
    start, end = coarse[0][1], coarse[-1][1]
    assert np.hypot(*(end - start)) > 0.5
    assert 0.9 < coarse[-1][0][6] < 0.97
