"""Throughput of the gymnasium adapter: env steps per second with random actions.

    cargo build --release -p flyloop-sitl
    .venv/bin/python benchmarks/gym_throughput.py [--seconds 5] [--vehicles 16]

For each env id: a single env made with gymnasium.make (the env checker wrappers included),
stepping random actions and resetting when an episode ends, rendering off; then the vector
env with --vehicles vehicles in one SITL (gymnasium.make_vec). Random actions are drawn from
numpy in batches, so the figure is the env's own cost; --sample-actions calls
action_space.sample() every step instead (flyloop's FastBox: ~5 µs, gymnasium's Box: ~35 µs).
Wall-clock time, so run it on a quiet machine (`uptime` load < 1); the SITL runs in its own
process, so one env keeps about two cores busy.
"""

from __future__ import annotations

import argparse
import os
import time

import flyloop  # noqa: F401  (registers the env ids)
import gymnasium as gym
import numpy as np

ENV_IDS = ["flyloop/QuadHover-v0", "flyloop/QuadWaypoints-v0", "flyloop/Lander2D-v0"]
BATCH = 4096


def _actions(space, rng, n):
    return rng.uniform(space.low, space.high, (n, *space.shape)).astype(np.float32)


def single(env_id: str, seconds: float, sample: bool) -> float:
    env = gym.make(env_id)
    rng = np.random.default_rng(0)
    env.reset(seed=0)
    steps, start = 0, time.perf_counter()
    while time.perf_counter() - start < seconds:
        actions = _actions(env.action_space, rng, BATCH)
        for a in actions:
            if sample:
                a = env.action_space.sample()
            _, _, terminated, truncated, _ = env.step(a)
            if terminated or truncated:
                env.reset()
        steps += BATCH
    rate = steps / (time.perf_counter() - start)
    env.close()
    return rate


def vector(env_id: str, vehicles: int, seconds: float, sample: bool) -> float:
    envs = gym.make_vec(env_id, num_envs=vehicles)
    rng = np.random.default_rng(0)
    envs.reset(seed=0)
    steps, start = 0, time.perf_counter()
    while time.perf_counter() - start < seconds:
        actions = _actions(envs.single_action_space, rng, 256 * vehicles).reshape(256, vehicles, -1)
        for a in actions:
            if sample:
                a = envs.action_space.sample()
            envs.step(a)  # NEXT_STEP autoreset: no reset call needed
        steps += 256 * vehicles
    rate = steps / (time.perf_counter() - start)
    envs.close()
    return rate


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=5.0, help="per measurement")
    parser.add_argument("--vehicles", type=int, default=16)
    parser.add_argument("--sample-actions", action="store_true")
    parser.add_argument("--env", action="append", choices=ENV_IDS, help="default: all three")
    args = parser.parse_args()
    load = os.getloadavg()[0]
    print(f"load average {load:.2f}{'  (busy machine: figures are low)' if load > 1 else ''}")
    print(f"| env | single env steps/s | vector env ({args.vehicles} vehicles) env-steps/s |")
    print("|---|---|---|")
    for env_id in args.env or ENV_IDS:
        s = single(env_id, args.seconds, args.sample_actions)
        v = vector(env_id, args.vehicles, args.seconds, args.sample_actions)
        print(f"| {env_id} | {s:,.0f} | {v:,.0f} |", flush=True)


if __name__ == "__main__":
    main()
