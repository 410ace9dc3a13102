"""Train PPO on flyloop's QuadHover (or Lander2D) with Ray RLlib: several env runners, each
with its own env and so its own flyloop-sitl process.

On one machine (here: 2 cores; Ray is started with --num-cpus of them, no dashboard):

    .venv/bin/python examples/train/train_rllib.py --num-env-runners 2 --iterations 10

prints, per iteration, the mean return of the episodes finished in it, the env steps
sampled, and env steps/s (env steps of the iteration / its wall time, learning included).

On a Ray cluster, the same script: every node needs this repository's Python package
(`pip install -e python` plus `ray[rllib]` and torch, in the same versions as the head) and a
`flyloop-sitl` binary on PATH or at the same FLYLOOP_SITL path (`cargo build --release -p
flyloop-sitl`). Then:

    ray start --head --port=6379                              # on the head node
    ray start --address=HEAD_IP:6379                          # on each worker node
    python examples/train/train_rllib.py --address auto \\
        --num-env-runners 64 --iterations 200 --train-batch 32000 # on the head node

With --address the script joins the running cluster (`ray.init(address="auto")`) instead of
starting Ray itself; --num-cpus is then ignored (the cluster's nodes bring their own CPUs).
Ray ships this folder (examples/train, for training_envs.py) to every worker as the job's
working_dir, and passes FLYLOOP_SITL on when it is set. Each env runner takes one CPU, so
64 env runners need 64 CPUs across the nodes; the learner runs in this driver process
(`--num-learners N` moves learning to N learner actors, e.g. on GPU nodes).

The env and its arguments reach each env runner through RLlib's env_config,
{"env": "hover" | "lander", "action": None (the preset's) | "motors" | "primitives" |
"rates", "env_kwargs": {...}}, made by training_envs.make_env, so the env runners fly
exactly the presets train_sb3.py and evaluate.py use. Stopping the algorithm closes every
env runner's env, which stops its SITL process.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import sys
import time
from pathlib import Path
from typing import Any

HERE = Path(__file__).resolve().parent
ENV_NAME = "flyloop-preset"


def env_creator(env_config: dict[str, Any]):
    """RLlib's env factory: one preset env (one SITL process) from env_config; with
    {"backend": "native"} and RLlib's "num_envs" (gym_env_vectorize_mode VECTOR_ENTRY_POINT),
    the native vector env: all the runner's envs in-process, stepped in one call."""
    from training_envs import make_env, make_native_vector_env

    if env_config.get("backend") == "native" and "num_envs" in env_config:
        return make_native_vector_env(
            env_config.get("env", "hover"),
            int(env_config["num_envs"]),
            overrides=env_config.get("env_kwargs"),
            # One thread: an env runner has one CPU (num_cpus_per_env_runner=1).
            num_threads=1,
        )
    return make_env(
        env_config.get("env", "hover"),
        action=env_config.get("action"),
        overrides=env_config.get("env_kwargs"),
        # Each env runner flies its own SITL process (make_env's default is in-process).
        backend=env_config.get("backend", "sitl"),
    )


def observation_filter(env=None, spaces=None, device=None):
    """Normalises observations by their running mean and std (as VecNormalize does for
    stable-baselines3): the hover observation mixes metres, m/s and rad/s² of very different
    scales. The statistics are merged across env runners after each iteration."""
    from ray.rllib.connectors.env_to_module import MeanStdFilter

    return MeanStdFilter()


def ppo_hyperparameters(train_batch: int, minibatch: int, epochs: int) -> dict[str, Any]:
    """PPO's learning settings (PPOConfig.training's keywords) shared by the RLlib examples."""
    return dict(
        lr=3e-4,
        gamma=0.99,
        lambda_=0.95,
        train_batch_size_per_learner=train_batch,
        minibatch_size=minibatch,
        num_epochs=epochs,
    )


def build_config(
    env: str,
    num_env_runners: int,
    seed: int,
    *,
    train_batch: int = 4000,
    minibatch: int = 256,
    epochs: int = 10,
    envs_per_env_runner: int = 1,
    env_kwargs: dict[str, Any] | None = None,
    num_learners: int = 0,
    backend: str = "sitl",
):
    """A small PPO config: fully connected 64×64 policy, torch, observation filter, and
    `envs_per_env_runner` envs in each env runner: SITL processes (backend "sitl",
    vectorised by gymnasium's SyncVectorEnv) or one native vector env (backend "native")."""
    import gymnasium as gym
    from ray.rllib.algorithms.ppo import PPOConfig
    from ray.rllib.core.rl_module.default_model_config import DefaultModelConfig

    mode = gym.VectorizeMode.VECTOR_ENTRY_POINT if backend == "native" else gym.VectorizeMode.SYNC
    env_config = {"env": env, "env_kwargs": env_kwargs or {}, "backend": backend}
    return (
        PPOConfig()
        .environment(ENV_NAME, env_config=env_config)
        .framework("torch")
        .env_runners(
            num_env_runners=num_env_runners,
            num_envs_per_env_runner=envs_per_env_runner,
            gym_env_vectorize_mode=mode,
            num_cpus_per_env_runner=1,
            rollout_fragment_length="auto",
            env_to_module_connector=observation_filter,
        )
        .learners(num_learners=num_learners)
        .training(**ppo_hyperparameters(train_batch, minibatch, epochs))
        .rl_module(model_config=DefaultModelConfig(fcnet_hiddens=[64, 64]))
        .debugging(seed=seed)
    )


