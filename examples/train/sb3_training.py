"""stable-baselines3 training of the presets in training_envs.py: hyperparameters, the
episode log, and train() that writes a run folder (see train_sb3.py, its command line)."""

from __future__ import annotations

import json
import time
from pathlib import Path
from typing import Any

import flyloop.sb3
import numpy as np
import torch
from learning_curve import EpisodeLog, plot_learning_curve
from stable_baselines3 import PPO, SAC
from stable_baselines3.common.callbacks import BaseCallback
from stable_baselines3.common.vec_env import (
    DummyVecEnv,
    VecEnv,
    VecEnvWrapper,
    VecMonitor,
    VecNormalize,
)
from training_envs import check_action, make_success_env, preset, random_policy_baseline

ALGORITHMS = {"ppo": PPO, "sac": SAC}

PPO_BASE: dict[str, Any] = dict(
    n_envs=4,
    n_steps=1024,
    batch_size=256,
    n_epochs=10,
    learning_rate=3e-4,
    gamma=0.99,
    gae_lambda=0.95,
    policy_kwargs=dict(net_arch=[64, 64]),
)
SAC_BASE: dict[str, Any] = dict(
    n_envs=1,
    learning_rate=3e-4,
    buffer_size=200_000,
    batch_size=256,
    learning_starts=5_000,
    gamma=0.99,
    policy_kwargs=dict(net_arch=[64, 64]),
)
# Lander2D: a landing comes after 300–700 steps of 20 ms, so a longer horizon (γ = 0.995:
# 200 steps, 4 s) lets the +100 of a landing reach the approach; 8 envs decorrelate batches.
LANDER_PPO: dict[str, Any] = {**PPO_BASE, "n_envs": 8, "n_steps": 512, "gamma": 0.995}

# Hyperparameters per (env preset, algorithm); tuned only as far as "learns on 2 cores in
# minutes". n_envs is the number of envs (and SITL processes) stepped together.
HYPERPARAMETERS: dict[tuple[str, str], dict[str, Any]] = {
    ("hover", "ppo"): {**PPO_BASE, "n_steps": 512},
    ("hover", "sac"): SAC_BASE,
    **{(name, "ppo"): LANDER_PPO for name in ("lander", "lander_moving", "lander_v0")},
    **{(name, "sac"): SAC_BASE for name in ("lander", "lander_moving", "lander_v0")},
}


class EpisodeRecorder(BaseCallback):
    """Appends every finished episode (from VecMonitor's info['episode']) to an EpisodeLog."""

    def __init__(self, log: EpisodeLog) -> None:
        super().__init__()
        self.log = log

    def _on_step(self) -> bool:
        for info in self.locals["infos"]:
            episode = info.get("episode")
            if episode is not None:
                self.log.add(
                    self.num_timesteps, episode["r"], episode["l"], bool(info.get("is_success"))
                )
        return True


class SuccessInfos(VecEnvWrapper):
    """Sets info['is_success'] where an episode ended (SuccessInfo for a VecEnv): SB3's
    `TimeLimit.truncated` is truncated and not terminated, all the preset's test needs."""

    def __init__(self, venv: VecEnv, success) -> None:
        super().__init__(venv)
        self._success = success

    def reset(self):
        return self.venv.reset()

    def step_wait(self):
        obs, rewards, dones, infos = self.venv.step_wait()
        for i in np.flatnonzero(dones):
            info = infos[i]
            truncated = bool(info["TimeLimit.truncated"])
            info["is_success"] = bool(self._success(not truncated, truncated, info))
        return obs, rewards, dones, infos


def make_base_vec_env(env: str, action: str | None, n_envs: int, backend: str) -> VecEnv:
    """The preset's n_envs envs with info['is_success'] at episode ends. Native backend with
    the preset's default action interface: one flyloop.sb3 VecEnv over the native batch
    (the same episodes as single envs, several times faster); otherwise single envs (a SITL
    each with backend="sitl"; the other action interfaces are single-env wrappers) in a
    DummyVecEnv."""
    p = preset(env)
    action = check_action(p, action)
    if backend == "native" and action == p.default_action:
        venv = flyloop.sb3.make_vec_env(
            p.env_id, n_envs, unit_actions=action is not None, **p.env_kwargs
        )
        return SuccessInfos(venv, p.success)
    return DummyVecEnv([lambda: make_success_env(env, action=action, backend=backend)] * n_envs)


