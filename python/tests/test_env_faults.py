"""Faults in the gym (issue 35): `faults=[...]` and `fault_randomization={...}` in both
backends, single and vector; `info["faults"]` lists the active ones; the same seed and
schedule fly the same bits through the SITL and in-process; bad faults name the field."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest

from flyloop import SitlParameterError
from flyloop.faults import catalogue, plan_text

WEAK_MOTOR = [{"kind": "motor_effectiveness", "motor": 2, "effectiveness": 0.5, "at": 0.2}]
GUST = {"kind": "gust", "north": 3.0, "rise_time": 0.3, "above_height": 1.0, "duration": 2.0}
DRAW = {"kinds": ["motor_effectiveness"], "at": (0.0, 0.5), "effectiveness": (0.5, 1.0)}
HOVER = np.full(4, 0.5, np.float32)


def fly(env, seed, steps):
    obs, info = env.reset(seed=seed)
    trace, infos = [obs], [info]
    for _ in range(steps):
        obs, reward, terminated, truncated, info = env.step(HOVER)
        trace.append(obs)
        infos.append(info)
        if terminated or truncated:
            break
    return np.array(trace), infos


def test_a_weak_motor_fires_at_its_time_and_is_listed_in_the_info(make_env):
    env = make_env("flyloop/QuadHover-v0", backend="native", faults=WEAK_MOTOR, use_wind=False)
    healthy = make_env("flyloop/QuadHover-v0", backend="native", use_wind=False)
    trace, infos = fly(env, 4, 60)
    reference, _ = fly(healthy, 4, 60)
    # Before 0.2 s the vehicle is the healthy one, bit for bit; then it rolls away.
    assert np.array_equal(trace[:20], reference[:20])
    assert not np.array_equal(trace[-1], reference[-1])
    assert infos[19]["faults"] == []
    assert infos[-1]["faults"] == [{"fault": "motor_effectiveness:2", "time": pytest.approx(0.2)}]
    body_rates = slice(13, 16)
    assert np.abs(trace[-1][body_rates]).max() > 0.1


def test_same_seed_same_faults_native_and_sitl_bit_for_bit(make_env):
    kwargs = dict(faults=[GUST], fault_randomization=DRAW)
    sitl = make_env("flyloop/QuadHover-v0", **kwargs)
    native = make_env("flyloop/QuadHover-v0", backend="native", **kwargs)
    for seed in (11, 12):
        t1, i1 = fly(sitl, seed, 120)
        t2, i2 = fly(native, seed, 120)
        assert np.array_equal(t1, t2)
        for a, b in zip(i1, i2, strict=True):
            assert a["faults"] == b["faults"]
            assert np.array_equal(a["fault_time"], b["fault_time"])
        fired = {f["fault"] for f in i1[-1]["faults"]}
        assert "gust" in fired and any(f.startswith("motor_effectiveness:") for f in fired)
    # Another seed draws another fault (motor or time).
    _, a = fly(native, 11, 60)
    _, b = fly(native, 12, 60)
    assert a[-1]["faults"] != b[-1]["faults"]


def test_vector_envs_fly_the_same_faults_as_single_envs(make_env):
    kwargs = dict(fault_randomization=DRAW)
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
            envs.reset(seed=[31, 32, 33])
            for _ in range(60):
                obs, _, _, _, infos = envs.step(np.tile(HOVER, (3, 1)))
            for i, seed in enumerate((31, 32, 33)):
                trace, info = fly(single, seed, 60)
                assert np.array_equal(obs[i], trace[-1]), backend
                assert infos["faults"][i] == info[-1]["faults"], backend
        finally:
            envs.close()


@pytest.mark.parametrize(
    ("faults", "message"),
    [
        ([{"kind": "motor_loss"}], "`motor_loss` as a fault `kind`"),
        ([{"kind": "motor_off", "motor": 5}], "`motor` = 5 is out of range: it must be in [0, 4]"),
        (
            [{"kind": "motor_effectiveness", "effectiveness": 1.5}],
            "`effectiveness` = 1.5 is out of range: it must be in [0, 1]",
        ),
        ([{"kind": "sensor_off", "sensor": "sonar"}], "`sonar` as a fault's `sensor`"),
        ([{"kind": "motor_off", "at": 50.0}], "`at` = 50 s can never fire"),
        ([{"kind": "motor_off", "at_waypoint": 1}], "no waypoints"),
    ],
)
def test_bad_faults_are_refused_naming_the_field(sitl_binary, faults, message):
    for backend in ("native", "sitl"):
        with pytest.raises(SitlParameterError, match="faults") as err:
            gym.make("flyloop/QuadHover-v0", backend=backend, faults=faults)
        assert message in str(err.value), (backend, str(err.value))


def test_the_plan_is_the_toml_the_core_reads_and_the_catalogue_is_the_cores():
    text = plan_text([{"kind": "gust", "north": 2, "at": 1.5}], {"kinds": ["motor_off"]})
    assert text == (
        '[[faults]]\nkind = "gust"\nnorth = 2\nat = 1.5\n'
        '[[fault_randomization]]\nkinds = ["motor_off"]\n'
    )
    assert plan_text(None, []) is None
    kinds, sensors = catalogue()
    assert sensors == ("gyro", "accel", "mag", "baro", "gps")
    names = [k["name"] for k in kinds]
    assert names[0] == "motor_effectiveness" and "wind_shear" in names
    with pytest.raises(TypeError, match=r"faults\[0\]\['north'\]"):
        plan_text([{"kind": "gust", "north": {"x": 1}}], None)
    with pytest.raises(TypeError, match="faults"):
        plan_text("motor_off", None)
    # Link faults act on flyloop-sitl's links: the in-process backend has none.
    with pytest.raises(ValueError, match=r"faults\[1\]: kind 'link_loss' acts on a link"):
        plan_text([{"kind": "gust"}, {"kind": "link_loss", "duration": 1}], None)
