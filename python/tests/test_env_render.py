"""Rendering wired into the envs: frames from rgb_array, nothing at all without a mode."""

from __future__ import annotations

import subprocess
import sys
import textwrap

import numpy as np
import pytest

from flyloop.envs import Lander2DEnv, QuadHoverEnv, QuadWaypointsEnv
from flyloop.rendering import LanderScene, LanderView, QuadrotorView, QuadScene


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


def frames_match_scenes(env, view, scene_of, actions):
    """Steps env with `actions`; at reset and after each step its frame must equal the one
    `view` draws of scene_of(obs, info, reward, episode_return)."""
    obs, info = env.reset(seed=4)
    reward, total = None, 0.0
    try:
        for action in actions:
            expected = view.render(scene_of(obs, info, reward, total))
            np.testing.assert_array_equal(env.render(), expected)
            obs, reward, terminated, truncated, info = env.step(action)
            total += reward
            if terminated or truncated:
                break
        np.testing.assert_array_equal(env.render(), view.render(scene_of(obs, info, reward, total)))
    finally:
        view.close()
    return info


def test_a_waypoints_frame_draws_the_observation_and_info_it_returned(make_env):
    env = make_env(QuadWaypointsEnv, render_mode="rgb_array", backend="native")

    def scene_of(obs, info, reward, total):
        # The Waypoints observation: velocity 3:6, quaternion 9:13, wind 22:25, motors 25:29.
        return QuadScene(
            time_s=info["episode_time"],
            step=info["step_count"],
            position=info["position"],
            velocity=obs[3:6],
            quaternion=obs[9:13],
            wind=obs[22:25],
            motors=obs[25:29],
            target=info["target_position"],
            next_waypoint=info["next_waypoint_pos"],
            reward=reward,
            episode_return=total,
            waypoints_reached=info["waypoints_reached"],
            status="crashed"
            if info["crashed"]
            else "out of bounds"
            if info["out_of_bounds"]
            else "",
        )

    rng = np.random.default_rng(0)
    actions = rng.uniform(0.3, 0.8, (60, 4)).astype(np.float32)
    frames_match_scenes(env, QuadrotorView("rgb_array"), scene_of, actions)


def test_a_lander_frame_draws_the_info_and_parameters_of_its_env(make_env):
    env = make_env(
        Lander2DEnv,
        render_mode="rgb_array",
        backend="native",
        moving_platform=True,
        platform_speed=3.0,
        spawn_x=30.0,
        model_params={"world_width": 60.0},
    )
    endings = ("lost_control", "out_of_bounds", "battery_empty")

    def scene_of(obs, info, reward, total):
        outcome = next((key.replace("_", " ") for key in endings if info[key]), "")
        return LanderScene(
            time_s=info["step"] * 0.02,
            step=info["step"],
            position=info["position"],
            velocity=info["velocity"],
            angle=info["angle"],
            angular_velocity=info["angular_velocity"],
            thrust=info["thrust"],
            battery=info["battery"],
            platform_x=info["platform_position"][0],
            platform_vx=float(obs[11]) * 3.0,  # observed as a fraction of platform_speed
            wind_force=info["wind_force"],
            wind_speed=5.0,
            landed=info["landed"],
            crashed=info["crashed"],
            outcome=outcome,
            max_steps=1000,
            reward=reward,
            episode_return=total,
            world_width=60.0,
            spawn_center=(30.0, 40.0),
        )

    actions = np.tile(np.array([0.2, 0.1], np.float32), (300, 1))
    info = frames_match_scenes(env, LanderView("rgb_array"), scene_of, actions)
    assert info["lost_control"]  # so the panel's "Lost control!" was compared too
