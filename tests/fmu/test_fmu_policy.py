"""HexaHoverPolicy.fmu (flyloop-fmu-pack policy policies/hexa_hover) against the policy the gym
flies in torch (evaluate.py's SavedRun), and in a closed loop with Hexacopter.fmu wired by name.

The episode: QuadHover-v0 on the hexa X as the policy was trained (hover_hexa_x: dt 0.02 s,
250 steps), started level without wind (start_attitude_range=0, use_wind=False) so that
Hexacopter.fmu's start values say the same start exactly (as test_fmu_gym_episode.py does).

Tolerances, and why: the observation, its normalisation (float64) and the action mapping
(float32) are the gym's operations in the gym's order, so they agree bit for bit; the network
is float32 in both, but tract sums the matrix products in another order (with FMA) and its
tanh is a rational approximation, not libm's: measured within 4.8e-7 of torch on every
command of the episode, asserted within 1e-5. In the closed loop those differences feed back
through the dynamics: measured 2.2e-6 m apart at most over 5 s, asserted within 1e-3 m.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from policy_episodes import Slave, hexa_episode

SEED = 2_000_003
COMMAND_TOLERANCE = 1e-5
POSITION_TOLERANCE_M = 1e-3


def hexa_hover_state() -> float:
    """The core's hover state of the default hexa X: sqrt(m·g / (6·k))."""
    return math.sqrt(1.0 * 9.81 / (6.0 * 10.0))


def plant_and_policy(fmus, policy_fmus, episode) -> tuple[Slave, Slave]:
    hover = hexa_hover_state()
    start_height = episode["positions"][0][2]
    plant = Slave(
        fmus["Hexacopter"],
        "plant",
        {"initial_motor": hover, "wind_enabled": False, "initial_z": start_height},
    )
    target = dict(zip(("target_x", "target_y", "target_z"), episode["target"], strict=True))
    policy = Slave(policy_fmus["HexaHoverPolicy"], "policy", {**target, "initial_motor": hover})
    return plant, policy


@pytest.fixture(scope="module")
def episode():
    return hexa_episode(SEED)


def test_the_policy_fmu_acts_as_torch_on_every_state_of_a_gym_episode(fmus, policy_fmus, episode):
    """Hexacopter.fmu replays the gym episode's commands (the same states bit for bit, as
    test_fmu_gym_episode.py shows); at each control step Policy.fmu reads the plant's outputs
    by name and its commands equal the torch policy's in the gym within 1e-5."""
    plant, policy = plant_and_policy(fmus, policy_fmus, episode)
    inputs, outputs = policy.names("input"), policy.names("output")
    assert set(inputs) <= set(plant.names("output")), "every policy input is a plant output"
    assert outputs == [f"motor_command_{i}" for i in range(6)]
    assert set(outputs) <= set(plant.names("input")), "every policy output is a plant input"
    dt, t = episode["dt"], 0.0
    got = []
    try:
        for command in episode["commands"]:
            policy.set(dict(zip(inputs, plant.get(inputs), strict=True)))
            got.append(policy.get(outputs))
            plant.set(dict(zip(outputs, command, strict=True)))
            plant.slave.doStep(t, dt)
            policy.slave.doStep(t, dt)
            t += dt
        final = np.array(plant.get(["x", "y", "z"]), np.float32)
    finally:
        plant.close()
        policy.close()
    assert np.array_equal(final, episode["positions"][-1].astype(np.float32)), "same states"
    error = np.abs(np.array(got) - episode["commands"]).max()
    print(f"largest |Policy.fmu - torch| over {len(got)} steps: {error:.3g}")
    assert error < COMMAND_TOLERANCE


def test_the_policy_fmu_and_the_plant_hold_the_target_as_the_gym_episode(
    fmus, policy_fmus, episode
):
    """Policy.fmu and Hexacopter.fmu in a closed loop (this test is the master; each policy
    input from the plant output of the same name, each plant input from the policy output
    of the same name) fly the gym's episode within 1 mm and end within 0.5 m of the target."""
    plant, policy = plant_and_policy(fmus, policy_fmus, episode)
    inputs, outputs = policy.names("input"), policy.names("output")
    dt, t = episode["dt"], 0.0
    positions = [plant.get(["x", "y", "z"])]
    try:
        for _ in episode["commands"]:
            policy.set(dict(zip(inputs, plant.get(inputs), strict=True)))
            plant.set(dict(zip(outputs, policy.get(outputs), strict=True)))
            plant.slave.doStep(t, dt)
            policy.slave.doStep(t, dt)
            t += dt
            positions.append(plant.get(["x", "y", "z"]))
    finally:
        plant.close()
        policy.close()
    positions = np.array(positions)
    deviation = np.abs(positions - episode["positions"]).max()
    distance = np.linalg.norm(positions[-1] - episode["target"])
    print(f"closed loop vs gym: {deviation:.3g} m apart at most; {distance:.3f} m from target")
    assert deviation < POSITION_TOLERANCE_M
    assert distance < 0.5
    # The policy flew somewhere: the target was not the start.
    assert np.linalg.norm(episode["target"] - episode["positions"][0]) > 1.0
