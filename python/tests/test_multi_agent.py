"""The PettingZoo multi-agent envs over the native extension: pettingzoo's API and seed tests,
bit-identical seeds, the action dict's order, per-agent interfaces and randomisation, the
batched vector form across thread counts, and bad input naming the item."""

from __future__ import annotations

import numpy as np
import pytest
from pettingzoo.test import parallel_api_test, parallel_seed_test

import flyloop

ENVS = ["flyloop/MultiHover-v0", "flyloop/Swap-v0", "flyloop/Swap-v1"]


@pytest.mark.parametrize("env_id", ENVS)
@pytest.mark.parametrize("interface", ["motors", "rates"])
def test_pettingzoo_api_and_seed_tests_pass(env_id, interface):
    env = flyloop.parallel_env(env_id, num_agents=4, interface=interface)
    parallel_api_test(env, num_cycles=300)
    parallel_seed_test(
        lambda: flyloop.parallel_env(env_id, num_agents=4, interface=interface), num_cycles=100
    )


def _rollout(env, seed, order, steps=80):
    """Observations, rewards and ends as bytes, the action dict built in `order`."""
    obs, _ = env.reset(seed=seed)
    rng = np.random.default_rng(3)
    out = [b"".join(obs[a].tobytes() for a in env.possible_agents)]
    for _ in range(steps):
        if not env.agents:
            break
        draws = {a: rng.uniform(0.0, 1.0, 4).astype(np.float32) for a in env.possible_agents}
        actions = {a: draws[a] for a in order(env.agents)}
        obs, rew, term, trunc, _ = env.step(actions)
        for a in sorted(obs):
            out.append(obs[a].tobytes() + np.float64(rew[a]).tobytes() + bytes([term[a], trunc[a]]))
    return out


@pytest.mark.parametrize("env_id", ENVS)
def test_same_seed_same_bits_whatever_the_order_of_the_action_dict(env_id):
    env = flyloop.parallel_env(env_id, num_agents=5, wind_enabled=True)
    forward = _rollout(env, 11, lambda agents: agents)
    backward = _rollout(env, 11, lambda agents: list(reversed(agents)))
    assert forward == backward
    other = flyloop.parallel_env(env_id, num_agents=5, wind_enabled=True)
    assert _rollout(other, 11, lambda agents: agents) == forward
    assert _rollout(other, 12, lambda agents: agents) != forward


def test_spaces_and_observation_layout():
    env = flyloop.parallel_env("flyloop/Swap-v0", num_agents=3, neighbours=4)
    assert env.possible_agents == ["drone_0", "drone_1", "drone_2"]
    space = env.observation_space("drone_1")
    assert space.shape == (33 + 4 * 7,)
    assert env.observation_layout[-1] == ("neighbours", 28)
    obs, infos = env.reset(seed=0)
    o = obs["drone_0"]
    assert space.contains(o)
    # Two others present (flag 1), two slots absent (zeros).
    slots = o[33:].reshape(4, 7)
    assert list(slots[:, 6]) == [1.0, 1.0, 0.0, 0.0]
    assert not slots[2:].any()
    # The first neighbour's relative position is its position minus the agent's.
    p, _ = env.positions()
    nearest = min((1, 2), key=lambda j: np.linalg.norm(p[j] - p[0]))
    np.testing.assert_allclose(slots[0, :3], p[nearest] - p[0], atol=1e-6)
    assert infos["drone_2"]["collisions"] == 0 and infos["drone_2"]["success"] is False
    rates = flyloop.parallel_env("flyloop/Swap-v0", num_agents=3, interface="rates")
    assert rates.observation_space("drone_0").shape == (16 + 3 * 7,)
    assert rates.action_space("drone_0").high[1] > 1.0  # rad/s, not a motor command


def test_domain_randomisation_draws_a_vehicle_per_agent():
    env = flyloop.parallel_env(
        "flyloop/MultiHover-v0", num_agents=3, domain_randomization={"mass": (0.6, 1.4)}
    )
    _, infos = env.reset(seed=5)
    masses = [float(infos[a]["randomized"][0]) for a in env.possible_agents]
    assert len(set(masses)) == 3 and all(0.6 <= m <= 1.4 for m in masses)
    _, again = env.reset(seed=5)
    assert [float(again[a]["randomized"][0]) for a in env.possible_agents] == masses


def _first_collision(env, seeds=range(30), steps=100):
    """(seed, infos, rewards, terminations) of the first step a collision starts in: two
    vehicles 2 cm apart climbing at 0.8 thrust drift on their random start tilts."""
    for seed in seeds:
        env.reset(seed=seed)
        for _ in range(steps):
            if not env.agents:
                break
            _, rew, term, _, info = env.step({a: np.full(4, 0.8, np.float32) for a in env.agents})
            if any(i["collided"] for i in info.values()):
                return seed, info, rew, term
    return None


