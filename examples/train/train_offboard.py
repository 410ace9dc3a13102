"""Train a policy that flies through PX4: collective thrust + body rates (PX4's offboard rates
setpoint) through the core's model of PX4's rate loop, on the Iris of flyloop's PX4 preset,
with domain randomisation, by the fast PPO (fast_ppo.py) on the native vector env.

    .venv/bin/python examples/train/train_offboard.py --out runs/offboard

Writes OUT/: `policy.npz` + `policy.json` (the policy as examples/px4_offboard.py loads it: a
numpy MLP, its observation normalisation and its interface), `policy.pt`, `progress.csv`,
`learning_curve.png` and `summary.json` with held-out evaluations (seeds from 1,000,000) on
the nominal Iris and on an unseen vehicle (mass +20 %, thrust coefficient −10 %).
"""

from __future__ import annotations

import argparse
import csv
import json
import sys
import time
from dataclasses import asdict
from pathlib import Path

import fast_ppo
import flyloop  # noqa: F401  (registers the envs)
import gymnasium as gym
import numpy as np
import tomllib
import torch

ROOT = Path(__file__).resolve().parents[2]
# The Iris of flyloop-sitl --px4 (wind is the env argument use_wind).
IRIS = tomllib.loads((ROOT / "sitl" / "presets" / "px4_iris.toml").read_text())
IRIS.pop("wind_enabled", None)
# The vehicle the policy never saw: the README's unseen-vehicle config for flyloop-sitl --px4.
UNSEEN = {
    **IRIS,
    "mass": IRIS["mass"] * 1.2,
    "thrust_coefficient": IRIS["thrust_coefficient"] * 0.9,
}

# What the policy is trained on: the rates interface at 50 Hz, PX4-like estimator noise, a
# control latency, and per-episode vehicles around the Iris.
ENV_KWARGS = dict(
    action_interface="rates",
    dt=0.02,
    max_steps=500,
    target_change_interval=250,
    use_wind=False,
    start_attitude_range=0.2,
    observation_noise={"position": 0.02, "velocity": 0.05, "attitude": 0.01, "rates": 0.02},
)
RANDOMIZE = {
    "mass": (1.2, 1.85),
    "inertia_xx": (0.023, 0.035),
    "inertia_yy": (0.023, 0.035),
    "inertia_zz": (0.044, 0.066),
    "thrust_coefficient": (8.5, 11.0),
    "yaw_torque_coefficient": (0.04, 0.08),
    "motor_time_constant": (0.015, 0.035),
    "drag_area": (0.02, 0.1),
    "roll_rate_p": (0.12, 0.18),
    "pitch_rate_p": (0.12, 0.18),
    "action_latency": (0.0, 0.04),
}


def make_envs(backend: str, num_envs: int, randomize=RANDOMIZE, vehicle=IRIS, **overrides):
    kwargs = {**ENV_KWARGS, **overrides}
    if randomize:
        kwargs["randomize"] = randomize
    return gym.make_vec(
        "flyloop/QuadHover-v0",
        num_envs=num_envs,
        vectorization_mode="vector_entry_point",
        backend=backend,
        model_params=vehicle,
        **kwargs,
    )


def evaluate(model, norm, episodes: int, **env) -> dict:
    """The deterministic policy on `episodes` episodes seeded 1,000,000.. on the vehicle
    `env` gives, each holding one target for the whole episode; success = the hover preset's
    (within 0.5 m at the time limit)."""
    envs = make_envs("native", episodes, target_change_interval=None, **env)
    try:
        obs, _ = envs.reset(seed=fast_ppo.EVAL_SEED)
        done = np.zeros(episodes, bool)
        success = np.zeros(episodes, bool)
        distance = np.zeros(episodes)
        while not done.all():
            with torch.no_grad():
                action = model.mu(torch.as_tensor(norm(obs))).numpy()
            space = envs.single_action_space
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


def export(model, norm, space: gym.spaces.Box, out: Path, meta: dict) -> None:
    """policy.npz (mean network, normalisation) and policy.json (its interface) for
    examples/px4_offboard.py, which needs numpy only."""
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
        dt=ENV_KWARGS["dt"],
        **meta,
    )
    (out / "policy.json").write_text(json.dumps(interface, indent=2) + "\n")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--timesteps", type=int, default=3_000_000)
    parser.add_argument("--num-envs", type=int, default=128)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--eval-episodes", type=int, default=200)
    parser.add_argument("--out", type=Path, default=Path("runs/offboard"))
    parser.add_argument("--no-progress-bar", action="store_true")
    args = parser.parse_args(argv)
    cfg = fast_ppo.Config(num_envs=args.num_envs, rollout_steps=64, learning_rate=5e-4)
    fast_ppo.make_envs = make_envs  # fast_ppo's training loop on these envs
    started = time.perf_counter()
    run = fast_ppo.train(args, "native", cfg)
    model, norm = run["model"], run["norm"]
    nominal = evaluate(model, norm, args.eval_episodes, randomize=None)
    unseen = evaluate(model, norm, args.eval_episodes, randomize=None, vehicle=UNSEEN)
    args.out.mkdir(parents=True, exist_ok=True)
    rows = run["rows"]
    with open(args.out / "progress.csv", "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)
    torch.save(
        {"model": model.state_dict(), "obs_mean": norm.mean, "obs_var": norm.var},
        args.out / "policy.pt",
    )
    envs = make_envs("native", 1)
    space = envs.single_action_space
    envs.close()
    summary = dict(
        env_id="flyloop/QuadHover-v0",
        env_kwargs=ENV_KWARGS,
        model_params=IRIS,
        randomize={k: list(v) for k, v in RANDOMIZE.items()},
        seed=args.seed,
        config=asdict(cfg),
        env_steps=run["steps"],
        training_wall_s=run["wall_s"],
        total_wall_s=time.perf_counter() - started,
        evaluation_nominal=nominal,
        evaluation_unseen=unseen,
        command=" ".join(
            ["examples/train/train_offboard.py", *(argv if argv is not None else sys.argv[1:])]
        ),
    )
    export(model, norm, space, args.out, dict(training=summary))
    (args.out / "summary.json").write_text(json.dumps({**summary, "rows": rows}, indent=2) + "\n")
    fast_ppo.plot(
        {"native": rows},
        args.out / "learning_curve.png",
        "PPO, rates interface, Iris with randomisation",
    )
    for name, e in (("nominal Iris", nominal), ("unseen vehicle", unseen)):
        print(
            f"{name}: held-out success {100 * e['success_rate']:.0f} %, "
            f"final distance {e['mean_final_distance_m']:.3f} m"
        )
    print(f"{run['steps']:,} env steps, {run['wall_s']:.1f} s of training")
    return 0


if __name__ == "__main__":
    sys.exit(main())
