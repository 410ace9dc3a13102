"""Scenes from task frames and per-episode history of flyloop.rendering (no pygame)."""

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import flyloop
from flyloop.rendering import LanderScene, QuadScene, lander_scene, quad_scene
from flyloop.rendering.canvas import FlightPath


def quad(**over):
    base = dict(time_s=0.0, step=0, position=(0, 0, 1), velocity=(0, 0, 0), quaternion=(1, 0, 0, 0))
    base.update(over)
    return QuadScene(**base)


def lander(**over):
    base = dict(
        time_s=0.0,
        step=0,
        position=(25, 40),
        velocity=(0, 0),
        angle=0.0,
        angular_velocity=0.0,
        thrust=(7, 7),
        battery=100.0,
        platform_x=25.0,
    )
    base.update(over)
    return LanderScene(**base)


def test_importing_the_package_does_not_import_pygame():
    code = "import sys, flyloop.rendering; print('pygame' in sys.modules)"
    # The child finds flyloop where this process did (installed or on pytest's pythonpath).
    root = str(Path(flyloop.__file__).resolve().parents[1])
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([root, os.environ.get("PYTHONPATH", "")])}
    out = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, check=True, env=env
    )
    assert out.stdout.strip() == "False"


def test_quad_scene_normalises_and_stores_arrays():
    s = quad(quaternion=(2, 0, 0, 0), motors=(1.0000001, -1e-9, 0.5, 0.25), target=[1, 2, 3])
    np.testing.assert_allclose(s.quaternion, [1, 0, 0, 0])
    np.testing.assert_allclose(s.motors, [1.0, 0.0, 0.5, 0.25])
    assert s.target.dtype == np.float64 and s.target.shape == (3,)
    assert s.next_waypoint is None


def test_lander_scene_derives_the_sensor_target():
    s = lander(position=(28.0, 14.5), platform_x=25.0)
    assert s.platform_top == (25.0, 10.5)
    assert s.distance_to_platform == pytest.approx(5.0)


def test_flight_path_restarts_with_each_episode_and_records_a_step_once():
    path = FlightPath(max_points=3)
    for step in range(5):
        assert path.update(step, (step, 0.0)) is False
    assert path.points[:, 0].tolist() == [2, 3, 4]  # bounded, oldest dropped
    path.update(4, (40.0, 0.0))  # the same step rendered again replaces, not appends
    assert path.points[:, 0].tolist() == [2, 3, 40]
    assert path.update(0, (7.0, 7.0)) is True  # step went back: a new episode
    assert path.points.tolist() == [[7.0, 7.0]]
    path.clear()
    assert len(path.points) == 0


def test_quad_scene_from_a_waypoints_step():
    obs = np.zeros(37)
    obs[3:6] = (1.0, 2.0, 3.0)
    obs[9:13] = (0.0, 0.0, 0.0, 1.0)
    obs[13:16] = (0.1, 0.2, 0.3)
    obs[22:25] = (4.0, 0.0, -1.0)
    obs[25:29] = (0.1, 0.2, 0.3, 0.4)
    info = {  # names and order as `flyloop-sitl --task waypoints --describe-frame`
        "distance_to_target": 1.0,
        "position": [0.5, 0.6, 1.7],
        "target_position": [1.0, 1.0, 2.0],
        "step_count": 42.0,
        "episode_time": 0.42,
        "distance_progress": 0.1,
        "crashed": 0.0,
        "out_of_bounds": 1.0,
        "waypoints_reached": 3.0,
        "current_waypoint_pos": [1.0, 1.0, 2.0],
        "next_waypoint_pos": [-1.0, 0.0, 1.0],
        "steps_since_checkpoint": 0.3,
    }
    s = quad_scene(obs, info, reward=0.5, episode_return=3.0)
    assert (s.time_s, s.step, s.waypoints_reached, s.status) == (0.42, 42, 3, "out of bounds")
    np.testing.assert_allclose(s.position, [0.5, 0.6, 1.7])
    np.testing.assert_allclose(s.velocity, [1, 2, 3])
    np.testing.assert_allclose(s.quaternion, [0, 0, 0, 1])
    np.testing.assert_allclose(s.wind, [4, 0, -1])
    np.testing.assert_allclose(s.motors, [0.1, 0.2, 0.3, 0.4])
    np.testing.assert_allclose(s.target, [1, 1, 2])
    np.testing.assert_allclose(s.next_waypoint, [-1, 0, 1])
    hover_info = {k: v for k, v in info.items() if k in list(info)[:8]}
    hover = quad_scene(obs[:33], hover_info)
    assert hover.next_waypoint is None and hover.waypoints_reached is None


def test_lander_scene_from_a_landing_step():
    info = {  # names as `flyloop-sitl --model lander2d --task landing --describe-frame`
        "position": [30.0, 20.0],
        "velocity": [1.0, -2.0],
        "angle": 0.1,
        "angular_velocity": -0.2,
        "battery": 88.0,
        "thrust": [6.0, 9.0],
        "wind_force": [0.0, -2.5],
        "platform_position": [27.0, 10.5],
        "distance": 9.96,
        "landed": 0.0,
        "crashed": 0.0,
        "lost_control": 0.0,
        "out_of_bounds": 0.0,
        "battery_empty": 1.0,
        "time_limit": 0.0,
        "platform_contact": 0.0,
        "touchdown_speed": 0.0,
        "step": 150.0,
    }
    obs = np.zeros(12)
    obs[11] = -1.0
    params = {"platform_speed": 2.5, "world_width": 60.0, "spawn_x": 30.0}
    s = lander_scene(info, obs, max_steps=1000, params=params)
    assert (s.step, s.time_s, s.outcome, s.max_steps) == (150, 3.0, "battery empty", 1000)
    assert (s.platform_x, s.platform_vx, s.world_width) == (27.0, -2.5, 60.0)
    assert s.spawn_center.tolist() == [30.0, 40.0]
    np.testing.assert_allclose(s.thrust, [6, 9])
    np.testing.assert_allclose(s.wind_force, [0, -2.5])
    assert s.wind_speed == 5.0
    assert lander_scene(info, params={"wind_enabled": False}).wind_speed == 0.0
    assert lander_scene(info).platform_vx == 0.0
