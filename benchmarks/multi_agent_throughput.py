"""Throughput of the native multi-agent env against the single-agent native vector env, in
one run: agent-steps per second at 64 agents per world, env-steps per second of QuadHover's
vector env with as many sub-envs, and one world of 1,024 agents.

    .venv/bin/python benchmarks/multi_agent_throughput.py [--seconds 5] [--worlds 4]

Each form steps random motor commands (drawn in batches from numpy) on one thread, motor
interface, no wind, the world's contact and downwash on:
- multi: flyloop.MultiAgentVectorEnv("flyloop/Swap-v0") with --worlds worlds x 64 agents
  (swap_radius 8 m: a circle the hulls fit on), k = 3 neighbours, autoreset;
- single: gymnasium.make_vec("flyloop/QuadHover-v0", backend="native") with the same number of
  sub-envs (worlds x 64), one thread;
- 1,024 agents in one world (swap_radius 60 m: 0.37 m between neighbours).
Prints each rate and the ratio multi / single (the issue's target: >= 0.6). Wall-clock time:
say the machine's load (printed) with the figures.
"""

from __future__ import annotations

import argparse
import os
import platform
import time

import flyloop
import gymnasium as gym
import numpy as np

BATCH = 64


def _cpu() -> str:
    try:
        for line in open("/proc/cpuinfo"):
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor()


def _rate(envs, seconds: float) -> float:
    """Sub-env steps per second of `envs` under random actions for `seconds`."""
    rng = np.random.default_rng(0)
    envs.reset(seed=0)
    low, high = envs.single_action_space.low, envs.single_action_space.high
    n = envs.num_envs
    steps, start = 0, time.perf_counter()
    while time.perf_counter() - start < seconds:
        u = rng.random((BATCH, n, len(low)), dtype=np.float32)
        for a in low + (high - low) * u:
            envs.step(a)
            steps += n
    return steps / (time.perf_counter() - start)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--seconds", type=float, default=5.0, help="per form")
    parser.add_argument("--worlds", type=int, default=4, help="worlds of 64 agents")
    args = parser.parse_args()
    print(f"CPU: {_cpu()}, {os.cpu_count()} CPUs; load before: {os.getloadavg()}")

    multi = flyloop.MultiAgentVectorEnv(
        "flyloop/Swap-v0", num_worlds=args.worlds, num_agents=64, swap_radius=8.0
    )
    single = gym.make_vec(
        "flyloop/QuadHover-v0",
        num_envs=args.worlds * 64,
        vectorization_mode="vector_entry_point",
        backend="native",
        num_threads=1,
        use_wind=False,
    )
    big = flyloop.MultiAgentVectorEnv(
        "flyloop/Swap-v0", num_worlds=1, num_agents=1024, swap_radius=60.0
    )
    rates = {}
    for name, envs in (("multi", multi), ("single", single), ("world_1024", big)):
        rates[name] = _rate(envs, args.seconds)
        envs.close()
    print(f"multi, {args.worlds} worlds x 64 agents: {rates['multi']:,.0f} agent-steps/s")
    print(f"single, QuadHover vector env of {args.worlds * 64}: {rates['single']:,.0f} env-steps/s")
    print(f"ratio multi / single: {rates['multi'] / rates['single']:.2f}")
    print(f"one world of 1,024 agents: {rates['world_1024']:,.0f} agent-steps/s")
    print(f"load after: {os.getloadavg()}")


if __name__ == "__main__":
    main()