# Swap-v1's layers keep two agents 0.6 m apart in height: its collisions are v0's.
@pytest.mark.parametrize("env_id", ENVS[:2])
def test_a_collision_is_in_both_agents_info_and_ends_them(env_id):
    env = flyloop.parallel_env(
        env_id, num_agents=2, swap_radius=0.16, hover_spacing=0.32, collision_penalty=10.0
    )
    found = _first_collision(env)
    assert found is not None, "two vehicles 2 cm apart never touched in 30 episodes"
    _, info, rew, term = found
    for a in ("drone_0", "drone_1"):
        assert info[a]["collided"] and info[a]["collisions"] == 1
        assert info[a]["collision_speed"] > 0.0
        assert term[a] and rew[a] < -8.0
    assert env.agents == []


def test_vector_form_is_the_same_on_one_and_two_threads():
    results = []
    for threads in (1, 2):
        v = flyloop.MultiAgentVectorEnv(
            "flyloop/Swap-v0", num_worlds=6, num_threads=threads, num_agents=4, max_steps=40
        )
        obs, _ = v.reset(seed=3)
        rng = np.random.default_rng(0)
        trace = [obs.tobytes()]
        for _ in range(100):
            obs, rew, term, trunc, info = v.step(rng.uniform(0, 1, (24, 4)).astype(np.float32))
            trace.append(obs.tobytes() + rew.tobytes() + term.tobytes() + trunc.tobytes())
        assert info["active"].dtype == bool
        results.append(trace)
    assert results[0] == results[1]


def test_bad_input_names_the_item():
    with pytest.raises(ValueError, match="num_agents.*65536"):
        flyloop.parallel_env("flyloop/Swap-v0", num_agents=70_000)
    with pytest.raises(ValueError, match="swap_radius"):
        flyloop.parallel_env("flyloop/Swap-v0", num_agents=64, swap_radius=1.0)
    with pytest.raises(ValueError, match="interface"):
        flyloop.parallel_env("flyloop/Swap-v0", interface="thrust")
    with pytest.raises(ValueError, match="massss"):
        flyloop.parallel_env("flyloop/Swap-v0", massss=1.0)
    with pytest.raises(ValueError, match="flyloop/Nope-v0"):
        flyloop.parallel_env("flyloop/Nope-v0")
    with pytest.raises(ValueError, match="backend must be 'native' or 'sitl', got 'px4'"):
        flyloop.parallel_env("flyloop/Swap-v0", backend="px4")
    env = flyloop.parallel_env("flyloop/Swap-v0", num_agents=3)
    env.reset(seed=0)
    hover = np.full(4, 0.5, np.float32)
    with pytest.raises(KeyError, match="drone_2"):
        env.step({"drone_0": hover, "drone_1": hover})
    with pytest.raises(KeyError, match="drone_9"):
        env.step({a: hover for a in env.agents} | {"drone_9": hover})
    with pytest.raises(ValueError, match="agent 1"):
        env.step(
            {a: hover if a != "drone_1" else np.full(4, np.nan, np.float32) for a in env.agents}
        )


def test_swap_v1_flies_each_agent_on_its_own_layer_and_v0_on_one():
    """Swap-v1 = Swap-v0 with swap_layer 0.6 m and swap_radius 1 m: starts and targets at
    0.6 / 1.2 / 1.8 / 2.4 m, 1 m from the middle; v0 with the same arguments is the same
    episode, bit for bit."""
    v1 = flyloop.parallel_env("flyloop/Swap-v1", num_agents=4)
    _, infos = v1.reset(seed=5)
    heights = [infos[a]["position"][2] for a in v1.agents]
    targets = [infos[a]["target_position"][2] for a in v1.agents]
    np.testing.assert_allclose(heights, [0.6, 1.2, 1.8, 2.4], atol=1e-6)
    np.testing.assert_allclose(targets, heights, atol=1e-6)
    radii = [np.hypot(*infos[a]["position"][:2]) for a in v1.agents]
    np.testing.assert_allclose(radii, 1.0, atol=1e-6)
    v0 = flyloop.parallel_env("flyloop/Swap-v0", num_agents=4)
    _, flat = v0.reset(seed=5)
    np.testing.assert_allclose([flat[a]["position"][2] for a in v0.agents], 1.5, atol=1e-6)
    same = flyloop.parallel_env("flyloop/Swap-v0", num_agents=4, swap_layer=0.6, swap_radius=1.0)
    obs0, _ = same.reset(seed=5)
    obs1, _ = v1.reset(seed=5)
    for a in v1.agents:
        assert obs0[a].tobytes() == obs1[a].tobytes()
