"""Faults in the multi-agent envs (issue 35): `faults=[...]` and `fault_randomization={...}`
for every agent or one (`"agent": "drone_1"`), drawn per agent from the episode's seed;
`infos[agent]["faults"]`; the same seed flies the same bits; bad faults name the field."""

from __future__ import annotations

import numpy as np
import pytest

import flyloop
from flyloop.multi_agent import native_config

HOVER = np.full(4, 0.5, np.float32)
DRAW = {"kinds": ["motor_effectiveness"], "at": (0.0, 0.4), "effectiveness": (0.5, 0.9)}
MOTOR_OFF = {"kind": "motor_off", "motor": 3, "at": 0.2, "agent": "drone_1"}


def fly(env, seed, steps=60):
    """Every agent's observations as bytes and the last infos, all agents at hover."""
    obs, infos = env.reset(seed=seed)
    out = [b"".join(obs[a].tobytes() for a in env.possible_agents)]
    for _ in range(steps):
        if not env.agents:
            break
        obs, _, _, _, infos = env.step({a: HOVER for a in env.agents})
        out.append(b"".join(obs[a].tobytes() for a in sorted(obs)))
    return out, infos


def test_one_agents_motor_off_fires_for_that_agent_only():
    env = flyloop.parallel_env("flyloop/MultiHover-v0", num_agents=3, faults=[MOTOR_OFF])
    healthy = flyloop.parallel_env("flyloop/MultiHover-v0", num_agents=3)
    _, before = fly(env, 5, 19)
    assert all(before[a]["faults"] == [] for a in env.possible_agents)
    trace, infos = fly(env, 5, 40)
    reference, _ = fly(healthy, 5, 40)
    assert infos["drone_1"]["faults"] == [{"fault": "motor_off:3", "time": pytest.approx(0.2)}]
    assert infos["drone_0"]["faults"] == infos["drone_2"]["faults"] == []
    # Every agent reports the table's slot; drone_0's is empty (kind -1, never fired).
    assert list(infos["drone_0"]["fault_kind"]) == [-1.0]
    assert list(infos["drone_0"]["fault_time"]) == [-1.0]
    # The same up to 0.2 s (20 steps of 10 ms), then drone_1 tumbles.
    assert trace[:21] == reference[:21] and trace[-1] != reference[-1]
    rates = slice(13, 16)
    assert (
        np.abs(np.asarray(env.step({a: HOVER for a in env.agents})[0]["drone_1"][rates])).max()
        > 0.5
    )


def test_draws_are_per_agent_and_the_same_seed_gives_the_same_bits():
    make = lambda: flyloop.parallel_env(  # noqa: E731
        "flyloop/Swap-v1", num_agents=4, fault_randomization=DRAW
    )
    a, b = make(), make()
    ta, ia = fly(a, 21)
    tb, ib = fly(b, 21)
    assert ta == tb
    for agent in a.possible_agents:
        assert ia[agent]["faults"] == ib[agent]["faults"]
        assert np.array_equal(ia[agent]["fault_target"], ib[agent]["fault_target"])
    # Each agent draws its own motor, time and strength from the episode's seed.
    drawn = {(float(i["fault_target"][0]), float(i["fault_time"][0])) for i in ia.values()}
    assert len(drawn) > 1
    assert all(len(i["faults"]) == 1 for i in ia.values())
    tc, _ = fly(a, 22)
    assert tc != ta


def test_the_vector_env_takes_the_same_faults():
    envs = flyloop.MultiAgentVectorEnv(
        "flyloop/MultiHover-v0", num_worlds=2, num_agents=2, fault_randomization=DRAW
    )
    envs.reset(seed=3)
    for _ in range(50):
        _, _, _, _, infos = envs.step(np.full((4, 4), 0.5, np.float32))
    assert infos["fault_kind"].shape == (4, 1)
    assert (infos["fault_kind"] == 0).all()  # motor_effectiveness for every agent
    assert (infos["fault_time"] >= 0).all()


def test_the_config_holds_the_tables_a_sitl_config_file_would():
    text = native_config(num_agents=2, faults=[MOTOR_OFF], fault_randomization=DRAW)["faults"]
    assert text.splitlines() == [
        "[[faults]]",
        'kind = "motor_off"',
        "motor = 3",
        "at = 0.2",
        "agent = 1",
        "[[fault_randomization]]",
        'kinds = ["motor_effectiveness"]',
        "at = [0.0, 0.4]",
        "effectiveness = [0.5, 0.9]",
    ]
    assert "faults" not in native_config(num_agents=2)


@pytest.mark.parametrize(
    ("kwargs", "names"),
    [
        (dict(faults=[{**MOTOR_OFF, "agent": "drone_7"}]), ("`agent` = 7", "[0, 3]")),
        (dict(faults=[{**MOTOR_OFF, "agent": "leader"}]), ("['agent']", "'leader'")),
        (dict(faults=[{**MOTOR_OFF, "motor": 5}]), ("`motor`", "[0, 4]")),
        (
            dict(faults=[{"kind": "motor_effectiveness", "effectiveness": 1.5}]),
            ("`effectiveness`", "[0, 1]"),
        ),
        (dict(faults=[{"kind": "gust", "north": 3.0}]), ("`gust`", "multi-agent")),
        (dict(faults=[{"kind": "propeller"}]), ("propeller", "motor_effectiveness")),
        (dict(fault_randomization={"kinds": ["motor_off"], "at": (0, 99)}), ("`at`",)),
    ],
)
def test_bad_faults_are_refused_naming_the_field(kwargs, names):
    with pytest.raises((ValueError, TypeError)) as err:
        flyloop.parallel_env("flyloop/MultiHover-v0", num_agents=4, **kwargs)
    for name in names:
        assert name in str(err.value), str(err.value)
