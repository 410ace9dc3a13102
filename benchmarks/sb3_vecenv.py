"""stable-baselines3 on flyloop: the native VecEnv (flyloop.sb3, one batch stepped in one call)
against SB3's DummyVecEnv over single native envs (what train_sb3.py used before), in one run.

    .venv/bin/python benchmarks/sb3_vecenv.py [--seconds 3] [--envs 4 8 64]
        [--ppo-steps 32768]

1. Env steps/s of `VecEnv.step` alone, random actions (drawn in batches beforehand), for
   each --envs count, the best of two alternating rounds of each: QuadHover-v0 as
   train_sb3.py's hover preset makes it (dt 0.02, 250 steps, wind, actions in [-1, 1]) and
   Lander2D-v1 (1,000 steps). Both give the same observations bit for bit
   (python/tests/test_sb3_vecenv.py); the first steps are compared here too.
2. PPO training env steps/s (learning included), train_sb3.py's hover hyperparameters
   (10 epochs of minibatches of 256; torch on one thread) for --ppo-steps env steps on each
   VecEnv, for each --ppo-envs count with the same 2,048 env steps per update (4 envs: 512
   steps per env, train_sb3.py's default; 16 envs: 128).
Prints the CPU, the load average before each part, and each figure with the ratio.
Wall-clock time, so run it on a quiet machine (`uptime` load < 1).
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

import flyloop.sb3
import numpy as np
from stable_baselines3.common.vec_env import DummyVecEnv

sys.path.insert(0, str(Path(__file__).resolve().parent))
from gym_throughput import machine  # noqa: E402

# (label, env id, arguments, actions in [-1, 1] rescaled onto the env's bounds)
ENVS = [
    ("QuadHover-v0, train_sb3's hover", "flyloop/QuadHover-v0", {"dt": 0.02, "max_steps": 250}, 1),
    ("Lander2D-v1", "flyloop/Lander2D-v1", {"max_steps": 1000}, 0),
]


def dummy(env_id: str, n: int, kwargs: dict, unit: bool) -> DummyVecEnv:
    return flyloop.sb3.dummy_vec_env(env_id, n, unit_actions=unit, **kwargs)


def native(env_id: str, n: int, kwargs: dict, unit: bool):
    return flyloop.sb3.make_vec_env(env_id, n, unit_actions=unit, **kwargs)


def steps_per_s(venv, seconds: float) -> float:
    rng = np.random.default_rng(0)
    venv.seed(0)
    venv.reset()
    low, high = venv.action_space.low, venv.action_space.high
    shape = (256, venv.num_envs, *venv.action_space.shape)
    steps, start = 0, time.perf_counter()
    while time.perf_counter() - start < seconds:
        for a in low + (high - low) * rng.random(shape, dtype=np.float32):
            venv.step(a)
        steps += shape[0] * venv.num_envs
    rate = steps / (time.perf_counter() - start)
    venv.close()
    return rate


def same_start(env_id: str, kwargs: dict, unit: bool) -> bool:
    """The first 200 steps of both VecEnvs (4 envs, seed 0) give the same observations."""
    a, b = native(env_id, 4, kwargs, unit), dummy(env_id, 4, kwargs, unit)
    a.seed(0), b.seed(0)
    same = np.array_equal(a.reset(), b.reset())
    rng = np.random.default_rng(1)
    for _ in range(200):
        act = rng.uniform(-1, 1, (4, *a.action_space.shape)).astype(np.float32)
        same &= np.array_equal(a.step(act)[0], b.step(act)[0])
    a.close(), b.close()
    return bool(same)


def ppo_steps_per_s(venv, timesteps: int) -> float:
    """PPO's env steps/s on `venv` (2,048 env steps per update)."""
    import torch
    from stable_baselines3 import PPO

    torch.set_num_threads(1)
    model = PPO(
        "MlpPolicy", venv, n_steps=2048 // venv.num_envs, batch_size=256, n_epochs=10,
        seed=0, device="cpu", policy_kwargs=dict(net_arch=[64, 64]),
    )  # fmt: skip
    start = time.perf_counter()
    model.learn(timesteps)
    rate = model.num_timesteps / (time.perf_counter() - start)
    venv.close()
    return rate


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--seconds", type=float, default=3.0, help="per stepping figure")
    parser.add_argument("--envs", type=int, nargs="+", default=[4, 8, 64])
    parser.add_argument("--ppo-steps", type=int, default=32_768, help="0 skips PPO")
    parser.add_argument("--ppo-envs", type=int, nargs="+", default=[4, 16])
    args = parser.parse_args(argv)
    print(f"CPU: {machine()}")
    print(f"VecEnv.step, random actions, {args.seconds:g} s each; load {os.getloadavg()}")
    for label, env_id, kwargs, unit in ENVS:
        print(f"{label}: same observations as DummyVecEnv: {same_start(env_id, kwargs, unit)}")
        for n in args.envs:
            # Two rounds, alternating, the best of each: load from elsewhere hits both alike.
            ours = ref = 0.0
            for _ in range(2):
                ours = max(ours, steps_per_s(native(env_id, n, kwargs, unit), args.seconds))
                ref = max(ref, steps_per_s(dummy(env_id, n, kwargs, unit), args.seconds))
            print(
                f"  {n:>4} envs: flyloop.sb3 {ours:>10,.0f}  DummyVecEnv {ref:>9,.0f} "
                f"env steps/s  ratio {ours / ref:.1f}x"
            )
    label, env_id, kwargs, unit = ENVS[0]
    for n in args.ppo_envs if args.ppo_steps else []:
        print(f"PPO, {label}, {n} envs, {args.ppo_steps:,} env steps; load {os.getloadavg()}")
        ours = ppo_steps_per_s(native(env_id, n, kwargs, unit), args.ppo_steps)
        ref = ppo_steps_per_s(dummy(env_id, n, kwargs, unit), args.ppo_steps)
        print(
            f"  flyloop.sb3 {ours:,.0f}  DummyVecEnv {ref:,.0f} env steps/s (learning "
            f"included)  ratio {ours / ref:.2f}x"
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
