"""Train a policy that flies through PX4: collective thrust + body rates (PX4's offboard rates
setpoint) through the core's model of PX4's rate loop, on the Iris of flyloop's PX4 preset,
with domain randomisation — fast_ppo.py's `offboard` task on the native vector env — then
check it on held-out episodes and export it for examples/px4_offboard.py.

    .venv/bin/python examples/train/train_offboard.py --out runs/offboard

Writes OUT/: `policy.npz` + `policy.json` (the policy as examples/px4_offboard.py loads it: a
numpy MLP, its observation normalisation and its interface), `policy.pt`, `progress.csv`,
`learning_curve.png` and `summary.json` with held-out evaluations (seeds from 1,000,000, one
target held for the 10 s episode) on the nominal Iris, on randomised vehicles and on an unseen
vehicle (mass +20 %, thrust coefficient −10 %: sitl/presets/px4_iris_unseen.toml).
"""

from __future__ import annotations

import argparse
import csv
import json
import sys
from dataclasses import asdict
from pathlib import Path

import fast_ppo
import numpy as np
import torch
from training_envs import preset, px4_vehicle

UNSEEN = px4_vehicle("px4_iris_unseen")
TASK = "offboard"


def evaluate(model, norm, episodes: int, **env) -> dict:
    """The deterministic policy on `episodes` episodes seeded 1,000,000.. with the preset's
    env changed by `env`, each holding one target for the whole episode; success = the
    hover preset's (within 0.5 m at the time limit)."""
    envs = fast_ppo.make_envs(TASK, "native", episodes, target_change_interval=None, **env)
    try:
        obs, _ = envs.reset(seed=fast_ppo.EVAL_SEED)
        done = np.zeros(episodes, bool)
        success = np.zeros(episodes, bool)
        distance = np.zeros(episodes)
        space = envs.single_action_space
        while not done.all():
            with torch.no_grad():
                action = model.mu(torch.as_tensor(norm(obs))).numpy()
            obs, _, terminated, truncated, infos = envs.step(fast_ppo.to_env(action, space))
            ended = ~done & (terminated | truncated)
            success[ended] = fast_ppo.successes(terminated, truncated, infos)[ended]
            distance[ended] = np.asarray(infos["distance_to_target"])[ended]
            done |= ended
    finally:
        envs.close()
    return dict(
        episodes=episodes,
        success_rate=float(success.mean()),
        mean_final_distance_m=float(distance.mean()),
    )


def export(model, norm, out: Path, meta: dict) -> None:
    """policy.npz (mean network, normalisation) and policy.json (its interface) for
    examples/px4_offboard.py, which needs numpy only."""
    envs = fast_ppo.make_envs(TASK, "native", 1)
    space = envs.single_action_space
    envs.close()
    layers = [m for m in model.mu if isinstance(m, torch.nn.Linear)]
    arrays = {f"w{i}": m.weight.detach().numpy().astype(np.float64) for i, m in enumerate(layers)}
    arrays |= {f"b{i}": m.bias.detach().numpy().astype(np.float64) for i, m in enumerate(layers)}
    np.savez(out / "policy.npz", layers=len(layers), obs_mean=norm.mean, obs_var=norm.var, **arrays)
    interface = dict(
        interface="px4-rates-v1",
        observation="flyloop rates interface, 16 values: target - position and velocity in "
        "the heading frame (NED turned by yaw), body down axis in the heading frame, body "
        "rates FRD, previous action",
        action="thrust [0, 1], roll, pitch, yaw rate rad/s body FRD",
        action_low=space.low.tolist(),
        action_high=space.high.tolist(),
        dt=preset(TASK).env_kwargs["dt"],
        **meta,
    )
    (out / "policy.json").write_text(json.dumps(interface, indent=2) + "\n")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    task = fast_ppo.TASKS[TASK]
    parser.add_argument("--timesteps", type=int, default=task.timesteps)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--eval-episodes", type=int, default=task.eval_episodes)
    parser.add_argument("--out", type=Path, default=Path("runs/offboard"))
    parser.add_argument("--no-progress-bar", action="store_true")
    # fast_ppo.train reads fast_ppo's --init (a run to continue); this run starts fresh.
    parser.set_defaults(init=None)
    args = parser.parse_args(argv)
    args.env = TASK
    cfg = task.config
    run = fast_ppo.train(args, "native", cfg)
    model, norm, rows = run["model"], run["norm"], run["rows"]
    evaluations = {
        "nominal": evaluate(model, norm, args.eval_episodes, randomize=None),
        "randomized": evaluate(model, norm, args.eval_episodes),
        "unseen": evaluate(model, norm, args.eval_episodes, randomize=None, model_params=UNSEEN),
    }
    args.out.mkdir(parents=True, exist_ok=True)
    with open(args.out / "progress.csv", "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)
    state = {"model": model.state_dict(), "obs_mean": norm.mean, "obs_var": norm.var}
    torch.save(state, args.out / "policy.pt")
    kwargs = preset(TASK).env_kwargs
    summary = dict(
        env_id=preset(TASK).env_id,
        env_kwargs={k: v for k, v in kwargs.items() if k not in ("model_params", "randomize")},
        model_params=px4_vehicle(),
        randomize={k: list(v) for k, v in kwargs["randomize"].items()},
        seed=args.seed,
        config=asdict(cfg),
        env_steps=run["steps"],
        training_wall_s=run["wall_s"],
        evaluation=evaluations,
        evaluation_note="held-out seeds 1,000,000.., one target held for 10 s; success: "
        "within 0.5 m at the time limit",
        command=" ".join(["examples/train/train_offboard.py", *(argv or sys.argv[1:])]),
    )
    export(model, norm, args.out, dict(training=summary))
    (args.out / "summary.json").write_text(json.dumps({**summary, "rows": rows}, indent=2) + "\n")
    fast_ppo.plot({"native": rows}, args.out / "learning_curve.png", task.title)
    for name, e in evaluations.items():
        print(
            f"{name}: held-out success {100 * e['success_rate']:.0f} %, "
            f"final distance {e['mean_final_distance_m']:.3f} m"
        )
    print(f"{run['steps']:,} env steps, {run['wall_s']:.1f} s of training")
    return 0


if __name__ == "__main__":
    sys.exit(main())