def start_ray(address: str | None, num_cpus: int) -> None:
    """Joins the cluster at `address`, or starts a local Ray with `num_cpus` CPUs."""
    import ray

    env_vars = {"OMP_NUM_THREADS": "1"}
    if os.environ.get("FLYLOOP_SITL"):
        env_vars["FLYLOOP_SITL"] = os.environ["FLYLOOP_SITL"]
    runtime_env = {
        "working_dir": str(HERE),
        "excludes": ["__pycache__", "*.png", "runs"],
        "env_vars": env_vars,
    }
    if address:
        ray.init(address=address, runtime_env=runtime_env, log_to_driver=False)
    else:
        ray.init(
            # A fresh local instance: without it ray.init() joins whatever cluster RAY_ADDRESS
            # or Ray's last-started-cluster file names (and then refuses num_cpus).
            address="local",
            num_cpus=num_cpus,
            include_dashboard=False,
            runtime_env=runtime_env,
            log_to_driver=False,
            # A small object store: this machine's memory is shared with other work.
            object_store_memory=200 * 1024 * 1024,
        )


def iteration_figures(result: dict[str, Any]) -> dict[str, float]:
    """The figures of one algo.train() result: the mean return of the episodes finished in
    the iteration (NaN if none), env steps sampled, wall time and env steps/s (the whole
    iteration: sampling and learning)."""
    runners = result.get("env_runners", {})
    steps = float(runners.get("num_env_steps_sampled", 0))
    seconds = float(result.get("time_this_iter_s", math.nan))
    return dict(
        episode_return_mean=float(runners.get("episode_return_mean", math.nan)),
        episode_len_mean=float(runners.get("episode_len_mean", math.nan)),
        episodes=float(runners.get("num_episodes", 0)),
        env_steps=steps,
        env_steps_lifetime=float(result.get("num_env_steps_sampled_lifetime", math.nan)),
        seconds=seconds,
        env_steps_per_s=steps / seconds if seconds > 0 else math.nan,
    )


def sampling_throughput(algo, steps_per_runner: int) -> dict[str, float]:
    """Times every remote env runner sampling `steps_per_runner` env steps at once with the
    current policy (no learning): how sampling scales with the number of env runners."""
    group = algo.env_runner_group
    start = time.perf_counter()
    counts = group.foreach_env_runner(
        lambda runner: sum(len(e) for e in runner.sample(num_timesteps=steps_per_runner)),
        local_env_runner=False,
    )
    seconds = time.perf_counter() - start
    steps = float(sum(counts))
    return dict(
        env_runners=float(len(counts)),
        env_steps=steps,
        seconds=seconds,
        env_steps_per_s=steps / seconds,
    )


def run_iterations(algo, iterations: int, on_iteration) -> list[dict[str, float]]:
    """Trains `algo` for `iterations` iterations: the figures of each, given to
    on_iteration(i, figures, algo) (if not None) as it ends."""
    history: list[dict[str, float]] = []
    for i in range(iterations):
        figures = iteration_figures(algo.train())
        history.append(figures)
        if on_iteration is not None:
            on_iteration(i, figures, algo)
    return history


def train(
    env: str = "hover",
    num_env_runners: int = 2,
    iterations: int = 10,
    seed: int = 0,
    *,
    address: str | None = None,
    num_cpus: int = 2,
    train_batch: int = 4000,
    minibatch: int = 256,
    epochs: int = 10,
    envs_per_env_runner: int = 1,
    env_kwargs: dict[str, Any] | None = None,
    num_learners: int = 0,
    checkpoint: Path | None = None,
    measure_sampling: int = 0,
    on_iteration=None,
    backend: str = "sitl",
) -> dict[str, Any]:
    """Starts (or joins) Ray, trains for `iterations` iterations, optionally measures
    sampling alone (`measure_sampling` env steps per env runner), stops the algorithm (and so
    every env runner's SITL) and Ray. Returns {"iterations": [figures of each iteration],
    "sampling": sampling_throughput's figures or None}. `on_iteration(i, figures, algo)` is
    called after each iteration."""
    import ray
    import torch
    from ray.tune.registry import register_env

    torch.set_num_threads(1)  # the learner, in this process; env runners get OMP_NUM_THREADS=1
    sys.path.insert(0, str(HERE))
    start_ray(address, num_cpus)
    algo = None
    try:
        register_env(ENV_NAME, env_creator)
        config = build_config(
            env,
            num_env_runners,
            seed,
            train_batch=train_batch,
            minibatch=minibatch,
            epochs=epochs,
            envs_per_env_runner=envs_per_env_runner,
            env_kwargs=env_kwargs,
            num_learners=num_learners,
            backend=backend,
        )
        algo = config.build_algo()
        history = run_iterations(algo, iterations, on_iteration)
        sampling = sampling_throughput(algo, measure_sampling) if measure_sampling > 0 else None
        if checkpoint is not None:
            algo.save_to_path(str(checkpoint.resolve()))
    finally:
        if algo is not None:
            algo.stop()
        ray.shutdown()
    return {"iterations": history, "sampling": sampling}


