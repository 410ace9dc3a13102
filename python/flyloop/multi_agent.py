"""PettingZoo multi-agent envs on the core's World: `flyloop/MultiHover-v0` and `flyloop/Swap-v0`.

    import flyloop
    env = flyloop.parallel_env("flyloop/Swap-v0", num_agents=4)        # a pettingzoo ParallelEnv
    obs, infos = env.reset(seed=0)
    obs, rewards, terminations, truncations, infos = env.step(
        {agent: env.action_space(agent).sample() for agent in env.agents})

N quadrotors share one world (its wind, hull contact, downwash; docs/core.md). Each agent flies
its own vehicle through the single-agent flight interface and is rewarded as QuadHover rewards.
The task is the core's (`core/src/tasks/multi/`); this module only moves arrays.

**Agents**: ``drone_0`` … ``drone_{N-1}`` (agent i is vehicle i of the world).

**Action** per agent (Box float32, 4): ``interface="motors"`` (default): the four motor
commands in [0, 1]; ``interface="rates"``: collective thrust in [0, 1] and roll, pitch, yaw rate
(rad/s, body FRD) through PX4's rate loop (bounds from its ``roll_pitch_rate_max`` /
``yaw_rate_max``). Values outside the bounds are clipped; a non-finite value is a ValueError.

**Observation** per agent (Box float32, every value inside its declared bound): the
single-agent QuadHover observation of its own vehicle and target — 33 values on the motor
interface (world ENU / body FLU: target − position, velocity, acceleration, quaternion, body
rates, angular acceleration, body z axis, wind, motor states, motor commands), 16 on the rates
interface (the estimator's view in the heading frame) — then its ``neighbours`` (k, default
3) nearest other vehicles, nearest first, 7 values each: position relative to its own (m),
velocity relative to its own (m/s), both in the same frame as its own values, and 1.0
(present). A slot with no neighbour (fewer than k others) is *absent*: seven zeros.

**Reward** per agent and step: QuadHover's e^(−d) + ½(1 − e^(−d))·tanh(v·d̂ / velocity_scale)
towards its own target, minus ``collision_penalty`` (default 10) on the step its hull starts
touching another's.

**Termination**: the agent crashed, is out of bounds or collided; in Swap any agent's crash or
collision ends the episode for all (the swap failed). **Truncation**: ``max_steps`` (default
1000 steps of ``dt`` = 0.01 s). A done agent leaves ``env.agents``; its vehicle stays in the
world with its motors off.

**Scenarios**: MultiHover — agents start on a square grid ``hover_spacing`` apart (default 2 m)
at 1.5 m and each flies to a target drawn around its start as QuadHover draws one. Swap — agents
start evenly on a circle of ``swap_radius`` (default 2 m, turned at random each episode) and
fly to the opposite point, all through the middle; success = every agent within
``arrival_radius`` (0.5 m) of its target and no agent collided or crashed.

**Version history** (Swap): v1 — each agent starts and ends on an altitude layer of its own,
``swap_layer`` = 0.6 m apart around the start height (0.6 / 1.2 / 1.8 / 2.4 m for four
agents), so the straight line is a swap that leaves two hulls of room, and the circle is
``swap_radius`` = 1 m (2 m to fly, QuadHover's distances); everything else as v0. v0 — every
agent at the start height (``swap_layer`` = 0) on a 2 m circle: the lines all meet in the
middle and a straight flight always collides (docs/training.md "Swap").

**Info** per agent: distance_to_target, position, target_position, step_count, episode_time,
distance_progress, crashed, out_of_bounds, collided (this step), collision_speed (m/s),
collisions (this episode), arrived, all_arrived, success, randomized (the drawn values)
with domain randomisation, and with faults the per-table slots (fault_kind, fault_target,
fault_time, fault_active) and ``faults``, the active ones (docs/faults.md).

**Arguments**: ``num_agents`` (1–65,536), ``interface`` ("motors" | "rates"),
``domain_randomization`` ({core parameter: (low, high)}, drawn per agent and episode from the
seed), ``faults`` and ``fault_randomization`` (as QuadHover's, docs/faults.md; an entry is
every agent's, or one agent's with ``"agent": "drone_1"``; drawn per agent from the episode's
seed; the air faults — gust, wind shear — are refused: the world's wind field blows), and any
core parameter by name: the multi-agent task's (``neighbours``,
``collision_penalty``, ``arrival_radius``, ``swap_radius``, ``swap_layer``,
``hover_spacing``), the world's (``wind_enabled`` — off by default here —,
``wind_speed_max``, ``collisions_enabled``, ``downwash_enabled``, …), the flight task's
(``dt``, ``max_steps``, …) and the vehicle's (``mass``, …). Same seed, same episode, bit
for bit; the order of the action dict changes nothing.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import gymnasium
import numpy as np

from .faults import FAULTS_KEY, add_fault_list, plan_text

ENV_TASKS = {
    "flyloop/MultiHover-v0": "multi_hover",
    "flyloop/Swap-v0": "swap",
    "flyloop/Swap-v1": "swap",
}
# What an id sets over the core's defaults (an argument of the same name overrides it).
ENV_DEFAULTS: dict[str, dict[str, Any]] = {
    "flyloop/Swap-v1": {"swap_layer": 0.6, "swap_radius": 1.0}
}
_INTERFACES = ("motors", "rates")


def _agent_index(where: str, agent: Any) -> int:
    """An `agent` key's index: an integer, or an agent's name ``drone_i``."""
    if isinstance(agent, str) and agent.startswith("drone_") and agent[6:].isdigit():
        return int(agent[6:])
    if isinstance(agent, int | np.integer) and not isinstance(agent, bool):
        return int(agent)
    raise ValueError(
        f"{where}['agent'] must be an agent ('drone_0', ...) or its index, got {agent!r}"
    )


def _per_agent(arg: str, entries: Any) -> Any:
    """`faults` / `fault_randomization` with each `agent` key as the core's index."""
    if entries is None or isinstance(entries, str):
        return entries
    listed = [entries] if isinstance(entries, Mapping) else entries
    out = []
    for i, entry in enumerate(listed):
        if isinstance(entry, Mapping) and "agent" in entry:
            entry = {**entry, "agent": _agent_index(f"{arg}[{i}]", entry["agent"])}
        out.append(entry)
    return out


