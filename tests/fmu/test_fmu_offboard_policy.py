"""OffboardPolicy.fmu (flyloop-fmu-pack policy policies/px4_offboard_hover): the PX4 offboard
rates policy as an FMU, closed on Quadrotor.fmu (the Iris) through RateController.fmu, wired
by name, against the gym's `action_interface="rates"` episode of the same policy and seed.

The policy observes what PX4's estimator gives (the "rates-estimate" recipe: target - position
and velocity in the heading frame, the body's down axis, body rates FRD, the previous
setpoint); in an FMU system the estimate is the plant's true state, so the gym episode runs
without observation noise and randomisation, level, one target held (seed 1).

This test is the master, in the gym's order on RateController's 4 ms grid: the plant's outputs
into the policy and RateController, the policy's setpoint into RateController, its motor
commands into the plant, then all three step. Tolerances, and why: the observation, its
normalisation and the setpoint map are the gym's operations in its order (a plant state gives
the gym's observation bit for bit); the network is float32 in both, but tract sums the
products in another order (with FMA) and its tanh is a rational approximation. Fed the gym's
states, the FMU's setpoints are torch's within 1.7e-6 (asserted 1e-5; the first tick's are
equal bit for bit). In the closed loop
those differences feed back: the policy is a stiff one (it starts with thrust 0 and rates of
2.4 rad/s), the trajectories part by 5e-8 m in the first 0.2 s and by 8.8e-5 m at
most over the 5 s (asserted 5e-4 m).
"""

from __future__ import annotations

import numpy as np
import pytest
from fmpy.validation import validate_fmu
from policy_episodes import Slave, offboard_episode
from test_fmu_validate import test_fmutool_check_finds_the_fmu_compliant as fmutool_check

SEED = 1
STEP = 0.004  # RateController's grid, s
SETPOINT = ["thrust", "roll_rate", "pitch_rate", "yaw_rate"]
SETPOINT_TOLERANCE = 1e-5
POSITION_TOLERANCE_M = 5e-4
IRIS = {
    "mass": 1.5,
    "arm_length": 0.25,
    "inertia_xx": 0.029125,
    "inertia_yy": 0.029125,
    "inertia_zz": 0.055225,
    "thrust_coefficient": 10.0,
    "motor_time_constant": 0.02,
    "yaw_torque_coefficient": 0.06,
    "drag_area": 0.05,
    "angular_damping_linear": 0.02,
    "angular_damping_quadratic": 0.0,
    "gear_x": 0.177,
    "gear_y": 0.177,
    "gear_z": -0.055,
}
IRIS_HOVER = (1.5 * 9.81 / 40.0) ** 0.5


@pytest.fixture(scope="module")
def episode():
    return offboard_episode(SEED)


@pytest.mark.parametrize("name", ["OffboardPolicy", "OffboardPolicy-fmi3"])
def test_fmutool_finds_the_offboard_policy_compliant(policy_fmus, name):
    fmutool_check(policy_fmus, name)


def test_the_offboard_policy_validates_and_connects_by_name(fmus, policy_fmus):
    for name in ("OffboardPolicy", "OffboardPolicy-fmi3"):
        assert validate_fmu(str(policy_fmus[name])) == [], name
    policy = Slave(policy_fmus["OffboardPolicy"], "policy", {})
    plant = Slave(fmus["Quadrotor"], "plant", {})
    rates = Slave(fmus["RateController"], "rates", {})
    try:
        inputs = policy.names("input")
        assert inputs == "x y z vx vy vz qw qx qy qz wx wy wz".split()
        assert set(inputs) <= set(plant.names("output")), "every input is a plant output"
        assert policy.names("output") == SETPOINT
        assert set(SETPOINT) <= set(rates.names("input")), "every output a setpoint input"
    finally:
        for fmu in (policy, plant, rates):
            fmu.close()


def fly(fmus, policy_fmus, episode, replay: bool) -> dict[str, np.ndarray]:
    """The three FMUs in the gym's order for the episode's length: the policy's setpoints at
    its ticks and the plant's positions every control step. With `replay` RateController
    gets the gym's setpoints (the policy only observes), so the plant flies the gym's states."""
    start_z = episode["positions"][0][2]
    assert episode["positions"][0][:2].tolist() == [0.0, 0.0]
    plant = Slave(
        fmus["Quadrotor"],
        "plant",
        {**IRIS, "initial_motor": IRIS_HOVER, "wind_enabled": False, "initial_z": start_z},
    )
    rates = Slave(fmus["RateController"], "rates", {})
    target = dict(zip(("target_x", "target_y", "target_z"), episode["target"], strict=True))
    policy = Slave(policy_fmus["OffboardPolicy"], "policy", {**target, "initial_motor": IRIS_HOVER})
    inputs, gyro = policy.names("input"), ["wx", "wy", "wz"]
    motors = [f"motor_command_{i}" for i in range(4)]
    per_tick = round(episode["dt"] / STEP)
    setpoints, positions = [], [plant.get(["x", "y", "z"])]
    try:
        for k in range(len(episode["commands"]) * per_tick):
            policy.set(dict(zip(inputs, plant.get(inputs), strict=True)))
            if k % per_tick == 0:
                setpoints.append(policy.get(SETPOINT))
            setpoint = list(episode["commands"][k // per_tick]) if replay else setpoints[-1]
            rates.set(dict(zip(SETPOINT + gyro, setpoint + plant.get(gyro), strict=True)))
            plant.set(dict(zip(motors, rates.get(motors), strict=True)))
            for fmu in (plant, rates, policy):
                fmu.slave.doStep(k * STEP, STEP)
            if (k + 1) % per_tick == 0:
                positions.append(plant.get(["x", "y", "z"]))
    finally:
        for fmu in (policy, plant, rates):
            fmu.close()
    return dict(setpoints=np.array(setpoints), positions=np.array(positions))


def test_the_offboard_policy_fmu_acts_as_torch_on_every_state_of_a_gym_episode(
    fmus, policy_fmus, episode
):
    """RateController.fmu and Quadrotor.fmu replay the gym's setpoints (the same states as
    the gym's rates interface); at every tick the policy, reading the plant's outputs by
    name, gives torch's setpoint within 1e-5."""
    run = fly(fmus, policy_fmus, episode, replay=True)
    final = run["positions"][-1].astype(np.float32)
    assert np.array_equal(final, episode["positions"][-1].astype(np.float32)), "same states"
    error = np.abs(run["setpoints"] - episode["commands"]).max()
    print(f"largest |OffboardPolicy.fmu - torch| over {len(run['setpoints'])} ticks: {error:.3g}")
    assert error < SETPOINT_TOLERANCE


def test_the_offboard_policy_flies_the_gym_episode_through_the_rate_controller(
    fmus, policy_fmus, episode
):
    """The closed loop: the policy's setpoints into RateController, its commands into the
    plant. It flies the gym's episode within 5e-4 m and ends near the target."""
    run = fly(fmus, policy_fmus, episode, replay=False)
    deviation = np.abs(run["positions"] - episode["positions"]).max()
    distance = np.linalg.norm(run["positions"][-1] - episode["target"])
    print(f"closed loop vs gym: {deviation:.3g} m apart at most; {distance:.3f} m from target")
    assert deviation < POSITION_TOLERANCE_M
    assert distance < 0.15
    assert np.linalg.norm(episode["target"] - episode["positions"][0]) > 1.0, "it flew"
