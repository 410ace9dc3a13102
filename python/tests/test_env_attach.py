"""An env attached to a SITL someone else runs (sitl_address): parameters over MAVLink,
task checks, and the SITL left running on close()."""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap

import numpy as np
import pytest

from flyloop import SitlError, SitlParameterError
from flyloop.envs import Lander2DEnv, QuadHoverEnv
from flyloop.sitl_process import SitlProcess


@pytest.fixture
def hover_sitl(sitl_binary):
    sitl = SitlProcess(sitl_binary, ["--task", "hover", "--gcs", "off", "--vehicles", "2"])
    yield sitl
    sitl.stop()


def test_an_attached_env_sets_its_arguments_over_mavlink_and_flies(hover_sitl, make_env):
    host, port = hover_sitl.address
    env = make_env(
        QuadHoverEnv, sitl_address=f"{host}:{port}", vehicle=2, max_steps=5, use_wind=False
    )
    obs, info = env.reset(seed=3)
    assert (obs[22:25] == 0).all(), "use_wind=False reached the vehicle"
    for _ in range(5):
        obs, _, _, truncated, info = env.step(np.full(4, 0.5, np.float32))
    assert truncated and info["step_count"] == 5, "max_steps=5 reached the vehicle"
    # The same seed gives the same episode as an env with its own SITL.
    own = make_env(QuadHoverEnv, max_steps=5, use_wind=False)
    np.testing.assert_array_equal(own.reset(seed=3)[0], env.reset(seed=3)[0])
    env.close()
    assert hover_sitl.running, "close() leaves a SITL it did not start running"


def test_an_attached_env_refuses_values_the_core_refuses(hover_sitl):
    with pytest.raises(SitlParameterError, match=r"crash_tilt_threshold.*out of range"):
        QuadHoverEnv(sitl_address=hover_sitl.address, crash_tilt_threshold=500.0)


def test_attaching_to_a_sitl_of_another_task_is_a_clear_error(hover_sitl):
    with pytest.raises(SitlError, match="flies task 'hover' on vehicle 1; .* --task landing"):
        Lander2DEnv(sitl_address=hover_sitl.address)


def test_nobody_listening_at_the_address_is_a_sitl_error(sitl_binary):
    import socket

    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        s.bind(("127.0.0.1", 0))
        free = s.getsockname()
    with pytest.raises(SitlError, match="127.0.0.1"):
        QuadHoverEnv(sitl_address=free, timeout=0.5)


def test_human_mode_renders_every_step_through_the_view(sitl_binary):
    script = textwrap.dedent(
        """
        import numpy as np
        from flyloop.envs import Lander2DEnv
        env = Lander2DEnv(render_mode="human")
        frames = []
        real = env._view.render
        env._view.render = lambda scene: frames.append(scene.step) or real(scene)
        env.reset(seed=0)
        for _ in range(3):
            env.step(np.zeros(2, np.float32))
        assert env.render() is None
        env.close()
        print(frames)
        """
    )
    environ = {**os.environ, "SDL_VIDEODRIVER": "dummy"}
    out = subprocess.run(
        [sys.executable, "-c", script], capture_output=True, text=True, timeout=60, env=environ
    )
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == "[0, 1, 2, 3, 3]"