def native_config(
    num_agents: int = 4,
    interface: str = "motors",
    domain_randomization: Mapping[str, tuple[float, float]] | None = None,
    faults: Any = None,
    fault_randomization: Any = None,
    **params: Any,
) -> dict[str, Any]:
    """The extension's parameter dict for these arguments (errors name the argument).
    `faults` / `fault_randomization` are the single-agent envs' (docs/faults.md), each
    entry for every agent or, with an ``agent`` key (``"drone_1"`` or 1), for that one; the
    config's ``faults`` holds their TOML text as a SITL config file does."""
    if isinstance(num_agents, bool) or not isinstance(num_agents, int | np.integer):
        raise TypeError(f"num_agents must be an integer, got {num_agents!r}")
    if interface not in _INTERFACES:
        raise ValueError(f"interface must be 'motors' or 'rates', got {interface!r}")
    config: dict[str, Any] = {"num_agents": int(num_agents), "rates_action": interface == "rates"}
    text = plan_text(
        _per_agent("faults", faults), _per_agent("fault_randomization", fault_randomization)
    )
    if text is not None:
        config[FAULTS_KEY] = text
    for name, pair in (domain_randomization or {}).items():
        if not isinstance(pair, tuple | list) or len(pair) != 2:
            raise ValueError(f"domain_randomization[{name!r}] must be (low, high), got {pair!r}")
        config["randomize." + name] = (float(pair[0]), float(pair[1]))
    for name, value in params.items():
        config[name] = float(value) if isinstance(value, bool | int | float | np.number) else value
    return config


def _batch(
    env_id: str, num_worlds: int, num_threads: int, kwargs: dict[str, Any], backend="native"
):
    from . import _native

    if env_id not in ENV_TASKS:
        raise ValueError(f"unknown multi-agent env {env_id!r}; known: {sorted(ENV_TASKS)}")
    kwargs = {**ENV_DEFAULTS.get(env_id, {}), **kwargs}
    if "action_interface" in kwargs:  # the single-agent envs' name
        kwargs["interface"] = kwargs.pop("action_interface")
    if "randomize" in kwargs:
        kwargs["domain_randomization"] = kwargs.pop("randomize")
    if backend == "sitl":
        from .multi_sitl import SitlMultiBatch

        link = {k: kwargs.pop(k) for k in ("sitl_path", "timeout", "gcs") if k in kwargs}
        return SitlMultiBatch(ENV_TASKS[env_id], native_config(**kwargs), **link)
    return _native.MultiBatch(ENV_TASKS[env_id], native_config(**kwargs), num_worlds, num_threads)


def _spaces(batch) -> tuple[gymnasium.spaces.Box, gymnasium.spaces.Box, dict]:
    d = batch.describe()
    obs = gymnasium.spaces.Box(d["observation_low"], d["observation_high"], dtype=np.float32)
    act = gymnasium.spaces.Box(
        d["action_low"].astype(np.float32), d["action_high"].astype(np.float32), dtype=np.float32
    )
    return obs, act, d


