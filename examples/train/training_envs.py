"""The envs as the training and evaluation scripts make them: one preset per task, with the
action wrapper, the env arguments and what counts as a success.

QuadHover is trained on the raw motor commands, rescaled from [0, 1]⁴ to [-1, 1]⁴ so that the
zero action, where a fresh Gaussian policy starts, is every motor at 0.5 (hover is 0.495),
at a 20 ms control period (dt=0.02, 250 steps = 5 s per episode). Measured on this machine
(PPO, seed 0, mean training return after ~100k env steps; see the issue-8 report): raw motors
at dt=0.02 learned fastest (114 of at most 250); MotionPrimitiveActionWrapper (rescaled the
same way) reached 50, and at dt=0.01 raw motors, motion primitives and
ThrustChangeController all learned slower per env step and per second. Lander2D's two
motors are already in [-1, 1].

The same presets serve stable-baselines3 (train_sb3.py), the evaluation (evaluate.py) and
RLlib (train_rllib.py), so a model is always evaluated on the env it was trained on.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import flyloop  # noqa: F401  (registers the envs)
import gymnasium as gym
import numpy as np
import tomllib
from flyloop.wrappers import MotionPrimitiveActionWrapper, ThrustChangeController

# A hover episode is a success when it ran to the time limit (no crash, not out of bounds)
# and ended within this distance of the target.
HOVER_SUCCESS_DISTANCE_M = 0.5


def hover_success(terminated: bool, truncated: bool, info: Mapping[str, Any]) -> bool:
    return (
        truncated
        and not terminated
        and float(info["distance_to_target"]) < HOVER_SUCCESS_DISTANCE_M
    )


# A Preset's success fields for the hover tasks (QuadHover-v0, whatever its actions).
HOVER_SUCCESS = {
    "success": hover_success,
    "success_text": (
        f"reached the time limit (no crash, not out of bounds) within "
        f"{HOVER_SUCCESS_DISTANCE_M} m of the target"
    ),
    "outcomes": (
        f"held the target (within {HOVER_SUCCESS_DISTANCE_M} m at the time limit)",
        "did not hold the target",
    ),
}


def swap_success(terminated: bool, truncated: bool, info: Mapping[str, Any]) -> bool:
    """Swap: every agent within its arrival radius at the end, no agent collided or crashed
    (the core's info['success'], the same for every agent of a world)."""
    return bool(info["success"])


def lander_success(terminated: bool, truncated: bool, info: Mapping[str, Any]) -> bool:
    return bool(info["landed"])


def unit_actions(env: gym.Env) -> gym.Env:
    """The env's Box actions rescaled to [-1, 1] (float32 bounds)."""
    unit = np.ones(env.action_space.shape, np.float32)
    return gym.wrappers.RescaleAction(env, -unit, unit)


def motion_primitives(env: gym.Env) -> gym.Env:
    """[hover, roll, pitch, yaw] in [-1, 1]⁴ (hover 0 = half throttle)."""
    return unit_actions(MotionPrimitiveActionWrapper(env))


# The quadrotor's action interfaces (train_sb3.py --action): what the policy outputs.
QUAD_ACTIONS: dict[str, Callable[[gym.Env], gym.Env]] = {
    "motors": unit_actions,
    "primitives": motion_primitives,
    "rates": ThrustChangeController,
}


class SuccessInfo(gym.Wrapper):
    """Sets info['is_success'] on the last step of an episode (stable-baselines3 logs its mean
    as rollout/success_rate)."""

    def __init__(self, env: gym.Env, success: Callable[[bool, bool, Mapping[str, Any]], bool]):
        super().__init__(env)
        self._success = success

    def step(self, action):
        obs, reward, terminated, truncated, info = self.env.step(action)
        if terminated or truncated:
            info = {**info, "is_success": bool(self._success(terminated, truncated, info))}
        return obs, reward, terminated, truncated, info


@dataclass(frozen=True)
class Preset:
    name: str
    env_id: str
    env_kwargs: Mapping[str, Any]
    # Action interfaces by name (the first is the default); None: the env's own actions.
    actions: Mapping[str, Callable[[gym.Env], gym.Env]] | None
    success: Callable[[bool, bool, Mapping[str, Any]], bool]
    success_text: str
    # How an episode ended, in the task's own words: (a success, anything else).
    outcomes: tuple[str, str] = ("landed", "did not land")

    @property
    def default_action(self) -> str | None:
        return next(iter(self.actions)) if self.actions else None

    def outcome(self, success: bool) -> str:
        return self.outcomes[0] if success else self.outcomes[1]


# The vehicles of flyloop-sitl --px4 (sitl/presets/). Read when a preset needs them: RLlib's
# env runners import this file from a copy of examples/train/ where sitl/ is not beside it.
PRESETS_DIR = Path(__file__).resolve().parents[2] / "sitl" / "presets"


def px4_vehicle(name: str = "px4_iris") -> dict[str, Any]:
    """A PX4-mode preset's quadrotor parameters (its wind switch is the env's use_wind)."""
    params = tomllib.loads((PRESETS_DIR / f"{name}.toml").read_text())
    params.pop("wind_enabled", None)
    return params


# Per-episode vehicles around the Iris, and PX4 in the loop's latency (train_offboard.py).
OFFBOARD_RANDOMIZE = {
    "mass": (1.2, 1.85),
    "inertia_xx": (0.023, 0.035),
    "inertia_yy": (0.023, 0.035),
    "inertia_zz": (0.044, 0.066),
    "thrust_coefficient": (8.5, 11.0),
    "yaw_torque_coefficient": (0.04, 0.08),
    "motor_time_constant": (0.015, 0.035),
    "drag_area": (0.02, 0.1),
    "roll_rate_p": (0.12, 0.18),
    "pitch_rate_p": (0.12, 0.18),
    "action_latency": (0.0, 0.04),
}

SWAP = Preset(
    name="swap",
    env_id="flyloop/Swap-v0",
    env_kwargs={"num_agents": 4, "max_steps": 250, "dt": 0.02},
    actions=None,
    success=swap_success,
    success_text="every agent within 0.5 m of the opposite point at the time limit, "
    "no collision or crash",
    outcomes=("all four swapped places", "the swap failed"),
)

PRESETS: dict[str, Preset] = {
    # Four agents exchange places through the middle of a 2 m circle (flyloop.parallel_env's
    # Swap-v0, the task), one policy for all: 5 s episodes (250 steps of 20 ms), no
    # wind. Trained through flyloop.MultiAgentVectorEnv (one sub-env per agent).
    "swap": SWAP,
    # The same on Swap-v1: a 1 m circle, each agent on its own altitude layer.
    "swap_layers": replace(SWAP, name="swap_layers", env_id="flyloop/Swap-v1"),
    "hover": Preset(
        name="hover",
        env_id="flyloop/QuadHover-v0",
        # 5 s episodes (250 steps of 20 ms), the default wind (mean 0–5 m/s + turbulence).
        env_kwargs={"max_steps": 250, "dt": 0.02},
        actions=QUAD_ACTIONS,
        **HOVER_SUCCESS,
    ),
    # Lander2D-v1 (the landing reward; v0's seed reward pays for hovering, see its docstring).
    "lander": Preset(
        name="lander",
        env_id="flyloop/Lander2D-v1",
        env_kwargs={"max_steps": 1000},
        actions=None,
        success=lander_success,
        success_text="landed on the platform (info['landed'])",
    ),
    "lander_moving": Preset(
        name="lander_moving",
        env_id="flyloop/Lander2D-v1",
        env_kwargs={"max_steps": 1000, "moving_platform": True},
        actions=None,
        success=lander_success,
        success_text="landed on the moving platform (info['landed'])",
    ),
    # The seed's reward, to reproduce its defect (PPO learns to hover beside the pad).
    "lander_v0": Preset(
        name="lander_v0",
        env_id="flyloop/Lander2D-v0",
        env_kwargs={"max_steps": 1000},
        actions=None,
        success=lander_success,
        success_text="landed on the platform (info['landed'])",
    ),
}


# QuadHover with a weak motor (issue 35, docs/faults.md): every episode one motor of the quad X,
# drawn from the episode's seed, loses up to half its effectiveness (thrust and reaction
# torque at the same command) at a time drawn in the first half of the episode. The policy
# sees it only through the motor states (the observation's motor commands are what it sent).
MOTOR_FAULT_RANDOMIZATION = {
    "kinds": ["motor_effectiveness"],
    "at": (0.0, 2.5),
    "effectiveness": (0.5, 1.0),
}
PRESETS["hover_motor_fault"] = replace(
    PRESETS["hover"],
    name="hover_motor_fault",
    env_kwargs={**PRESETS["hover"].env_kwargs, "fault_randomization": MOTOR_FAULT_RANDOMIZATION},
)
# QuadHover on another of the core's frames (fast_ppo.py --frame): the hover preset with the
# env's `frame`, one motor command per rotor. The quad X is "hover" itself.
FRAMES = ("quad_plus", "hexa_x", "octo_x")
for _frame in FRAMES:
    PRESETS[f"hover_{_frame}"] = replace(
        PRESETS["hover"],
        name=f"hover_{_frame}",
        env_kwargs={**PRESETS["hover"].env_kwargs, "frame": _frame},
    )


def offboard_preset() -> Preset:
    """A policy for PX4's offboard mode: thrust + body rates through the core's model of PX4's
    rate loop at 50 Hz, PX4-like estimator noise, 10 s episodes with a new target after 5 s,
    on the Iris with per-episode randomisation (train_offboard.py, examples/px4_offboard.py).
    Made when asked for: it reads the Iris from sitl/presets/."""
    return Preset(
        name="offboard",
        env_id="flyloop/QuadHover-v0",
        env_kwargs={
            "action_interface": "rates",
            "dt": 0.02,
            "max_steps": 500,
            "target_change_interval": 250,
            "use_wind": False,
            "start_attitude_range": 0.2,
            "observation_noise": {
                "position": 0.02,
                "velocity": 0.05,
                "attitude": 0.01,
                "rates": 0.02,
            },
            "model_params": px4_vehicle(),
            "randomize": OFFBOARD_RANDOMIZE,
        },
        actions=None,
        **HOVER_SUCCESS,
    )


# Presets made on demand (they read files outside examples/train/).
LAZY_PRESETS: dict[str, Callable[[], Preset]] = {"offboard": offboard_preset}


ALIASES = {
    "QuadHover": "hover",
    "flyloop/QuadHover-v0": "hover",
    "Lander2D": "lander",
    "flyloop/Lander2D-v1": "lander",
    "flyloop/Lander2D-v0": "lander_v0",
}


def preset(name: str) -> Preset:
    key = ALIASES.get(name, name)
    if key in LAZY_PRESETS:
        return LAZY_PRESETS[key]()
    if key not in PRESETS:
        choices = sorted(PRESETS) + sorted(LAZY_PRESETS) + sorted(ALIASES)
        raise ValueError(f"unknown env {name!r}; choose one of {choices}")
    return PRESETS[key]


def check_action(p: Preset, action: str | None) -> str | None:
    """The action interface's name (the preset's default for None), or a ValueError."""
    if action is None:
        return p.default_action
    if not p.actions or action not in p.actions:
        choices = sorted(p.actions) if p.actions else ["its own (leave --action out)"]
        raise ValueError(f"env {p.name!r} has no action interface {action!r}; choose {choices}")
    return action


def make_env(
    name: str,
    *,
    action: str | None = None,
    render_mode: str | None = None,
    overrides: Mapping[str, Any] | None = None,
    backend: str = "native",
) -> gym.Env:
    """The preset's env with its action interface (default: the preset's first), as it is
    trained; with backend="sitl" each env starts its own SITL, with "native" the core runs
    in this process (same episodes, bit for bit)."""
    p = preset(name)
    action = check_action(p, action)
    kwargs = {**p.env_kwargs, **(overrides or {})}
    env = gym.make(p.env_id, render_mode=render_mode, backend=backend, **kwargs)
    return p.actions[action](env) if action is not None else env


def make_native_vector_env(
    name: str,
    num_envs: int,
    *,
    overrides: Mapping[str, Any] | None = None,
    num_threads: int | None = None,
) -> gym.vector.VectorEnv:
    """The preset's env as one native vector env of `num_envs` sub-envs with the preset's
    default action interface (the quadrotor's motor commands rescaled to [-1, 1]; the other
    interfaces are single-env wrappers)."""
    p = preset(name)
    kwargs = {**p.env_kwargs, **(overrides or {})}
    envs = gym.make_vec(
        p.env_id,
        num_envs=num_envs,
        vectorization_mode="vector_entry_point",
        backend="native",
        num_threads=num_threads,
        **kwargs,
    )
    if p.actions is None:
        return envs
    unit = np.ones(envs.single_action_space.shape, np.float32)
    return gym.wrappers.vector.RescaleAction(envs, -unit, unit)


def make_success_env(name: str, **kwargs: Any) -> gym.Env:
    """make_env, with info['is_success'] at the end of each episode."""
    return SuccessInfo(make_env(name, **kwargs), preset(name).success)


def random_policy_baseline(
    name: str, episodes: int, seed: int, action: str | None = None, backend: str = "native"
) -> tuple[float, float]:
    """Mean return and success rate of uniformly random actions (the bar training must
    clear), over `episodes` episodes seeded seed, seed + 1, ..."""
    env = make_env(name, action=action, backend=backend)
    rng = np.random.default_rng(seed)
    p = preset(name)
    returns, successes = [], 0
    try:
        for episode in range(episodes):
            env.reset(seed=seed + episode)
            total, done = 0.0, False
            while not done:
                action = rng.uniform(env.action_space.low, env.action_space.high).astype(np.float32)
                _, reward, terminated, truncated, info = env.step(action)
                total += reward
                done = terminated or truncated
            returns.append(total)
            successes += p.success(terminated, truncated, info)
    finally:
        env.close()
    return float(np.mean(returns)), successes / episodes