def make_vec_env(
    env: str,
    action: str | None,
    n_envs: int,
    seed: int,
    gamma: float,
    backend: str = "native",
    statistics: Path | None = None,
) -> VecNormalize:
    """n_envs preset envs (make_base_vec_env), monitored and normalised (starting from the
    normalisation `statistics` of an earlier run, if given); env i's first episode has seed
    `seed + i`."""
    venv = make_base_vec_env(env, action, n_envs, backend)
    venv.seed(seed)
    if statistics is not None:
        return VecNormalize.load(str(statistics), VecMonitor(venv))
    return VecNormalize(VecMonitor(venv), gamma=gamma)


def linear_decay(start: float):
    """A learning rate falling linearly from `start` to 0 over the run (stable-baselines3
    calls it with the fraction of the run remaining)."""
    return lambda remaining: start * remaining


def train(
    env: str,
    algo: str,
    timesteps: int,
    seed: int,
    out: Path,
    *,
    action: str | None = None,
    progress_bar: bool = True,
    baseline_episodes: int = 20,
    n_envs: int | None = None,
    backend: str = "native",
    hyper_overrides: dict[str, Any] | None = None,
    init_from: Path | None = None,
    lr_decay: bool = False,
) -> dict[str, Any]:
    """Trains, saves everything under `out` and returns the summary (also in summary.json).
    `init_from`: continue from the policy and normalisation of an earlier run's folder;
    `lr_decay`: the learning rate falls linearly to 0 over this run."""
    torch.set_num_threads(1)
    p = preset(env)
    if algo not in ALGORITHMS:
        raise ValueError(f"unknown algorithm {algo!r}; choose one of {sorted(ALGORITHMS)}")
    action = check_action(p, action)
    hyper = {**HYPERPARAMETERS[(p.name, algo)], **(hyper_overrides or {})}
    n = int(hyper.pop("n_envs"))
    n = n if n_envs is None else int(n_envs)
    out.mkdir(parents=True, exist_ok=True)

    random_return, random_success = random_policy_baseline(
        p.name, episodes=baseline_episodes, seed=10_000 + seed, action=action, backend=backend
    )
    print(
        f"random policy on {p.env_id}: mean return {random_return:.1f}, "
        f"success {100 * random_success:.0f} % ({baseline_episodes} episodes)"
    )

    if lr_decay:
        hyper["learning_rate"] = linear_decay(hyper["learning_rate"])
    statistics = Path(init_from) / "vecnormalize.pkl" if init_from is not None else None
    gamma = hyper.get("gamma", 0.99)
    venv = make_vec_env(p.name, action, n, seed, gamma, backend=backend, statistics=statistics)
    log = EpisodeLog()
    try:
        if init_from is None:
            model = ALGORITHMS[algo](
                "MlpPolicy",
                venv,
                seed=seed,
                verbose=0,
                tensorboard_log=str(out / "tb"),
                device="cpu",
                **hyper,
            )
        else:
            model = ALGORITHMS[algo].load(
                Path(init_from) / "model.zip",
                env=venv,
                device="cpu",
                seed=seed,
                tensorboard_log=str(out / "tb"),
                custom_objects={"learning_rate": hyper["learning_rate"]},
            )
            model.set_random_seed(seed)
        start = time.perf_counter()
        model.learn(
            total_timesteps=timesteps,
            callback=EpisodeRecorder(log),
            progress_bar=progress_bar,
            tb_log_name=f"{p.name}_{algo}",
        )
        wall = time.perf_counter() - start
        steps = int(model.num_timesteps)
        model.save(out / "model.zip")
        venv.save(str(out / "vecnormalize.pkl"))
    finally:
        venv.close()

    log.write_csv(out / "episodes.csv")
    title = f"{algo.upper()} on {p.env_id} (seed {seed}, {n} envs, {steps:,} steps, {wall:.0f} s)"
    plot_learning_curve(log, out / "learning_curve.png", title=title, random_return=random_return)
    last = slice(-max(1, len(log) // 10), None)
    summary = dict(
        env=p.name,
        env_id=p.env_id,
        env_kwargs=dict(p.env_kwargs),
        action=action,
        algo=algo,
        backend=backend,
        seed=seed,
        n_envs=n,
        timesteps=steps,
        wall_time_s=wall,
        env_steps_per_s=steps / wall,
        episodes=len(log),
        random_mean_return=random_return,
        random_success_rate=random_success,
        last_tenth_mean_return=float(np.mean(log.returns[last])) if len(log) else None,
        last_tenth_success_rate=float(np.mean(log.successes[last])) if len(log) else None,
        success=p.success_text,
        init_from=str(init_from) if init_from is not None else None,
        lr_decay=lr_decay,
    )
    (out / "summary.json").write_text(json.dumps(summary, indent=2) + "\n")
    return summary
