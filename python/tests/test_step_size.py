"""The control period does not change the vehicle: QuadHover at dt = 0.01 and dt = 0.02 s,
flown by the same actions held per 0.02 s, gives the same observations bit for bit at every
0.02 s (the core integrates on its fixed 5 ms physics grid and samples the wind on its own
grid), over the SITL and in-process."""

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
