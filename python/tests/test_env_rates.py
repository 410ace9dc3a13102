"""The rates interface (thrust + body rates through the core's model of PX4's rate loop) and
domain randomisation in the gym envs: gymnasium's checker on each, the same episodes and the
same randomised vehicles bit for bit in both backends, single and vector, and bad ranges
refused naming what is wrong."""

from __future__ import annotations

import math
import warnings

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import flyloop  # noqa: F401
from flyloop import SitlParameterError

RATES = dict(action_interface="rates", dt=0.02, max_steps=200)
RANDOMIZE = {"mass": (1.2, 1.8), "thrust_coefficient": (9.0, 11.0), "roll_rate_p": (0.1, 0.2)}
NOISE = {"position": 0.02, "rates": 0.01}


@pytest.mark.parametrize("env_id", ["flyloop/QuadHover-v0", "flyloop/QuadWaypoints-v0"])
@pytest.mark.parametrize("backend", ["sitl", "native"])
def test_check_env_passes_on_the_rates_interface_with_randomisation(make_env, env_id, backend):
    env = make_env(env_id, backend=backend, randomize=RANDOMIZE, observation_noise=NOISE, **RATES)
    max_rate = math.radians(220)
    assert env.action_space.shape == (4,)
    assert np.allclose(env.action_space.low, [0, -max_rate, -max_rate, -math.radians(200)])
    expected = 16 if env_id.endswith("Hover-v0") else 20
    assert env.observation_space.shape == (expected,)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        # Advice, not a defect: the action is in PX4's units (rad/s), as offboard takes it.
        warnings.filterwarnings("ignore", message=".*symmetric and normalized space")
        check_env(env.unwrapped, skip_render_check=True)


def test_same_seed_same_randomised_vehicle_in_both_backends_bit_for_bit(make_env):
    kwargs = dict(randomize=RANDOMIZE, observation_noise=NOISE, action_latency=0.008, **RATES)
    sitl = make_env("flyloop/QuadHover-v0", **kwargs)
    native = make_env("flyloop/QuadHover-v0", backend="native", **kwargs)
    rng = np.random.default_rng(3)
    for seed in (5, 6, 5):
        o1, i1 = sitl.reset(seed=seed)
        o2, i2 = native.reset(seed=seed)
        assert np.array_equal(o1, o2)
        assert np.array_equal(i1["randomized"], i2["randomized"])
        drawn = i1["randomized"]
        assert drawn.shape == (3,)
        for value, (low, high) in zip(drawn, RANDOMIZE.values(), strict=True):
            assert low <= value <= high
        for _ in range(100):
            a = np.array([0.6, 0, 0, 0]) + rng.normal(0, [0.05, 0.3, 0.3, 0.1])
            a = a.astype(np.float32)
            o1, r1, t1, u1, i1 = sitl.step(a)
            o2, r2, t2, u2, i2 = native.step(a)
            assert np.array_equal(o1, o2)
            assert np.float32(r1) == np.float32(r2) and (t1, u1) == (t2, u2)
            if t1 or u1:
                break
    # Another seed flies another vehicle.
    _, a = native.reset(seed=7)
    _, b = native.reset(seed=8)
    assert not np.array_equal(a["randomized"], b["randomized"])


def test_vector_envs_fly_the_same_randomised_vehicles_as_single_envs(make_env):
    kwargs = dict(randomize=RANDOMIZE, **RATES)
    single = make_env("flyloop/QuadHover-v0", backend="native", **kwargs)
    for backend in ("native", "sitl"):
        envs = gym.make_vec(
            "flyloop/QuadHover-v0",
            num_envs=3,
            vectorization_mode="vector_entry_point",
            backend=backend,
            **kwargs,
        )
        try:
            obs, infos = envs.reset(seed=[21, 22, 23])
            for i, seed in enumerate((21, 22, 23)):
                o, info = single.reset(seed=seed)
                assert np.array_equal(obs[i], o), backend
                assert np.allclose(infos["randomized"][i], info["randomized"]), backend
        finally:
            envs.close()


@pytest.mark.parametrize(
    ("randomize", "message"),
    [
        ({"mass": (-1.0, 1.0)}, "`mass` = [-1, 1] kg must be ordered (low <= high) and inside"),
        ({"inertia_xx": (1.0, 2e4)}, "inside [1e-7, 10000] kg.m2"),
        ({"masss": (1.0, 2.0)}, "unknown parameter `masss`"),
        ({"ground_enabled": (0.0, 1.0)}, "only real parameters can be randomised"),
    ],
)
def test_a_bad_range_is_refused_naming_it(sitl_binary, randomize, message):
    for backend in ("native", "sitl"):
        with pytest.raises(SitlParameterError, match="randomize") as err:
            gym.make("flyloop/QuadHover-v0", backend=backend, randomize=randomize)
        assert message in str(err.value), str(err.value)


def test_wrong_types_and_unordered_ranges_are_refused(sitl_binary):
    with pytest.raises(ValueError, match=r"randomize\['mass'\] = \(2.0, 1.0\): min must not"):
        gym.make("flyloop/QuadHover-v0", backend="native", randomize={"mass": (2.0, 1.0)})
    with pytest.raises(TypeError, match="randomize"):
        gym.make("flyloop/QuadHover-v0", backend="native", randomize=[("mass", 1, 2)])
    with pytest.raises(TypeError, match=r"randomize\['mass'\]"):
        gym.make("flyloop/QuadHover-v0", backend="native", randomize={"mass": 1.0})
    with pytest.raises(ValueError, match="action_interface"):
        gym.make("flyloop/QuadHover-v0", backend="native", action_interface="torques")
    with pytest.raises(ValueError, match="observation_noise"):
        gym.make("flyloop/QuadHover-v0", backend="native", observation_noise={"gps": 1.0})


def test_a_roll_rate_command_rolls_the_vehicle_right_side_down(make_env):
    """FRD roll rate > 0: the right side goes down, the body rates the env reports (FRD)
    follow the command, and the vehicle drifts to its right (east when facing north)."""
    env = make_env(
        "flyloop/QuadHover-v0", backend="native", start_attitude_range=0.0, use_wind=False, **RATES
    )
    obs, _ = env.reset(seed=1)
    hover = math.sqrt(9.81 / 40.0)  # the default 1 kg vehicle
    for _ in range(10):
        obs, *_ = env.step(np.array([hover, 0.5, 0.0, 0.0], np.float32))
    assert abs(obs[9] - 0.5) < 0.1, obs[9:12]
    # Right side down: the thrust (body up) leans right, the body's down axis left (−y in the
    # heading frame).
    assert obs[7] < -0.02, obs[6:9]
