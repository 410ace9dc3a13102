"""frame=: QuadHover and QuadWaypoints on every rotor table the core ships. The motor
interface takes one command per rotor and observes every motor, the rates interface keeps its
four values; the native backend equals the SITL backend bit for bit on the hexa (single and
vector envs, randomised too), the SB3 VecEnv over the native batch equals SB3's DummyVecEnv,
gymnasium's check_env passes, and bad frames and actions get errors that say what is wanted."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import flyloop
import flyloop.sb3
from flyloop import _native
from flyloop.tasks import observation_slices

FRAMES = {"quad_x": 4, "quad_plus": 4, "hexa_x": 6, "octo_x": 8}
FLIGHT_IDS = ("flyloop/QuadHover-v0", "flyloop/QuadWaypoints-v0")
SHORT = {"max_steps": 150}
# The mass and motor lag drawn per episode: randomisation goes on working on any frame.
RANDOMIZE = {"mass": (0.8, 1.3), "motor_time_constant": (0.05, 0.1)}


def random_actions(space: gym.spaces.Box, shape: tuple, seed: int) -> np.ndarray:
    """Actions over and beyond the bounds, so the clamping is exercised too."""
    rng = np.random.default_rng(seed)
    lo, hi = space.low.astype(np.float64), space.high.astype(np.float64)
    span = hi - lo
    return (lo - 0.1 * span + 1.2 * span * rng.random((*shape, *space.shape))).astype(np.float32)


def test_the_frames_are_the_cores_and_size_the_motor_interface():
    assert set(_native.frames()) == set(FRAMES)
    for env_id in FLIGHT_IDS:
        for frame, rotors in FRAMES.items():
            env = gym.make(env_id, frame=frame, backend="native")
            core = env.unwrapped.core
            assert core["frame"] == frame and core["rotors"] == rotors
            assert env.action_space.shape == (rotors,)
            assert np.all(env.action_space.low == 0) and np.all(env.action_space.high == 1)
            at = observation_slices(core)
            assert at["motor_states"] == slice(25, 25 + rotors)
            assert at["motor_commands"] == slice(25 + rotors, 25 + 2 * rotors)
            extra = 4 if "Waypoints" in env_id else 0
            assert env.observation_space.shape == (25 + 2 * rotors + extra,)
            rates = gym.make(env_id, frame=frame, action_interface="rates", backend="native")
            assert rates.action_space.shape == (4,) and rates.observation_space.shape[0] == (
                16 + extra
            )
            env.close()
            rates.close()


@pytest.mark.parametrize(
    ("env_id", "kwargs"),
    [
        ("flyloop/QuadHover-v0", {}),
        ("flyloop/QuadWaypoints-v0", {}),
        ("flyloop/QuadHover-v0", {"action_interface": "rates"}),
        ("flyloop/QuadHover-v0", {"randomize": RANDOMIZE}),
    ],
    ids=["hover", "waypoints", "rates", "randomized"],
)
def test_a_hexa_on_the_native_backend_equals_the_sitl_bit_for_bit(make_env, env_id, kwargs):
    sitl = make_env(env_id, frame="hexa_x", **SHORT, **kwargs)
    native = make_env(env_id, frame="hexa_x", backend="native", **SHORT, **kwargs)
    assert sitl.unwrapped.sitl_process is not None
    assert native.observation_space == sitl.observation_space
    assert native.action_space == sitl.action_space
    steps, resets = 1500, 0
    actions = random_actions(native.action_space, (steps,), 5)
    o1, i1 = sitl.reset(seed=21)
    o2, i2 = native.reset(seed=21)
    for t in range(steps):
        assert np.array_equal(o1.view(np.uint32), o2.view(np.uint32)), f"step {t}"
        o1, r1, te1, tr1, i1 = sitl.step(actions[t])
        o2, r2, te2, tr2, i2 = native.step(actions[t])
        assert np.float32(r2) == np.float32(r1) and (te1, tr1) == (te2, tr2), f"step {t}"
        assert np.array_equal(i1["position"], i2["position"]), f"step {t}"
        if te1 or tr1:
            resets += 1
            o1, i1 = sitl.reset()
            o2, i2 = native.reset()
    assert resets >= 5


def test_a_hexa_vector_env_equals_the_sitl_vector_env_and_the_sb3_vecenv_dummy(sitl_binary):
    n, steps = 4, 300
    kwargs = {"frame": "hexa_x", "max_steps": 60, "randomize": RANDOMIZE}
    make = dict(num_envs=n, vectorization_mode="vector_entry_point")
    sitl = gym.make_vec("flyloop/QuadHover-v0", **make, **kwargs)
    native = gym.make_vec("flyloop/QuadHover-v0", **make, backend="native", **kwargs)
    try:
        assert native.single_action_space.shape == (6,)
        o1, _ = sitl.reset(seed=3)
        o2, _ = native.reset(seed=3)
        for t, a in enumerate(random_actions(native.single_action_space, (steps, n), 8)):
            assert np.array_equal(o1.view(np.uint32), o2.view(np.uint32)), f"step {t}"
            o1, r1, te1, tr1, _ = sitl.step(a)
            o2, r2, te2, tr2, _ = native.step(a)
            assert np.array_equal(r1.astype(np.float32), r2.astype(np.float32)), f"step {t}"
            assert np.array_equal(te1, te2) and np.array_equal(tr1, tr2), f"step {t}"
    finally:
        sitl.close()
        native.close()

    ours = flyloop.sb3.make_vec_env("flyloop/QuadHover-v0", n, unit_actions=True, **kwargs)
    ref = flyloop.sb3.dummy_vec_env("flyloop/QuadHover-v0", n, unit_actions=True, **kwargs)
    try:
        assert ours.action_space.shape == ref.action_space.shape == (6,)
        ours.seed(17), ref.seed(17)
        o1, o2 = ours.reset(), ref.reset()
        ends = 0
        for t, a in enumerate(random_actions(ours.action_space, (steps, n), 4)):
            assert np.array_equal(o1.view(np.uint32), o2.view(np.uint32)), f"step {t}"
            o1, r1, d1, _ = ours.step(a)
            o2, r2, d2, _ = ref.step(a)
            assert np.array_equal(r1, r2) and np.array_equal(d1, d2), f"step {t}"
            ends += int(d1.sum())
        assert ends >= n
    finally:
        ours.close()
        ref.close()


@pytest.mark.parametrize("backend", ["native", "sitl"])
def test_gymnasiums_check_env_passes_on_a_hexa(make_env, backend):
    env = make_env("flyloop/QuadHover-v0", frame="hexa_x", backend=backend)
    check_env(env.unwrapped, skip_render_check=True)


def test_bad_frames_and_wrong_length_actions_say_what_is_wanted(make_env):
    names = r"\['quad_x', 'quad_plus', 'hexa_x', 'octo_x'\]"
    with pytest.raises(ValueError, match=rf"frame must be one of {names}, got 'tri'"):
        gym.make("flyloop/QuadHover-v0", frame="tri", backend="native")
    with pytest.raises(TypeError, match=rf"frame must be a frame name, one of {names}, got 6"):
        gym.make("flyloop/QuadWaypoints-v0", frame=6)
    with pytest.raises(ValueError, match="one of"):
        gym.make_vec("flyloop/QuadHover-v0", num_envs=2, frame="hexa", backend="native")
    with pytest.raises(TypeError, match="frame"):
        gym.make("flyloop/Lander2D-v1", frame="hexa_x", backend="native")
    for backend in ("native", "sitl"):
        env = make_env("flyloop/QuadHover-v0", frame="hexa_x", backend=backend)
        env.reset(seed=1)
        with pytest.raises(ValueError, match=r"shape \(6,\), got \(4,\)"):
            env.step(np.full(4, 0.5, np.float32))
        env.step(np.full(6, 0.5, np.float32))
    envs = gym.make_vec(
        "flyloop/QuadHover-v0",
        num_envs=3,
        vectorization_mode="vector_entry_point",
        frame="octo_x",
        backend="native",
    )
    envs.reset(seed=0)
    with pytest.raises(ValueError, match=r"shape \(3, 8\)"):
        envs.step(np.zeros((3, 6), np.float32))
    envs.close()
    venv = flyloop.sb3.make_vec_env("flyloop/QuadHover-v0", 2, frame="hexa_x")
    venv.reset()
    with pytest.raises(ValueError, match=r"shape \(2, 6\), got \(2, 4\)"):
        venv.step(np.zeros((2, 4), np.float32))
    venv.close()


def test_a_hexa_renders_its_six_rotors_from_the_cores_table():
    from flyloop.rendering.quadrotor import frame_rotors

    hexa = frame_rotors("hexa_x")
    # PX4's 6001 order: right, left, front-left, rear-right, front-right, rear-left.
    assert hexa.names == ("R", "L", "FL", "RR", "FR", "RL")
    assert hexa.spins == ("CW", "CCW", "CW", "CCW", "CCW", "CW")
    assert len(frame_rotors("octo_x").names) == 8
    assert frame_rotors("quad_x").names == ("FR", "RL", "FL", "RR")
    env = gym.make(
        "flyloop/QuadHover-v0", frame="hexa_x", backend="native", render_mode="rgb_array"
    )
    env.reset(seed=1)
    env.step(np.full(6, 0.45, np.float32))
    assert env.render().shape == (720, 960, 3)
    env.close()
