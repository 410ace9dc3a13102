"""Events in the gym recordings: flyloop.view's Watch and WatchParallel turn what an env's
info reports — a fault that fires or ends (`info["faults"]`), a collision the world reports
(`collided`, `collision_speed`) — into lines of the recording's events log (/events/NAME) at
the step's simulation time, beside the collision's red mark and speed series."""

from __future__ import annotations

import sys
from pathlib import Path

import flyloop
import gymnasium as gym
import numpy as np
from flyloop.plot import events_of, series_of
from flyloop.view import Watch, WatchParallel

ROOT = Path(__file__).resolve().parents[2]
for folder in ("examples", "examples/train"):
    sys.path.insert(0, str(ROOT / folder))
from demo_gym_pd import pd_action  # noqa: E402
from swap_scripted import Strategy, waypoint  # noqa: E402

FAULT = {"kind": "motor_effectiveness", "motor": 2, "effectiveness": 0.5}


def test_a_fault_that_fires_and_ends_is_an_event_at_its_step(tmp_path):
    env = Watch(
        gym.make(
            "flyloop/QuadHover-v0",
            backend="native",
            max_steps=100,
            faults=[{**FAULT, "at": 0.2, "duration": 0.3}],
        ),
        serve=False,
        save=tmp_path / "fault.rrd",
    )
    env.reset(seed=0)
    dt = env.unwrapped.dt
    active = []
    for step in range(1, 61):
        _, _, _, _, info = env.step(np.full(4, 0.5, np.float32))
        active.append((step * dt, [f["fault"] for f in info["faults"]]))
    env.close()
    fired = next(t for t, a in active if a)
    ended = next(t for t, a in active if t > fired and not a)
    events = [(t, path, text) for t, path, text in events_of(tmp_path / "fault.rrd")]
    assert events == [
        (round(fired, 9), "/events/vehicle1", "fault motor_effectiveness:2 fired"),
        (round(ended, 9), "/events/vehicle1", "fault motor_effectiveness:2 ended"),
    ], (events, fired, ended)
    assert abs(fired - 0.2) <= dt + 1e-9 and abs(ended - 0.5) <= dt + 1e-9


def test_every_collision_of_a_multi_agent_env_is_an_event(tmp_path):
    env = WatchParallel(
        flyloop.parallel_env("flyloop/Swap-v0", num_agents=2),
        serve=False,
        save=tmp_path / "swap.rrd",
    )
    obs, infos = env.reset(seed=1_000_000)
    agents, dt, t = list(env.agents), float(env.dt), 0.0
    collisions = []
    while env.agents:
        actions = {}
        for a in env.agents:
            o = np.array(obs[a], float)
            position = np.asarray(infos[a]["position"], float)
            o[0:3] = waypoint(Strategy("straight"), infos[a], agents.index(a), 2) - position
            actions[a] = pd_action(o)
        obs, _, _, _, infos = env.step(actions)
        t += dt
        for a, info in infos.items():
            if info["collided"]:
                collisions.append((round(t, 9), a, float(info["collision_speed"])))
    env.close()
    assert {a for _, a, _ in collisions} == set(agents), "both agents collide, straight"
    events = events_of(tmp_path / "swap.rrd")
    want = [(t, f"/events/{a}", f"collision, closing at {s:.2f} m/s") for t, a, s in collisions]
    got = [e for e in events if "collision" in e[2]]
    assert sorted(got) == sorted(want)
    series = series_of(tmp_path / "swap.rrd")
    for _, a, speed in collisions:
        assert speed in series[f"/task/{a}/collision_speed"][1]


def test_a_fault_of_one_agent_is_its_event_only(tmp_path):
    fault = {"kind": "motor_off", "motor": 3, "at": 0.1, "agent": "drone_1"}
    env = WatchParallel(
        flyloop.parallel_env("flyloop/MultiHover-v0", num_agents=2, faults=[fault]),
        serve=False,
        save=tmp_path / "multi.rrd",
    )
    env.reset(seed=0)
    t, fired = 0.0, None
    for _ in range(30):
        _, _, _, _, infos = env.step({a: np.full(4, 0.5, np.float32) for a in env.agents})
        t += float(env.dt)
        if fired is None and infos["drone_1"]["faults"]:
            fired = round(t, 9)
        assert infos["drone_0"]["faults"] == []
    env.close()
    events = events_of(tmp_path / "multi.rrd")
    assert events == [(fired, "/events/drone_1", "fault motor_off:3 fired")], events
