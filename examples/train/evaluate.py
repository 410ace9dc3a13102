"""Evaluate a model saved by train_sb3.py or fast_ppo.py: N episodes, success rate and mean
return.

    .venv/bin/python examples/train/evaluate.py runs/hover_ppo --episodes 100
    .venv/bin/python examples/train/evaluate.py runs/hover_ppo --random   # the random bar
    .venv/bin/python examples/train/evaluate.py policies/lander_static --episodes 100 \
        --seed-offset 1000000                                # a shipped policy

The folder holds summary.json (which env and algorithm) and either model.zip and
vecnormalize.pkl (a train_sb3.py output) or policy.pt (a fast_ppo.py output, OUT/native/):
a training output or a shipped policy under policies/.
    .venv/bin/python examples/train/evaluate.py policies/hover --env hover_motor_fault
                                                             # on another preset's episodes

The policy acts deterministically (the mean of its action distribution). Episode k has seed
--seed-offset + k (--seed is the same option), so two evaluations with the same seeds fly
the same episodes; the default seeds (1,000,000 and up) are never among the training seeds.

What counts as a success:
- hover, hover_motor_fault (QuadHover-v0; the latter through a weak motor): the episode
  reaches the time limit (truncated: no crash, not out of bounds) and ends within 0.5 m of
  the target;
- lander, lander_moving, lander_v0 (Lander2D-v1 static or moving pad, Lander2D-v0): the
  drone landed on the platform (info['landed']); the touch-down speed relative to the
  platform and |angle| of the landings are reported too;
- swap, swap_layers (Swap-v0/-v1, a fast_ppo.py policy shared by the four agents): an
  episode is one world, flown by fast_ppo.py's own held-out evaluation; success is the
  task's (every agent arrived, none collided or crashed).
"""

from __future__ import annotations

import argparse
import json
import pickle
import sys
from pathlib import Path
from typing import Any

import numpy as np
from training_envs import make_env, preset

EVAL_SEED = 1_000_000


class SavedRun:
    """A trained policy from a train_sb3.py or fast_ppo.py folder, with its observation
    normalisation."""

    def __init__(self, folder: Path) -> None:
        folder = Path(folder)
        summary_path = folder / "summary.json"
        if not summary_path.is_file():
            raise FileNotFoundError(
                f"{summary_path} not found: is {folder} a train_sb3.py or fast_ppo.py output?"
            )
        self.summary = json.loads(summary_path.read_text())
        if "env" not in self.summary:
            raise ValueError(
                f"{folder} is not a train_sb3.py or fast_ppo.py run (its summary names no env "
                "preset); a train_offboard.py policy flies through PX4 with "
                "examples/px4_offboard.py"
            )
        self.preset = preset(self.summary["env"])
        if self.summary.get("algo") == "fast_ppo":
            self._load_fast_ppo(folder)
            return
        # Imported only now: torch and stable-baselines3 take seconds to load.
        from stable_baselines3 import PPO, SAC

        algorithms = {"ppo": PPO, "sac": SAC}
        self.model = algorithms[self.summary["algo"]].load(folder / "model.zip", device="cpu")
        # The normalisation statistics only: a VecNormalize pickled without its envs
        # (stable-baselines3 drops them on save), so no env is made for it.
        with open(folder / "vecnormalize.pkl", "rb") as f:
            self.norm = pickle.load(f)
        self.norm.training = False

    def _load_fast_ppo(self, folder: Path) -> None:
        """fast_ppo.py's policy.pt: the actor-critic's weights and the observation mean and
        variance; the policy acts with the mean of its Gaussian, clipped to [-1, 1]."""
        import torch
        from fast_ppo import ActorCritic, RunningNorm

        saved = torch.load(folder / "policy.pt", weights_only=False)
        state = saved["model"]
        obs_size, act_size = state["mu.0.weight"].shape[1], state["log_std"].shape[0]
        config = self.summary["config"]
        basis = config.get("action_basis", "motors")
        # The critic's extra input (the time remaining) when the run was timed.
        extra = int(config.get("time_limit_terminal", False))
        self.model = ActorCritic(
            obs_size, act_size, config["hidden"], basis=basis, value_extra=extra
        )
        self.model.load_state_dict(state)
        self.model.eval()
        self.norm = RunningNorm(obs_size)
        self.norm.mean, self.norm.var = saved["obs_mean"], saved["obs_var"]

        def act(obs: np.ndarray) -> np.ndarray:
            with torch.no_grad():
                mean = self.model.mu(torch.as_tensor(self.norm(obs[None, :]))).numpy()
                mean = self.model.to_actions(mean)
            return np.clip(mean[0], -1.0, 1.0)

        self.act = act

    def act(self, obs: np.ndarray) -> np.ndarray:
        normalised = self.norm.normalize_obs(obs[None, :].astype(np.float32))
        action, _ = self.model.predict(normalised, deterministic=True)
        return action[0]


