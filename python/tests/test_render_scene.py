"""The scenes of flyloop.rendering (no pygame)."""

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import flyloop
from flyloop.rendering import LanderScene, QuadScene


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
