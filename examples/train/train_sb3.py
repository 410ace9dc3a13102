"""Train PPO or SAC (stable-baselines3) on flyloop's QuadHover or Lander2D.

    .venv/bin/python examples/train/train_sb3.py --env hover --algo ppo --timesteps 300000 \\
        --seed 0 --out runs/hover_ppo
    .venv/bin/tensorboard --logdir runs/hover_ppo/tb        # the logs, live

Writes to --out: model.zip (the policy), vecnormalize.pkl (observation/return
normalisation statistics: evaluate.py needs them with the model), tb/ (TensorBoard logs:
rollout/ep_rew_mean, rollout/success_rate, losses), episodes.csv (every training episode),
learning_curve.png and summary.json (wall time, env steps/s, the random policy's mean
return). Prints a progress bar while it trains, then the wall time and env steps/s.

The --n-envs envs run the core in this process (--backend native, the default: one
flyloop.sb3 VecEnv over the native batch, all envs stepped in one call; with --action
primitives or rates single envs in a DummyVecEnv) or each its own flyloop-sitl process
(--backend sitl; found through FLYLOOP_SITL, PATH or the workspace build; see the flyloop
package's README): the same episodes bit for bit. Torch runs on one CPU thread: the policy
is small and the envs need the other core.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from training_envs import check_action, preset

ALGORITHMS = ("ppo", "sac")


def parse_args(argv: list[str] | None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument(
        "--env",
        default="hover",
        help="hover (QuadHover-v0), lander (Lander2D-v1, static pad), lander_moving "
        "(Lander2D-v1, moving pad) or lander_v0 (Lander2D-v0, the seed's reward)",
    )
    parser.add_argument("--algo", default="ppo", choices=ALGORITHMS)
    parser.add_argument(
        "--action",
        default=None,
        help="hover only: motors (default: the 4 motor commands, rescaled to [-1, 1]), "
        "primitives (MotionPrimitiveActionWrapper) or rates (ThrustChangeController)",
    )
    parser.add_argument("--timesteps", type=int, default=300_000, help="env steps to train for")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--out", type=Path, default=Path("runs/train"), help="output folder")
    parser.add_argument(
        "--n-envs", type=int, default=None, help="envs stepped together (SITL processes)"
    )
    parser.add_argument(
        "--baseline-episodes", type=int, default=20, help="episodes of the random policy's bar"
    )
    parser.add_argument(
        "--backend",
        default="native",
        choices=("native", "sitl"),
        help="sitl: one flyloop-sitl process per env; native: the core in this process "
        "(same episodes bit for bit, several times faster)",
    )
    parser.add_argument(
        "--init-from",
        type=Path,
        help="continue from an earlier run's folder (its policy and normalisation statistics)",
    )
    parser.add_argument(
        "--lr-decay",
        action="store_true",
        help="learning rate falling linearly to 0 over this run (settles a policy at the end)",
    )
    parser.add_argument("--no-progress-bar", action="store_true")
    args = parser.parse_args(argv)
    if args.timesteps <= 0:
        parser.error("--timesteps must be > 0")
    if args.baseline_episodes < 1:
        parser.error("--baseline-episodes must be >= 1")
    if args.n_envs is not None and args.n_envs < 1:
        parser.error("--n-envs must be >= 1")
    try:
        check_action(preset(args.env), args.action)
    except ValueError as exc:
        parser.error(str(exc))
    return args


def main(argv: list[str] | None = None) -> int:
    args = parse_args(argv)
    # Imported only now: torch and stable-baselines3 take seconds to load.
    from sb3_training import train

    s = train(
        args.env,
        args.algo,
        args.timesteps,
        args.seed,
        args.out,
        action=args.action,
        progress_bar=not args.no_progress_bar,
        baseline_episodes=args.baseline_episodes,
        n_envs=args.n_envs,
        backend=args.backend,
        init_from=args.init_from,
        lr_decay=args.lr_decay,
    )
    report(s, args.out)
    return 0


def report(s: dict, out: Path) -> None:
    """The run's summary `s` in a few lines."""
    print(
        f"trained {s['algo'].upper()} on {s['env_id']} for {s['timesteps']:,} env steps "
        f"({s['episodes']} episodes) in {s['wall_time_s']:.1f} s: "
        f"{s['env_steps_per_s']:.0f} env steps/s"
    )
    if s["episodes"]:
        print(
            f"last 10 % of training episodes: mean return {s['last_tenth_mean_return']:.1f} "
            f"(random policy {s['random_mean_return']:.1f}), "
            f"success {100 * s['last_tenth_success_rate']:.0f} %"
        )
    else:
        print("no training episode finished: train for more --timesteps")
    print(f"wrote {out}/model.zip, vecnormalize.pkl, tb/, episodes.csv, learning_curve.png")


if __name__ == "__main__":
    sys.exit(main())
