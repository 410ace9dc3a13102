"""Train one PPO policy shared by every agent of flyloop's MultiHover (or Swap) with RLlib's
multi-agent API (new API stack): env runners each step their own multi-agent env
(flyloop.rllib.multi_agent_env over flyloop.parallel_env), and a policy_mapping_fn sends
every agent to the one policy "shared".

    .venv/bin/python examples/train/train_rllib_multi.py --num-env-runners 2 --iterations 10

prints, per iteration, the mean return of the episodes finished in it (summed over the
agents of an episode, as RLlib reports it), and the agent steps sampled. The Ray setup
(local with --num-cpus, or --address of a cluster) is train_rllib.py's.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
from pathlib import Path
from typing import Any

HERE = Path(__file__).resolve().parent
ENV_NAME = "flyloop-multi"
POLICY = "shared"


def shared_policy(agent_id, episode, **kwargs) -> str:
    """Every agent flies the one shared policy."""
    return POLICY


def build_config(
    env_config: dict[str, Any],
    num_env_runners: int,
    seed: int,
    *,
    train_batch: int = 4000,
    minibatch: int = 256,
    epochs: int = 10,
):
    """PPO with one shared 64×64 policy for every agent of the env `env_config` makes."""
    from ray.rllib.algorithms.ppo import PPOConfig
    from ray.rllib.core.rl_module.default_model_config import DefaultModelConfig
    from ray.rllib.core.rl_module.multi_rl_module import MultiRLModuleSpec
    from ray.rllib.core.rl_module.rl_module import RLModuleSpec
    from train_rllib import ppo_hyperparameters

    return (
        PPOConfig()
        .environment(ENV_NAME, env_config=env_config)
        .framework("torch")
        .env_runners(
            num_env_runners=num_env_runners,
            num_cpus_per_env_runner=1,
            rollout_fragment_length="auto",
        )
        .multi_agent(policies={POLICY}, policy_mapping_fn=shared_policy)
        .rl_module(
            rl_module_spec=MultiRLModuleSpec(
                rl_module_specs={
                    POLICY: RLModuleSpec(model_config=DefaultModelConfig(fcnet_hiddens=[64, 64]))
                }
            )
        )
        .training(**ppo_hyperparameters(train_batch, minibatch, epochs))
        .debugging(seed=seed)
    )


def iteration_figures(result: dict[str, Any]) -> dict[str, Any]:
    """One algo.train() result's figures: train_rllib's, plus the agent steps sampled."""
    from train_rllib import iteration_figures as single

    figures = single(result)
    runners = result.get("env_runners", {})
    figures["agent_steps"] = float(sum(runners.get("num_agent_steps_sampled", {}).values()))
    # The policies (RLModules) the learner updated in this iteration.
    learners = result.get("learners", {})
    figures["modules"] = sorted(m for m in learners if not m.startswith("__"))
    return figures


def train(
    env_config: dict[str, Any],
    num_env_runners: int = 2,
    iterations: int = 10,
    seed: int = 0,
    *,
    address: str | None = None,
    num_cpus: int = 2,
    on_iteration=None,
    **training: Any,
) -> dict[str, Any]:
    """Starts (or joins) Ray, trains `iterations` iterations, stops the algorithm and Ray;
    returns {"iterations": [figures of each iteration]}."""
    import ray
    import torch
    from ray.tune.registry import register_env

    sys.path.insert(0, str(HERE))
    from flyloop.rllib import multi_agent_env
    from train_rllib import start_ray

    torch.set_num_threads(1)
    start_ray(address, num_cpus)
    algo = None
    history: list[dict[str, Any]] = []
    try:
        register_env(ENV_NAME, multi_agent_env)
        algo = build_config(env_config, num_env_runners, seed, **training).build_algo()
        for i in range(iterations):
            figures = iteration_figures(algo.train())
            history.append(figures)
            if on_iteration is not None:
                on_iteration(i, figures)
    finally:
        if algo is not None:
            algo.stop()
        ray.shutdown()
    return {"iterations": history}


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--env", default="flyloop/MultiHover-v0", help="a multi-agent env id")
    parser.add_argument("--num-agents", type=int, default=4)
    parser.add_argument("--max-steps", type=int, default=250, help="steps per episode")
    parser.add_argument("--num-env-runners", type=int, default=2)
    parser.add_argument("--iterations", type=int, default=10)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--train-batch", type=int, default=4000, help="env steps per iteration")
    parser.add_argument("--minibatch", type=int, default=256)
    parser.add_argument("--epochs", type=int, default=10, help="passes over each batch")
    parser.add_argument("--address", default=None, help='a running cluster, e.g. "auto"')
    parser.add_argument("--num-cpus", type=int, default=2, help="CPUs of a local Ray")
    parser.add_argument("--json", type=Path, default=None, help="write per-iteration figures")
    args = parser.parse_args(argv)
    if min(args.num_env_runners, args.iterations, args.num_agents, args.max_steps) < 1:
        parser.error("--num-env-runners, --iterations, --num-agents, --max-steps must be >= 1")
    env_config = {"env_id": args.env, "num_agents": args.num_agents, "max_steps": args.max_steps}
    print(
        f"RLlib PPO on {args.env} × {args.num_agents} agents, one shared policy: "
        f"{args.num_env_runners} env runners"
    )

    def show(i: int, f: dict[str, float]) -> None:
        print(
            f"iteration {i + 1:3d}: episode return mean {f['episode_return_mean']:8.1f}  "
            f"({f['episodes']:.0f} episodes)  env steps {f['env_steps']:.0f}  "
            f"agent steps {f['agent_steps']:.0f}  {f['seconds']:.1f} s",
            flush=True,
        )

    start = time.perf_counter()
    result = train(
        env_config,
        args.num_env_runners,
        args.iterations,
        args.seed,
        address=args.address,
        num_cpus=args.num_cpus,
        on_iteration=show,
        train_batch=args.train_batch,
        minibatch=args.minibatch,
        epochs=args.epochs,
    )
    returns = [f["episode_return_mean"] for f in result["iterations"]]
    print(
        f"{len(returns)} iterations in {time.perf_counter() - start:.1f} s with Ray's start "
        f"and stop; last return mean {returns[-1] if returns else math.nan:.1f}"
    )
    if args.json is not None:
        args.json.write_text(json.dumps(result, indent=2) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
