"""The shipped policies' gym episodes (torch, as the gym flies them) and an fmpy instance with
its variables by name: what tests/fmu compares Policy.fmu systems with.

Both episodes start level without wind, so that the plant FMU's start values say the same
start exactly: policies/hexa_hover on QuadHover-v0's hexa X (motor interface), and
policies/px4_offboard_hover on the nominal Iris through the core's PX4 rate loop (rates
interface; no randomisation and no observation noise: in an FMU system the estimate is the
plant's true state).
"""

from __future__ import annotations

import sys
from pathlib import Path

import flyloop  # noqa: F401  (registers the ids)
import numpy as np
from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave

ROOT = Path(__file__).resolve().parents[2]
POLICIES = ROOT / "policies"
sys.path.insert(0, str(ROOT / "examples" / "train"))


def hexa_episode(seed: int) -> dict[str, np.ndarray]:
    """policies/hexa_hover in the gym (evaluate.py's SavedRun): commands, positions, target."""
    import torch
    from evaluate import SavedRun
    from training_envs import make_env

    torch.set_num_threads(1)
    run = SavedRun(POLICIES / "hexa_hover")
    overrides = dict(start_attitude_range=0.0, use_wind=False)
    env = make_env(run.preset.name, action="motors", overrides=overrides)
    # What the env receives: RescaleAction's float32 map of the clipped action.
    return _fly(env, seed, lambda obs: run.act(obs).astype(np.float32), env.action)


def offboard_episode(seed: int, steps: int = 250) -> dict[str, np.ndarray]:
    """policies/px4_offboard_hover in the gym as train_offboard.py evaluates it (the actor's
    mean on the normalised observation, fast_ppo.py's to_env): setpoints, positions, target."""
    import fast_ppo
    import torch
    from training_envs import make_env

    torch.set_num_threads(1)
    saved = torch.load(POLICIES / "px4_offboard_hover" / "policy.pt", weights_only=False)
    size, actions = saved["model"]["mu.0.weight"].shape[1], saved["model"]["log_std"].shape[0]
    model = fast_ppo.ActorCritic(size, actions, hidden=64)
    model.load_state_dict(saved["model"])
    model.eval()
    norm = fast_ppo.RunningNorm(size)
    norm.mean, norm.var = saved["obs_mean"], saved["obs_var"]
    overrides = dict(
        randomize=None,
        observation_noise=None,
        start_attitude_range=0.0,
        target_change_interval=None,
        max_steps=steps,
    )
    env = make_env("offboard", overrides=overrides)

    def act(obs):
        with torch.no_grad():
            return model.mu(torch.as_tensor(norm(obs[None, :])))[0].numpy()

    return _fly(env, seed, lambda obs: fast_ppo.to_env(act(obs), env.action_space), np.asarray)


def _fly(env, seed: int, policy, received) -> dict[str, np.ndarray]:
    """One episode to its time limit, stepping `env` with policy(obs): what the vehicle
    received each step (`received(action)`), the positions."""
    commands, positions = [], []
    try:
        obs, info = env.reset(seed=seed)
        target = np.array(info["target_position"], np.float64)
        positions.append(info["position"])
        done = False
        while not done:
            action = policy(obs)
            commands.append(received(action))
            obs, _, terminated, truncated, info = env.step(action)
            positions.append(info["position"])
            done = terminated or truncated
        assert truncated and not terminated, "the policy holds the episode to its end"
        dt = env.unwrapped.dt
    finally:
        env.close()
    return dict(
        commands=np.array(commands, np.float64),
        positions=np.array(positions, np.float64),
        target=target,
        dt=dt,
    )


class Slave:
    """An fmpy Co-Simulation instance with its variables by name."""

    def __init__(self, fmu: Path, name: str, start: dict[str, float]):
        self.md = read_model_description(str(fmu))
        self.slave = FMU2Slave(
            guid=self.md.guid,
            unzipDirectory=extract(str(fmu)),
            modelIdentifier=self.md.coSimulation.modelIdentifier,
            instanceName=name,
        )
        self.vr = {v.name: v.valueReference for v in self.md.modelVariables}
        self.type = {v.name: v.type for v in self.md.modelVariables}
        self.slave.instantiate()
        self.slave.setupExperiment(startTime=0.0)
        self.set(start)
        self.slave.enterInitializationMode()
        self.slave.exitInitializationMode()

    def names(self, causality: str) -> list[str]:
        return [v.name for v in self.md.modelVariables if v.causality == causality]

    def get(self, names: list[str]) -> list[float]:
        return self.slave.getReal([self.vr[n] for n in names])

    def set(self, values: dict[str, float]) -> None:
        flags = {n: v for n, v in values.items() if self.type[n] == "Boolean"}
        reals = {n: v for n, v in values.items() if n not in flags}
        self.slave.setReal([self.vr[n] for n in reals], list(reals.values()))
        if flags:
            self.slave.setBoolean([self.vr[n] for n in flags], [bool(v) for v in flags.values()])

    def close(self) -> None:
        self.slave.terminate()
        self.slave.freeInstance()
