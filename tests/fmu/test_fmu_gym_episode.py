"""A hexa episode is the same in every front end (issue 33): QuadHover-v0 with frame="hexa_x"
on the native backend, the same episode over the MAVLink SITL, and Hexacopter.fmu in fmpy
fed the episode's motor commands give the same positions, bit for bit (as float32: the envs'
info["position"] is the core's position rounded to float32, as in the observation).

The episode starts level at rest at the task's start height with the motors at the hexa's
hover state and no wind (start_attitude_range=0, use_wind=False), which Hexacopter.fmu's
start values can say exactly; the commands are seeded random values around the hover."""

import math

import flyloop  # noqa: F401  (registers the ids)
import gymnasium as gym
import numpy as np
from fmpy import simulate_fmu

STEPS = 300
DT = 0.01  # the task's control step, s
KWARGS = dict(frame="hexa_x", start_attitude_range=0.0, use_wind=False, max_steps=STEPS)


def hexa_hover_state() -> float:
    """The core's hover_motor_state for the default hexa X, in its operation order:
    sqrt(m·g / (6·k))."""
    return math.sqrt(1.0 * 9.81 / (6.0 * 10.0))


def episode(backend: str, commands: np.ndarray) -> np.ndarray:
    env = gym.make("flyloop/QuadHover-v0", backend=backend, **KWARGS)
    try:
        _, info = env.reset(seed=11)
        positions = [info["position"]]
        for command in commands:
            _, _, terminated, truncated, info = env.step(command)
            positions.append(info["position"])
            assert not terminated, "the episode must stay airborne"
        dt = env.unwrapped.dt
    finally:
        env.close()
    assert dt == DT
    return np.array(positions, dtype=np.float64)


def test_a_hexa_episode_is_the_same_in_the_gym_the_sitl_and_the_fmu(fmus):
    hover = hexa_hover_state()
    rng = np.random.default_rng(5)
    commands = (hover + rng.uniform(-0.03, 0.03, (STEPS, 6))).astype(np.float32)
    native = episode("native", commands)
    sitl = episode("sitl", commands)
    assert np.array_equal(native.view(np.uint64), sitl.view(np.uint64))
    # The FMU: command k from t = k·dt on (a repeated time switches the input there).
    names = [f"motor_command_{i}" for i in range(6)]
    rows = []
    for k, command in enumerate(commands.astype(np.float64)):
        rows += [(k * DT, *command), ((k + 1) * DT, *command)]
    table = np.array(rows, dtype=[("time", np.float64)] + [(n, np.float64) for n in names])
    start_height = native[0][2]
    result = simulate_fmu(
        str(fmus["Hexacopter"]),
        stop_time=STEPS * DT,
        output_interval=DT,
        start_values={"initial_motor": hover, "wind_enabled": False, "initial_z": start_height},
        input=table,
        output=["x", "y", "z"],
    )
    # info["position"] carries the core's f64 rounded to float32, as the observation does.
    fmu = np.stack([result["x"], result["y"], result["z"]], axis=1).astype(np.float32)
    assert fmu.shape == native.shape
    assert np.array_equal(native.astype(np.float32), native)
    differing = np.flatnonzero((fmu != native).any(axis=1))
    assert differing.size == 0, (
        f"first differing step {differing[0]}: fmu {fmu[differing[0]]}, gym {native[differing[0]]}"
    )
    # The commands moved the vehicle (the comparison is not of a vehicle at rest).
    assert np.abs(native[-1] - native[0]).max() > 0.1