def parse_args(argv: list[str] | None) -> tuple[argparse.Namespace, Any]:
    """The arguments, checked, and the preset --env names."""
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument(
        "--env", default="hover", help="hover (QuadHover-v0) or lander (Lander2D-v0)"
    )
    parser.add_argument("--num-env-runners", type=int, default=2)
    parser.add_argument("--iterations", type=int, default=10)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--train-batch", type=int, default=4000, help="env steps per iteration")
    parser.add_argument("--minibatch", type=int, default=256)
    parser.add_argument("--epochs", type=int, default=10, help="passes over each batch")
    parser.add_argument(
        "--envs-per-env-runner",
        type=int,
        default=1,
        help="envs stepped together by one env runner (each with its SITL, or all in one "
        "native vector env)",
    )
    parser.add_argument(
        "--backend",
        default="sitl",
        choices=("sitl", "native"),
        help="sitl: each env flies its own flyloop-sitl process; native: each env runner "
        "steps its envs in-process in one native vector env (no SITL)",
    )
    parser.add_argument("--num-learners", type=int, default=0, help="0: learn in this process")
    parser.add_argument("--address", default=None, help='a running cluster, e.g. "auto"')
    parser.add_argument("--num-cpus", type=int, default=2, help="CPUs of a local Ray")
    parser.add_argument("--checkpoint", type=Path, default=None, help="save the algorithm here")
    parser.add_argument(
        "--measure-sampling",
        type=int,
        default=0,
        metavar="STEPS",
        help="after training, time each env runner sampling STEPS env steps at once",
    )
    parser.add_argument("--json", type=Path, default=None, help="write per-iteration figures")
    args = parser.parse_args(argv)
    if min(args.num_env_runners, args.iterations, args.envs_per_env_runner) < 1:
        parser.error("--num-env-runners, --iterations and --envs-per-env-runner must be >= 1")
    if not args.address and args.num_env_runners > args.num_cpus:
        parser.error(
            f"{args.num_env_runners} env runners need {args.num_env_runners} CPUs; "
            f"the local Ray has --num-cpus {args.num_cpus}"
        )
    sys.path.insert(0, str(HERE))
    from training_envs import preset

    try:
        p = preset(args.env)
    except ValueError as exc:
        parser.error(str(exc))
    return args, p


def print_iteration(i: int, f: dict[str, float], algo) -> None:
    print(
        f"iteration {i + 1:3d}: episode return mean {f['episode_return_mean']:8.1f}  "
        f"({f['episodes']:.0f} episodes, mean length {f['episode_len_mean']:.0f})  "
        f"env steps {f['env_steps']:.0f}  {f['seconds']:.1f} s  "
        f"{f['env_steps_per_s']:.0f} env steps/s",
        flush=True,
    )


def print_totals(result: dict[str, Any], start: float) -> None:
    """Training's and (if measured) sampling's throughput; `start`: perf_counter before Ray."""
    history = result["iterations"]
    steps = sum(f["env_steps"] for f in history)
    seconds = sum(f["seconds"] for f in history)
    print(
        f"{len(history)} iterations, {steps:.0f} env steps in {seconds:.1f} s of training "
        f"({steps / seconds:.0f} env steps/s); {time.perf_counter() - start:.1f} s with Ray's "
        f"start and stop"
    )
    sampling = result["sampling"]
    if sampling is not None:
        print(
            f"sampling alone: {sampling['env_steps']:.0f} env steps by "
            f"{sampling['env_runners']:.0f} env runners in {sampling['seconds']:.1f} s: "
            f"{sampling['env_steps_per_s']:.0f} env steps/s"
        )


def main(argv: list[str] | None = None) -> int:
    args, p = parse_args(argv)
    each = "each env with its own SITL" if args.backend == "sitl" else "native vector envs"
    print(
        f"RLlib PPO on {p.env_id}: {args.num_env_runners} env runners × "
        f"{args.envs_per_env_runner} envs, {each}"
    )
    start = time.perf_counter()
    result = train(
        p.name,
        args.num_env_runners,
        args.iterations,
        args.seed,
        address=args.address,
        num_cpus=args.num_cpus,
        train_batch=args.train_batch,
        minibatch=args.minibatch,
        epochs=args.epochs,
        envs_per_env_runner=args.envs_per_env_runner,
        num_learners=args.num_learners,
        checkpoint=args.checkpoint,
        measure_sampling=args.measure_sampling,
        on_iteration=print_iteration,
        backend=args.backend,
    )
    print_totals(result, start)
    if args.json is not None:
        args.json.write_text(json.dumps(result, indent=2) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