def _info_of(row: np.ndarray, layout) -> dict[str, Any]:
    """One agent's info dict from its row of info values."""
    out: dict[str, Any] = {}
    at = 0
    for name, size, kind in layout:
        v = row[at : at + size]
        at += size
        if kind == "flag":
            out[name] = bool(v[0])
        elif kind == "integer":
            out[name] = int(v[0])
        elif kind == "real":
            out[name] = float(v[0])
        else:
            out[name] = v.astype(np.float64)
    return out


class _Arrays:
    """The preallocated arrays of one MultiBatch."""

    def __init__(self, batch) -> None:
        rows = batch.num_worlds * batch.num_agents
        self.actions = np.zeros((rows, batch.action_size), np.float32)
        self.reset = np.zeros(batch.num_worlds, bool)
        self.seeds = np.zeros(batch.num_worlds, np.uint64)
        self.obs = np.zeros((rows, batch.observation_size), np.float32)
        self.info = np.zeros((rows, batch.info_size), np.float32)
        self.rewards = np.zeros(rows, np.float64)
        self.terminated = np.zeros(rows, bool)
        self.truncated = np.zeros(rows, bool)
        self.active = np.zeros(rows, bool)

    def run(self, batch) -> None:
        batch.step(
            self.actions, self.reset, self.seeds, self.obs, self.info,
            self.rewards, self.terminated, self.truncated, self.active,
        )  # fmt: skip


def _parallel_env_class():
    from pettingzoo import ParallelEnv

    class FlyloopParallelEnv(ParallelEnv):
        """A flyloop multi-agent task as a PettingZoo ParallelEnv (module docs)."""

        metadata = {"name": "flyloop_multi_v0", "render_modes": [], "is_parallelizable": True}

        def __init__(
            self,
            env_id: str,
            render_mode: str | None = None,
            backend: str = "native",
            **kwargs: Any,
        ) -> None:
            if render_mode is not None:
                raise ValueError(f"render_mode must be None, got {render_mode!r}")
            self.render_mode = None
            self.backend = backend
            self._batch = _batch(env_id, 1, 1, kwargs, backend)
            self._arrays = _Arrays(self._batch)
            self._obs_space, self._act_space, d = _spaces(self._batch)
            self._info_layout = d["info_layout"]
            self.dt = d["dt"]
            self.observation_layout = d["observation_layout"]
            self.possible_agents = [f"drone_{i}" for i in range(self._batch.num_agents)]
            self._index = {a: i for i, a in enumerate(self.possible_agents)}
            self.agents: list[str] = []
            self._seeds = np.random.default_rng()

        def observation_space(self, agent: str) -> gymnasium.spaces.Box:
            # One space object for every agent (pettingzoo's seed test seeds it per agent).
            return self._obs_space

        def action_space(self, agent: str) -> gymnasium.spaces.Box:
            return self._act_space

        def _results(self, agents: list[str]):
            a = self._arrays
            obs = {g: a.obs[self._index[g]].copy() for g in agents}
            infos = {
                g: add_fault_list(_info_of(a.info[self._index[g]], self._info_layout))
                for g in agents
            }
            return obs, infos

        def reset(self, seed: int | None = None, options: dict | None = None):
            if seed is not None:
                self._seeds = np.random.default_rng(seed)
                episode = int(seed)
            else:
                episode = int(self._seeds.integers(2**63))
            a = self._arrays
            a.reset[:] = True
            a.seeds[:] = np.uint64(episode % 2**64)
            a.run(self._batch)
            a.reset[:] = False
            self.agents = list(self.possible_agents)
            return self._results(self.agents)

        def step(self, actions: Mapping[str, Any]):
            missing = [g for g in self.agents if g not in actions]
            if missing:
                raise KeyError(f"no action for agent(s) {missing}: every live agent needs one")
            unknown = [g for g in actions if g not in self._index]
            if unknown:
                raise KeyError(f"unknown agent(s) {unknown}; agents are {self.possible_agents}")
            a = self._arrays
            a.actions[:] = 0.0
            for g in self.agents:
                value = np.asarray(actions[g], np.float32)
                if value.shape != (4,):
                    raise ValueError(f"action of {g} must have shape (4,), got {value.shape}")
                a.actions[self._index[g]] = value
            a.run(self._batch)
            agents = self.agents
            obs, infos = self._results(agents)
            rewards = {g: float(a.rewards[self._index[g]]) for g in agents}
            terms = {g: bool(a.terminated[self._index[g]]) for g in agents}
            truncs = {g: bool(a.truncated[self._index[g]]) for g in agents}
            self.agents = [g for g in agents if not (terms[g] or truncs[g])]
            return obs, rewards, terms, truncs, infos

        def positions(self) -> tuple[np.ndarray, np.ndarray]:
            """Every vehicle's position and target, (N, 3) each, world ENU, m."""
            p, t = self._batch.positions(0)
            return p.reshape(-1, 3), t.reshape(-1, 3)

        def close(self) -> None:
            close = getattr(self._batch, "close", None)  # the SITL backend's process
            if close is not None:
                close()

    return FlyloopParallelEnv


