"""The fleet in the view: flyloop.view.WatchParallel draws every agent of a multi-agent env
(flyloop.parallel_env) at once. Its recording must hold each agent's truth equal to the env's
info at every step; in headless Chromium each vehicle's hub must be drawn apart (one cluster
of hub pixels per vehicle; none for a missing one)."""

from __future__ import annotations

import socket

import flyloop
import numpy as np
from flight import free_port
from flyloop.plot import series_of
from flyloop.view import WatchParallel
from flyloop.view.screenshot import Browser, hub_pixels

AGENTS = 4
THRUST = 0.6  # every motor: a slow climb, all agents still flying after 100 steps


def clusters(pixels: np.ndarray, link: float = 8.0) -> int:
    """How many groups the pixels make, a pixel joining a group when it lies within `link`
    px of one of its pixels (one group per drawn hub, even where a rotor crosses it)."""
    p = pixels.astype(float)
    near = np.hypot(*(p[:, None, :] - p[None, :, :]).transpose(2, 0, 1)) < link
    group = np.arange(len(p))
    while True:  # every pixel takes the smallest label among its neighbours
        new = np.where(near, group[None, :], len(p)).min(axis=1)
        if np.array_equal(new, group):
            return len(set(group.tolist()))
        group = new


def fly(env, steps: int) -> list[dict]:
    """`steps` steps at THRUST; every step's infos."""
    out = []
    for _ in range(steps):
        _, _, _, _, infos = env.step({a: np.full(4, THRUST, np.float32) for a in env.agents})
        out.append(infos)
    return out


def test_every_agent_recorded_with_its_truth(tmp_path):
    env = WatchParallel(
        flyloop.parallel_env("flyloop/MultiHover-v0", num_agents=AGENTS),
        serve=False,
        save=tmp_path / "fleet.rrd",
    )
    env.reset(seed=0)
    infos = fly(env, 100)
    env.close()
    series = series_of(tmp_path / "fleet.rrd")
    for i in range(AGENTS):
        agent = f"drone_{i}"
        t, down = series[f"/position/{agent}/D/truth"]
        assert len(t) == 101  # the reset and every step
        want = [-float(step[agent]["position"][2]) for step in infos]
        assert np.array_equal(down[1:], np.array(want, dtype=down.dtype)), agent
        _, m0 = series[f"/motors/{agent}_command/m0"]
        assert abs(m0[-1] - THRUST) < 1e-6
        _, north = series[f"/position/{agent}/N/truth"]
        assert north[-1] == float(infos[-1][agent]["position"][1])


def test_the_fleet_drawn_in_the_browser(tmp_path):
    web, grpc = free_port(socket.SOCK_STREAM), free_port(socket.SOCK_STREAM)
    env = WatchParallel(
        flyloop.parallel_env("flyloop/MultiHover-v0", num_agents=AGENTS),
        web_port=web,
        grpc_port=grpc,
    )
    browser = Browser()
    try:
        env.reset(seed=0)
        browser.open(env.viewer.url)
        fly(env, 50)
        # The wasm loads (~20 s), then the viewer catches up with the stream: every hub drawn.
        shot, n = browser.wait_for_vehicle(
            AGENTS * 30, timeout=120, until=lambda px: clusters(px) == AGENTS
        )
        (tmp_path / "fleet.png").write_bytes(shot)
    finally:
        browser.close()
        env.close()
    assert clusters(hub_pixels(shot)) == AGENTS, tmp_path / "fleet.png"
