"""Smoke test of an installed wheel (run by scripts/wheel-smoke.sh in a fresh venv): every
env id passes gymnasium's check_env with both backends, the native vector env steps, and the
wheel's `flyloop-sitl` command is the SITL. Prints 'N passed, N failed'."""

from __future__ import annotations

import subprocess
import sys
import sysconfig
import traceback
from pathlib import Path

import flyloop
import gymnasium as gym
import numpy as np
from flyloop.registration import ENVS
from gymnasium.utils.env_checker import check_env


def check_ids() -> None:
    for env_id in sorted(ENVS):
        for backend in ("sitl", "native"):
            env = gym.make(env_id, backend=backend)
            try:
                check_env(env.unwrapped, skip_render_check=True)
            finally:
                env.close()
            print(f"ok  check_env {env_id} backend={backend}")


def check_vector() -> None:
    for env_id in sorted(ENVS):
        envs = gym.make_vec(
            env_id, num_envs=64, vectorization_mode="vector_entry_point", backend="native"
        )
        obs, _ = envs.reset(seed=0)
        for _ in range(50):
            obs, rew, *_ = envs.step(envs.action_space.sample())
        assert obs.shape[0] == 64 and np.isfinite(rew).all()
        envs.close()
        print(f"ok  native vector env {env_id}")


def check_command() -> None:
    binary = flyloop.find_sitl_binary()
    assert binary == Path(sysconfig.get_path("scripts")) / "flyloop-sitl", binary
    text = subprocess.run(
        [str(binary), "--task", "landing", "--describe-frame"],
        capture_output=True,
        text=True,
        check=True,
        timeout=60,
    ).stdout
    assert "info.touchdown_speed" in text, text
    print(f"ok  {binary} --describe-frame")


def main() -> None:
    passed = failed = 0
    for check in (check_ids, check_vector, check_command):
        try:
            check()
            passed += 1
        except Exception:
            traceback.print_exc()
            failed += 1
    print(f"wheel: {passed} passed, {failed} failed")
    sys.exit(1 if failed else 0)


if __name__ == "__main__":
    main()