def parallel_env(env_id: str, num_agents: int = 4, backend: str = "native", **kwargs: Any):
    """The multi-agent env `env_id` ("flyloop/MultiHover-v0", "flyloop/Swap-v0" or "-v1") as a
    PettingZoo ParallelEnv (module docs for the spaces, reward, ends and arguments), its world
    in this process (backend "native") or in a flyloop-sitl it starts (backend "sitl", the
    same bits: flyloop.multi_sitl; `sitl_path=`, `timeout=`, and `gcs="127.0.0.1:14550"` to
    show a ground station every agent as MAVLink system i + 1: docs/sitl.md)."""
    if backend not in ("native", "sitl"):
        raise ValueError(f"backend must be 'native' or 'sitl', got {backend!r}")
    return _parallel_env_class()(env_id, num_agents=num_agents, backend=backend, **kwargs)


class MultiAgentVectorEnv(gymnasium.vector.VectorEnv):
    """`num_worlds` worlds of `num_agents` agents as one gymnasium VectorEnv of
    num_worlds·num_agents sub-envs (row w·N + i is agent i of world w), for training one
    policy shared by every agent. A world restarts on the step after all its agents are done
    (NEXT_STEP autoreset: that step's action is ignored, its reward 0); a done agent of a world
    still flying reports reward 0 and ``info["active"]`` False until then. ``reset(seed=s)``
    seeds world w with s + w; later episodes draw their seeds from s."""

    def __init__(
        self,
        env_id: str,
        num_worlds: int = 1,
        num_threads: int = 1,
        **kwargs: Any,
    ) -> None:
        self._batch = _batch(env_id, num_worlds, num_threads, kwargs)
        self._arrays = _Arrays(self._batch)
        obs_space, act_space, d = _spaces(self._batch)
        self._info_layout = d["info_layout"]
        # One agent's observation groups: (name, number of values), in order.
        self.observation_layout = d["observation_layout"]
        self.num_worlds = num_worlds
        self.num_agents = self._batch.num_agents
        self.num_envs = num_worlds * self.num_agents
        self.single_observation_space = obs_space
        self.single_action_space = act_space
        self.observation_space = gymnasium.vector.utils.batch_space(obs_space, self.num_envs)
        self.action_space = gymnasium.vector.utils.batch_space(act_space, self.num_envs)
        self.metadata = {"autoreset_mode": gymnasium.vector.AutoresetMode.NEXT_STEP}
        self._restart = np.zeros(num_worlds, bool)
        self._seeds = np.random.default_rng()

    def _infos(self) -> dict[str, np.ndarray]:
        a = self._arrays
        out: dict[str, np.ndarray] = {}
        at = 0
        for name, size, kind in self._info_layout:
            v = a.info[:, at : at + size]
            at += size
            if kind == "flag":
                out[name] = v[:, 0] != 0
            elif kind == "integer":
                out[name] = v[:, 0].astype(np.int64)
            elif kind == "real":
                out[name] = v[:, 0].astype(np.float64)
            else:
                out[name] = v.astype(np.float64)
        out["active"] = a.active.copy()
        return out

    def reset(self, *, seed: int | None = None, options: dict | None = None):
        a = self._arrays
        if seed is not None:
            self._seeds = np.random.default_rng(seed)
            a.seeds[:] = np.arange(self.num_worlds, dtype=np.uint64) + np.uint64(seed)
        else:
            a.seeds[:] = self._seeds.integers(2**63, size=self.num_worlds, dtype=np.uint64)
        a.reset[:] = True
        a.run(self._batch)
        a.reset[:] = False
        self._restart[:] = False
        return a.obs.copy(), self._infos()

    def step(self, actions: np.ndarray):
        a = self._arrays
        a.actions[:] = np.asarray(actions, np.float32).reshape(a.actions.shape)
        a.reset[:] = self._restart
        if self._restart.any():
            n = int(self._restart.sum())
            a.seeds[self._restart] = self._seeds.integers(2**63, size=n, dtype=np.uint64)
        a.run(self._batch)
        done = (a.terminated | a.truncated | ~a.active).reshape(self.num_worlds, -1)
        self._restart = done.all(axis=1) & ~a.reset
        return (
            a.obs.copy(),
            a.rewards.copy(),
            a.terminated.copy(),
            a.truncated.copy(),
            self._infos(),
        )

    def close_extras(self, **kwargs: Any) -> None:
        pass


__all__ = ["ENV_TASKS", "MultiAgentVectorEnv", "native_config", "parallel_env"]
