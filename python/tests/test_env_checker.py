"""gymnasium's and stable-baselines3's env checkers on every env and both wrappers, with
every warning turned into a failure (determinism, dtype and bounds warnings included)."""

from __future__ import annotations

import warnings

import gymnasium as gym
import pytest
from gymnasium.utils.env_checker import check_env as gym_check_env

from flyloop.envs import Lander2DEnv, Lander2DLandingEnv, QuadHoverEnv, QuadWaypointsEnv
from flyloop.wrappers import MotionPrimitiveActionWrapper, ThrustChangeController

MAKERS = {
    "QuadHover": lambda: QuadHoverEnv(),
    "QuadWaypoints": lambda: QuadWaypointsEnv(),
    "Lander2D": lambda: Lander2DEnv(),
    "Lander2D-moving": lambda: Lander2DEnv(moving_platform=True),
    "Lander2D-v1": lambda: Lander2DLandingEnv(),
    "Lander2D-v1-moving": lambda: Lander2DLandingEnv(moving_platform=True),
    "ThrustChangeController": lambda: ThrustChangeController(QuadHoverEnv()),
    "MotionPrimitive": lambda: MotionPrimitiveActionWrapper(QuadWaypointsEnv()),
}


@pytest.fixture
def built(sitl_binary):
    envs = []

    def build(name):
        env = MAKERS[name]()
        envs.append(env)
        return env

    yield build
    for env in envs:
        env.close()


@pytest.mark.parametrize("name", sorted(MAKERS))
def test_gymnasium_check_env_passes_without_a_warning(built, name):
    env = built(name)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        if env is not env.unwrapped:
            # Said of every wrapped env, whatever the wrapper does.
            warnings.filterwarnings("ignore", message=".*different from the unwrapped version")
        gym_check_env(env, skip_render_check=True)


@pytest.mark.parametrize("name", sorted(MAKERS))
def test_stable_baselines3_check_env_passes_without_a_warning(built, name):
    sb3_checker = pytest.importorskip("stable_baselines3.common.env_checker")
    env = built(name)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        # Advice, not a defect: the quadrotor's motor commands are [0, 1] as in the seed
        # (ThrustChangeController gives the symmetric [-1, 1] space SB3 prefers).
        warnings.filterwarnings("ignore", message="We recommend you to use a symmetric")
        sb3_checker.check_env(env, warn=True)


@pytest.mark.parametrize(
    "env_id", ["flyloop/QuadHover-v0", "flyloop/Lander2D-v0", "flyloop/Lander2D-v1"]
)
def test_the_made_env_passes_with_its_passive_checker_and_rendering(
    sitl_binary, env_id, monkeypatch
):
    # The checker also makes the env in each declared render mode, "human" too: with no
    # display here, SDL's off-screen driver is asked for (human mode refuses to fall back to
    # it unasked).
    monkeypatch.setenv("SDL_VIDEODRIVER", "offscreen")
    env = gym.make(env_id, render_mode="rgb_array")
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            gym_check_env(env.unwrapped)
    finally:
        env.close()
