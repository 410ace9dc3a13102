"""Throughput of the gymnasium envs, native vs SITL backend in one run: env steps per second
with random actions, and the memory of the native vector env.

    bash scripts/setup.sh --no-demo      # or: cargo build --release; pip install -e python
    .venv/bin/python benchmarks/gym_throughput.py [--seconds 3] [--vehicles 16]
        [--native-envs 1024] [--memory-envs 100000]

For each env id:
- single env made with gymnasium.make (env checker wrappers included), both backends,
  stepping random actions and resetting when an episode ends, rendering off;
- the SITL vector env with --vehicles vehicles in one SITL process;
- the native vector env with --native-envs sub-envs (all CPUs), NEXT_STEP autoreset,
  copy=False (the arrays a learner reads in place); then at scale: 1,024 envs on one
  thread, and 10,000 Lander2D envs on all CPUs.
Random actions are drawn from numpy in batches, so the figure is the env's own cost
(--sample-actions calls action_space.sample() every step instead).
Memory: peak resident-set growth of making the native vector env and stepping it 500 times,
per env, for QuadHover and Lander2D, and for --memory-envs QuadHover envs in one vector env
(0 skips).
Wall-clock time, so run it on a quiet machine (`uptime` load < 1).
"""

from __future__ import annotations

import argparse
import glob
import os
import subprocess
import sys
import time

import flyloop  # noqa: F401  (registers the env ids)
import gymnasium as gym
import numpy as np
from flyloop.registration import ENVS

BATCH = 4096
# The native vector env at scale: (env id, envs, threads; None = all CPUs).
SCALE = [
    ("flyloop/QuadHover-v0", 1024, 1),
    ("flyloop/QuadWaypoints-v0", 1024, 1),
    ("flyloop/Lander2D-v1", 1024, 1),
    ("flyloop/Lander2D-v1", 10_000, None),
]


def _actions(space, rng, n):
    # Drawn in float32 (the envs' action dtype): half the cost of float64 and a cast.
    u = rng.random((n, *space.shape), dtype=np.float32)
    return space.low + (space.high - space.low) * u


def single(env_id: str, seconds: float, sample: bool, backend: str) -> float:
    env = gym.make(env_id, backend=backend)
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


