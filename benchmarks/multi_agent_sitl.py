"""Agent-steps per second of the multi-agent ParallelEnv on backend="sitl" (one flyloop-sitl
world, one datagram exchange per step: docs/protocol.md section 14) against backend="native",
in one run, at several agent counts.

    .venv/bin/python benchmarks/multi_agent_sitl.py [--seconds 4] [--agents 4 16 64] [--gcs]

Both step `flyloop/Swap-v0` (one altitude: v1's layers do not fit 64 agents) with random
motor commands (drawn before timing), motor interface, no wind, contact and downwash on,
k = 3 neighbours, swap_radius grown with the agent count so the starts fit; an episode that
ends is reset with the next seed. `--gcs`: the SITL also streams every agent's ground-station
telemetry (docs/sitl.md, default rates) to a socket this process drains, as a ground station
would. The link busy-waits FLYLOOP_SPIN_US for each reply, as the
env does. Wall-clock time: the machine's load is printed before and after; quote it with the
figures.
"""

from __future__ import annotations

import argparse
import os
import socket
import threading
import time

import flyloop
import numpy as np


def _rate(env, seconds: float) -> float:
    """Agent-steps per second of `env` under random actions for `seconds`."""
    rng = np.random.default_rng(0)
    agents = env.possible_agents
    draws = rng.uniform(0.0, 1.0, (256, len(agents), 4)).astype(np.float32)
    seed = 0
    env.reset(seed=seed)
    steps, k, start = 0, 0, time.perf_counter()
    while time.perf_counter() - start < seconds:
        if not env.agents:
            seed += 1
            env.reset(seed=seed)
        row = draws[k % len(draws)]
        k += 1
        env.step({a: row[i] for i, a in enumerate(agents) if a in env.agents})
        steps += len(agents)
    return steps / (time.perf_counter() - start)


def _gcs_sink() -> tuple[str, list[int]]:
    """A UDP socket a thread drains, as a ground station; its address and [datagrams, bytes]."""
    sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    sock.bind(("127.0.0.1", 0))
    counts = [0, 0]

    def drain() -> None:
        while True:
            counts[0] += 1
            counts[1] += len(sock.recv(65536))

    threading.Thread(target=drain, daemon=True).start()
    return f"127.0.0.1:{sock.getsockname()[1]}", counts


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--seconds", type=float, default=4.0, help="per form and count")
    parser.add_argument("--agents", type=int, nargs="+", default=[4, 16, 64])
    parser.add_argument("--gcs", action="store_true", help="ground-station link on (SITL)")
    args = parser.parse_args()
    gcs, received = _gcs_sink() if args.gcs else ("off", [0, 0])
    print(f"{os.cpu_count()} CPUs; load before: {os.getloadavg()}")
    head = ("agents", "native agent-steps/s", "sitl agent-steps/s", "sitl/native")
    print(f"{head[0]:>6} {head[1]:>21} {head[2]:>19} {head[3]:>11}")
    for n in args.agents:
        kwargs = dict(num_agents=n, swap_radius=max(1.0, 0.125 * n), max_steps=400)
        rates = {}
        for backend in ("native", "sitl"):
            link = {"gcs": gcs} if backend == "sitl" else {}
            env = flyloop.parallel_env("flyloop/Swap-v0", backend=backend, **kwargs, **link)
            try:
                rates[backend] = _rate(env, args.seconds)
            finally:
                env.close()
        ratio = rates["sitl"] / rates["native"]
        print(f"{n:>6} {rates['native']:>21,.0f} {rates['sitl']:>19,.0f} {ratio:>11.2f}")
    if args.gcs:
        print(f"ground station received {received[0]:,} datagrams, {received[1]:,} bytes")
    print(f"load after: {os.getloadavg()}")


if __name__ == "__main__":
    main()
