"""flyloop's multi-agent envs as RLlib MultiAgentEnvs (ray[rllib], new API stack).

    from ray.tune.registry import register_env
    from flyloop.rllib import multi_agent_env
    register_env("flyloop-multi", multi_agent_env)
    config = (
        PPOConfig()
        .environment("flyloop-multi", env_config={"env_id": "flyloop/MultiHover-v0",
                                                  "num_agents": 4})
        .multi_agent(policies={"shared"}, policy_mapping_fn=lambda agent, episode, **kw: "shared")
    )

`env_config` holds `flyloop.parallel_env`'s arguments: ``env_id`` (default
"flyloop/MultiHover-v0"), ``num_agents``, ``backend`` and any keyword it takes. Ray is
imported only when an env is made.

Why not ray's ParallelPettingZooEnv: it ends the episode when *every* agent stepped last
terminated (or every one truncated); flyloop's agents leave one by one, and when the last
ones end on the same step, one by a crash and one by the time limit, neither "__all__" is
set and RLlib steps an env with no agents. Here "__all__" is set as soon as no agent is left.
"""

from __future__ import annotations

from typing import Any


def multi_agent_env(env_config: dict[str, Any] | None = None):
    """RLlib's env factory: a MultiAgentEnv over `flyloop.parallel_env(**env_config)`."""
    return _env_class()(dict(env_config or {}))


def _env_class():
    import gymnasium
    from ray.rllib.env.multi_agent_env import MultiAgentEnv

    from .multi_agent import parallel_env

    class FlyloopMultiAgentEnv(MultiAgentEnv):
        """A flyloop PettingZoo ParallelEnv seen through RLlib's MultiAgentEnv API."""

        def __init__(self, env_config: dict[str, Any]) -> None:
            super().__init__()
            config = dict(env_config)
            # RLlib adds these keys to every env_config; they are not the env's arguments.
            for key in ("worker_index", "num_workers", "vector_index", "remote"):
                config.pop(key, None)
            env_id = config.pop("env_id", "flyloop/MultiHover-v0")
            self.par_env = parallel_env(env_id, **config)
            self.possible_agents = list(self.par_env.possible_agents)
            self.agents = []
            self.observation_spaces = {
                a: self.par_env.observation_space(a) for a in self.possible_agents
            }
            self.action_spaces = {a: self.par_env.action_space(a) for a in self.possible_agents}
            self.observation_space = gymnasium.spaces.Dict(self.observation_spaces)
            self.action_space = gymnasium.spaces.Dict(self.action_spaces)

        def reset(self, *, seed: int | None = None, options: dict | None = None):
            obs, infos = self.par_env.reset(seed=seed, options=options)
            self.agents = list(self.par_env.agents)
            return obs, infos

        def step(self, action_dict):
            obs, rewards, terms, truncs, infos = self.par_env.step(action_dict)
            self.agents = list(self.par_env.agents)
            over = not self.agents
            terms["__all__"] = over and all(terms.values())
            truncs["__all__"] = over and not terms["__all__"]
            return obs, rewards, terms, truncs, infos

        def close(self) -> None:
            self.par_env.close()

    return FlyloopMultiAgentEnv


__all__ = ["multi_agent_env"]
