"""Rendering wired into the envs: frames from rgb_array, nothing at all without a mode."""

from __future__ import annotations

import subprocess
import sys
import textwrap

import numpy as np
import pytest

from flyloop.envs import Lander2DEnv, QuadHoverEnv, QuadWaypointsEnv


@pytest.mark.parametrize(
    "cls, shape",
    [
        (QuadHoverEnv, (720, 960, 3)),
        (QuadWaypointsEnv, (720, 960, 3)),
        (Lander2DEnv, (800, 800, 3)),
    ],
)
def test_rgb_array_frames_follow_the_episode(make_env, cls, shape):
    env = make_env(cls, render_mode="rgb_array")
    assert env.metadata["render_fps"] == round(1 / env.unwrapped.dt)
    env.reset(seed=0)
    first = env.render()
    assert first.shape == shape and first.dtype == np.uint8
    assert len(np.unique(first.reshape(-1, 3), axis=0)) > 20, "a drawn scene, not a blank"
    for _ in range(30):
        env.step(env.action_space.sample())
    later = env.render()
    assert later.shape == shape and not np.array_equal(first, later)


def test_without_a_render_mode_pygame_is_never_imported(sitl_binary):
    script = textwrap.dedent(
        """
        import sys, numpy as np, gymnasium as gym, flyloop
        for env_id in ["flyloop/QuadHover-v0", "flyloop/Lander2D-v0"]:
            env = gym.make(env_id)
            env.reset(seed=0)
            env.step(env.action_space.sample())
            assert env.render() is None
            env.close()
        print("pygame" in sys.modules)
        """
    )
    out = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=60)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == "False"
