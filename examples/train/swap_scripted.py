"""Scripted controllers on flyloop/Swap-v0: is the swap reachable in the time limit, and how?

Each agent is flown by examples/demo_gym_pd.py's PD controller (motor interface) toward a
waypoint; the strategies differ only in the waypoint:

- ``straight``: the agent's own target (all four meet in the middle at one height);
- ``altitude``: its target raised by ``layer · (i − (N − 1)/2)`` m while it is farther than
  ``settle`` m from the target horizontally, then the target (each agent crosses on its own
  layer; the layer is chosen by agent index, which the shared policy does not observe);
- ``roundabout``: its target pushed ``offset`` m to the agent's right of the line start →
  target while it is farther than ``settle`` m, then the target (the same rule for every
  agent: what one policy shared by symmetric agents can do);
- ``hold``: the point ``stop`` m short of the middle on the agent's own side, at its target's
  height (the deadlock of agents that learned not to collide but not to pass).

    .venv/bin/python examples/train/swap_scripted.py --episodes 100

Prints per strategy the success rate (every agent within 0.5 m at the time limit, no
collision or crash), the failures by cause and the mean return per agent.
"""

from __future__ import annotations

import argparse
import sys
from dataclasses import dataclass
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
import flyloop  # noqa: E402
from demo_gym_pd import pd_action  # noqa: E402
from training_envs import PRESETS  # noqa: E402

HELD_OUT_SEED = 1_000_000


@dataclass(frozen=True)
class Strategy:
    """A waypoint rule (module docs) and its distances, m."""

    name: str  # "straight", "altitude" or "roundabout"
    layer: float = 0.6  # altitude: height step between agents' layers
    offset: float = 1.0  # roundabout: offset to the right of the direction of travel
    settle: float = 1.0  # horizontal distance from the target where the detour ends
    stop: float = 0.6  # hold: distance from the middle where the agent stays


def waypoint(strategy: Strategy, info: dict, i: int, n: int) -> np.ndarray:
    """Where agent i of n steers now, world ENU, m."""
    position = np.asarray(info["position"], float)
    target = np.asarray(info["target_position"], float)
    away = target - position
    if strategy.name == "hold":  # the target is opposite the start: its direction is -start
        inward = target[:2] / np.linalg.norm(target[:2])
        return np.array([-inward[0] * strategy.stop, -inward[1] * strategy.stop, target[2]])
    if strategy.name == "straight" or np.hypot(away[0], away[1]) < strategy.settle:
        return target
    if strategy.name == "altitude":
        return target + np.array([0.0, 0.0, strategy.layer * (i - (n - 1) / 2)])
    # Roundabout: to the right of the direction of travel (ENU: right of (x, y) is (y, -x)).
    heading = away[:2] / np.linalg.norm(away[:2])
    right = np.array([heading[1], -heading[0], 0.0])
    return target + strategy.offset * right


def run(strategy: Strategy, episodes: int, params: dict | None = None) -> dict:
    """Flies `episodes` held-out worlds (seeds from 1,000,000) of the swap preset (with
    `params` over its env arguments); counts successes and failures by cause."""
    env_kwargs = dict(PRESETS["swap"].env_kwargs)
    env_kwargs.update(params or {})
    env = flyloop.parallel_env("flyloop/Swap-v0", **env_kwargs)
    n = env_kwargs["num_agents"]
    results = {"success": 0, "collision": 0, "crash": 0, "not_arrived": 0, "returns": []}
    for episode in range(episodes):
        obs, infos = env.reset(seed=HELD_OUT_SEED + episode)
        agents = list(env.agents)
        total = dict.fromkeys(agents, 0.0)
        last = dict(infos)
        collided = crashed = False
        while env.agents:
            actions = {}
            for a in env.agents:
                i = agents.index(a)
                o = np.array(obs[a], float)
                o[0:3] = waypoint(strategy, last[a], i, n) - np.asarray(last[a]["position"], float)
                actions[a] = pd_action(o)
            obs, rewards, _, _, infos = env.step(actions)
            for a, r in rewards.items():
                total[a] += r
            for a, info in infos.items():
                last[a] = info
                collided |= bool(info["collided"])
                crashed |= bool(info["crashed"])
        if any(bool(info["success"]) for info in last.values()):
            results["success"] += 1
        elif collided:
            results["collision"] += 1
        elif crashed:
            results["crash"] += 1
        else:
            results["not_arrived"] += 1
        results["returns"].append(np.mean(list(total.values())))
    env.close()
    return results


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--episodes", type=int, default=100)
    parser.add_argument("--layer", type=float, default=0.6, help="altitude step, m")
    parser.add_argument("--offset", type=float, default=1.0, help="roundabout offset, m")
    parser.add_argument("--settle", type=float, default=1.0, help="m from the target")
    parser.add_argument("--stop", type=float, default=0.6, help="hold: m from the middle")
    parser.add_argument(
        "--param", action="append", default=[], help="env parameter NAME=VALUE (repeatable)"
    )
    parser.add_argument(
        "--strategies", default="straight,altitude,roundabout", help="comma-separated"
    )
    args = parser.parse_args()
    args.params = {k: float(v) for k, v in (p.split("=", 1) for p in args.param)}
    for key in ("max_steps", "num_agents"):
        if key in args.params:
            args.params[key] = int(args.params[key])
    for name in args.strategies.split(","):
        strategy = Strategy(name, args.layer, args.offset, args.settle, args.stop)
        r = run(strategy, args.episodes, args.params)
        print(
            f"{name:10s} success {r['success']}/{args.episodes}  collision "
            f"{r['collision']}  crash {r['crash']}  not arrived {r['not_arrived']}  "
            f"mean return/agent {np.mean(r['returns']):.1f}",
            flush=True,
        )


if __name__ == "__main__":
    main()