def preset_of(run: SavedRun | None, env: str | None):
    """The preset episodes are flown on: `env` when given (a policy may fly another preset
    of its env id, e.g. the hover policy on hover_motor_fault's faulty episodes), else the
    run's own (random actions: hover)."""
    if env is None:
        return run.preset if run is not None else preset("hover")
    p = preset(env)
    if run is not None and p.env_id != run.preset.env_id:
        raise ValueError(
            f"--env {env} is {p.env_id}; the policy was trained on {run.preset.env_id}"
        )
    return p


def evaluate(
    folder: Path | None,
    episodes: int,
    seed: int = EVAL_SEED,
    *,
    env: str | None = None,
    backend: str = "native",
) -> dict[str, Any]:
    """Runs `episodes` episodes of the saved policy in `folder` (or of uniformly random
    actions when folder is None) on the preset `env` (default: the policy's own, or hover)
    and returns the figures."""
    if folder is not None:
        import torch

        torch.set_num_threads(1)
    run = SavedRun(folder) if folder is not None else None
    p = preset_of(run, env)
    if is_swarm(p):
        return evaluate_swarm(run, folder, p, episodes, seed, backend)
    action = run.summary.get("action") if run is not None else None
    rng = np.random.default_rng(seed)
    e = make_env(p.name, action=action, backend=backend)

    def random_action(obs):
        return rng.uniform(e.action_space.low, e.action_space.high)

    act = run.act if run is not None else random_action
    returns, lengths, successes, final_distances = [], [], [], []
    landing_speeds, landing_angles = [], []
    try:
        for k in range(episodes):
            total, length, terminated, truncated, info = run_episode(e, act, seed + k)
            returns.append(total)
            lengths.append(length)
            successes.append(bool(p.success(terminated, truncated, info)))
            if "distance_to_target" in info:
                final_distances.append(float(info["distance_to_target"]))
            if info.get("landed"):
                landing_speeds.append(float(info["touchdown_speed"]))
                landing_angles.append(abs(float(info["angle"])))
    finally:
        e.close()
    return dict(
        env=p.name,
        env_id=p.env_id,
        policy=str(folder) if folder is not None else "random",
        episodes=episodes,
        first_seed=seed,
        success_rate=float(np.mean(successes)),
        mean_return=float(np.mean(returns)),
        std_return=float(np.std(returns)),
        mean_length=float(np.mean(lengths)),
        median_final_distance_m=float(np.median(final_distances)) if final_distances else None,
        landings=len(landing_speeds),
        landing_speed_mean_m_s=_mean(landing_speeds),
        landing_speed_max_m_s=max(landing_speeds, default=None),
        landing_angle_mean_rad=_mean(landing_angles),
        landing_angle_max_rad=max(landing_angles, default=None),
        success=p.success_text,
    )


def is_swarm(p) -> bool:
    """A multi-agent preset (its env is a flyloop.parallel_env, not a gym.make env)."""
    import flyloop.multi_agent

    return p.env_id in flyloop.multi_agent.ENV_TASKS


def evaluate_swarm(run, folder, p, episodes: int, seed: int, backend: str) -> dict[str, Any]:
    """A multi-agent preset (swap): `episodes` worlds of its agents, each agent flown by the
    shared policy, through fast_ppo.py's evaluation (the one its summary.json reports)."""
    if run is None or run.summary.get("algo") != "fast_ppo":
        raise ValueError(f"{p.name} is a multi-agent task: only a fast_ppo.py policy flies it")
    import fast_ppo

    figures = fast_ppo.evaluate(run.model, run.norm, p.name, backend, episodes, seed)
    return dict(
        env=p.name,
        env_id=p.env_id,
        policy=str(folder),
        episodes=episodes,
        first_seed=seed,
        success_rate=figures["success_rate"],
        mean_return=figures["mean_return"],
        std_return=None,
        mean_length=None,
        median_final_distance_m=None,
        landings=0,
        success=p.success_text,
    )


def run_episode(e, act, seed: int) -> tuple[float, int, bool, bool, dict]:
    """One episode of env `e` from `seed`, acting act(observation): its return, length,
    final flags and last info."""
    obs, info = e.reset(seed=seed)
    total, length, done = 0.0, 0, False
    while not done:
        action = act(obs)
        obs, reward, terminated, truncated, info = e.step(action.astype(np.float32))
        total += reward
        length += 1
        done = terminated or truncated
    return total, length, terminated, truncated, info


def _mean(values: list[float]) -> float | None:
    return float(np.mean(values)) if values else None