def vector(env_id: str, n: int, seconds: float, sample: bool, **kwargs) -> float:
    envs = gym.make_vec(env_id, num_envs=n, vectorization_mode="vector_entry_point", **kwargs)
    rng = np.random.default_rng(0)
    envs.reset(seed=0)
    rounds = max(1, min(256, 65536 // n))
    steps, start = 0, time.perf_counter()
    while time.perf_counter() - start < seconds:
        actions = _actions(envs.single_action_space, rng, rounds * n).reshape(rounds, n, -1)
        for a in actions:
            if sample:
                a = envs.action_space.sample()
            envs.step(a)  # NEXT_STEP autoreset: no reset call needed
        steps += rounds * n
    rate = steps / (time.perf_counter() - start)
    envs.close()
    return rate


def _rss_bytes() -> int:
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * os.sysconf("SC_PAGE_SIZE")


def memory_per_env(env_id: str, n: int) -> tuple[float, float]:
    """(bytes per env, total MB) of a native vector env of `n` envs, the peak over a reset
    and MEMORY_STEPS steps, measured in a fresh interpreter (in this one, heap freed by the
    throughput runs would be reused and hide the growth)."""
    child = subprocess.run(
        [sys.executable, __file__, "--memory-child", env_id, str(n)],
        capture_output=True,
        text=True,
        check=True,
    )
    grown = int(child.stdout.split()[-1])
    return grown / n, grown / 1e6


MEMORY_STEPS = 500


def memory_child(env_id: str, n: int, steps: int = MEMORY_STEPS) -> None:
    """Prints the resident-set growth, bytes, of making, resetting and stepping the env
    `steps` times with random actions (episodes end and restart meanwhile, so a
    Lander2D's rapier worlds, built only near the ground and the pad, are counted as they
    come and go)."""
    before = _rss_bytes()
    kwargs = dict(num_envs=n, vectorization_mode="vector_entry_point", backend="native")
    envs = gym.make_vec(env_id, **kwargs)
    envs.reset(seed=0)
    rng = np.random.default_rng(0)
    peak = 0
    for _ in range(steps):
        envs.step(_actions(envs.single_action_space, rng, n))
        peak = max(peak, _rss_bytes())
    print(peak - before)


def machine() -> str:
    """CPU model, logical CPUs and cache sizes (Linux), so figures from different machines are
    never mixed."""
    model = "unknown CPU"
    try:
        for line in open("/proc/cpuinfo"):
            if line.startswith("model name"):
                model = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    caches = []
    for index in sorted(glob.glob("/sys/devices/system/cpu/cpu0/cache/index*")):
        try:
            level = open(f"{index}/level").read().strip()
            kind = open(f"{index}/type").read().strip()
            size = open(f"{index}/size").read().strip()
        except OSError:
            continue
        name = {"Data": "d", "Instruction": "i"}.get(kind, "")
        caches.append(f"L{level}{name} {size}")
    return f"{model}, {os.cpu_count()} logical CPUs; caches: {', '.join(caches) or 'unknown'}"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=3.0, help="per measurement")
    parser.add_argument("--vehicles", type=int, default=16, help="SITL vector env size")
    parser.add_argument("--native-envs", type=int, default=1024, help="native vector env size")
    parser.add_argument("--memory-envs", type=int, default=100_000)
    parser.add_argument("--sample-actions", action="store_true")
    parser.add_argument("--env", action="append", choices=sorted(ENVS), help="default: all")
    # ENV N [STEPS]: one memory measurement (what memory_per_env and the tests run).
    parser.add_argument("--memory-child", nargs="+", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.memory_child:
        env_id, n, *steps = args.memory_child
        memory_child(env_id, int(n), *map(int, steps))
        return
    print(machine())
    load = os.getloadavg()[0]
    print(f"load average {load:.2f}{'  (busy machine: figures are low)' if load > 1 else ''}")
    print(
        f"| env | single SITL | single native | native/SITL | vector SITL ({args.vehicles}) "
        f"| vector native ({args.native_envs}) | native/SITL |"
    )
    print("|---|---|---|---|---|---|---|")
    t, s = args.seconds, args.sample_actions
    for env_id in args.env or sorted(ENVS):
        s_sitl = single(env_id, t, s, "sitl")
        s_nat = single(env_id, t, s, "native")
        v_sitl = vector(env_id, args.vehicles, t, s)
        v_nat = vector(env_id, args.native_envs, t, s, backend="native", copy=False)
        print(
            f"| {env_id} | {s_sitl:,.0f} | {s_nat:,.0f} | {s_nat / s_sitl:.0f}x "
            f"| {v_sitl:,.0f} | {v_nat:,.0f} | {v_nat / v_sitl:.0f}x |",
            flush=True,
        )
    print("\n| native vector env | envs | threads | env steps/s |")
    print("|---|---|---|---|")
    for env_id, n, threads in SCALE:
        if args.env and env_id not in args.env:
            continue
        rate = vector(env_id, n, t, s, backend="native", copy=False, num_threads=threads)
        shown = threads or os.cpu_count()
        print(f"| {env_id} | {n:,} | {shown} | {rate:,.0f} |", flush=True)
    print("\n| native vector env | envs | memory per env | total |")
    print("|---|---|---|---|")
    sizes = [("flyloop/QuadHover-v0", 10_000), ("flyloop/Lander2D-v1", 10_000)]
    if args.memory_envs:
        sizes.append(("flyloop/QuadHover-v0", args.memory_envs))
    for env_id, n in sizes:
        per, total = memory_per_env(env_id, n)
        print(f"| {env_id} | {n:,} | {per / 1024:,.1f} KiB | {total:,.0f} MB |", flush=True)


if __name__ == "__main__":
    main()