def parse_args(argv: list[str] | None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument(
        "run", type=Path, nargs="?", help="train_sb3.py or fast_ppo.py output folder"
    )
    parser.add_argument("--episodes", type=int, default=100)
    parser.add_argument(
        "--seed-offset",
        "--seed",
        dest="seed",
        type=int,
        default=EVAL_SEED,
        help="seed of the first episode (episode k has seed offset + k)",
    )
    parser.add_argument("--random", action="store_true", help="evaluate random actions instead")
    parser.add_argument(
        "--env",
        help="the preset to fly (default: the policy's own; with --random hover): e.g. "
        "hover_motor_fault flies a hover policy through a weak motor",
    )
    parser.add_argument(
        "--backend",
        default="native",
        choices=("native", "sitl"),
        help="the core in this process (default) or a flyloop-sitl process: same episodes",
    )
    parser.add_argument("--json", type=Path, help="also write the figures to this file")
    parser.add_argument(
        "--gif",
        type=Path,
        help="also record the first episode (seed --seed-offset) of the policy to this GIF/MP4",
    )
    args = parser.parse_args(argv)
    if args.episodes < 1:
        parser.error("--episodes must be >= 1")
    if args.random == (args.run is not None):
        parser.error("give either a run folder or --random")
    return args


def print_figures(result: dict[str, Any], episodes: int, seed: int) -> None:
    print(
        f"{result['policy']} on {result['env_id']}, {episodes} episodes "
        f"(seeds {seed}..{seed + episodes - 1}):"
    )
    print(f"  success rate {100 * result['success_rate']:.1f} %  ({result['success']})")
    if result["std_return"] is None:  # a multi-agent task: per agent, over all agents
        print(f"  mean return per agent {result['mean_return']:.1f}")
    else:
        print(f"  mean return {result['mean_return']:.1f} ± {result['std_return']:.1f}")
        print(f"  mean episode length {result['mean_length']:.0f} steps")
    if result["median_final_distance_m"] is not None:
        print(f"  median final distance to target {result['median_final_distance_m']:.3f} m")
    if result["landings"]:
        print(
            f"  landings: touch-down speed mean {result['landing_speed_mean_m_s']:.2f} m/s, "
            f"max {result['landing_speed_max_m_s']:.2f} m/s; |angle| mean "
            f"{result['landing_angle_mean_rad']:.3f} rad, max {result['landing_angle_max_rad']:.3f}"
        )


def main(argv: list[str] | None = None) -> int:
    args = parse_args(argv)
    try:
        result = evaluate(
            None if args.random else args.run,
            args.episodes,
            args.seed,
            env=args.env,
            backend=args.backend,
        )
    except (FileNotFoundError, ValueError) as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    print_figures(result, args.episodes, args.seed)
    if args.json is not None:
        args.json.write_text(json.dumps(result, indent=2) + "\n")
    if args.gif is not None and result["std_return"] is None:
        print(f"  --gif: a swap policy's GIF is examples/train/swap_gif.py {args.run}")
    elif args.gif is not None:
        shot = record(None if args.random else args.run, args.gif, args.seed, env=args.env)
        ending = shot["outcome"]
        print(f"  recorded seed {args.seed} ({shot['steps']} steps, {ending}) to {args.gif}")
    return 0


def record(
    folder: Path | None,
    path: Path,
    seed: int,
    *,
    env: str | None = None,
    frame_every: int = 2,
    scale: float = 0.5,
) -> dict[str, Any]:
    """Records one episode (seed `seed`) of the saved policy in `folder` (random actions when
    None), acting as in evaluate(), rendered with render_mode="rgb_array": every
    `frame_every`-th step, scaled by `scale`, played at real time, to a GIF or MP4."""
    from flyloop.rendering import save_video
    from PIL import Image

    run = SavedRun(folder) if folder is not None else None
    p = preset_of(run, env)
    action = run.summary.get("action") if run is not None else None
    e = make_env(p.name, action=action, render_mode="rgb_array")
    rng = np.random.default_rng(seed)

    def shrink(frame: np.ndarray) -> np.ndarray:
        image = Image.fromarray(frame)
        size = (round(image.width * scale), round(image.height * scale))
        return np.asarray(image.resize(size, Image.Resampling.LANCZOS))

    try:
        obs, info = e.reset(seed=seed)
        frames, steps, done = [shrink(e.render())], 0, False
        while not done:
            if run is not None:
                a = run.act(obs)
            else:
                a = rng.uniform(e.action_space.low, e.action_space.high)
            obs, _, terminated, truncated, info = e.step(a.astype(np.float32))
            steps += 1
            done = terminated or truncated
            if done or steps % frame_every == 0:
                frames.append(shrink(e.render()))
        fps = 1.0 / (e.unwrapped.dt * frame_every)
    finally:
        e.close()
    save_video(frames, path, fps=fps)
    success = bool(p.success(terminated, truncated, info))
    return dict(
        path=path, frames=len(frames), steps=steps, success=success, outcome=p.outcome(success)
    )


if __name__ == "__main__":
    sys.exit(main())
