"""Compact PPO (torch) on a flyloop vector env: QuadHover in seconds, Lander2D in minutes.

The rollouts come straight from one gymnasium VectorEnv (`gym.make_vec(...,
vectorization_mode="vector_entry_point", backend=...)`): the native one steps all envs in one
call into preallocated arrays, the SITL one flies them in one flyloop-sitl process over
MAVLink. No stable-baselines3 in the loop, big batches, a small MLP, one torch thread.

    .venv/bin/python examples/train/fast_ppo.py                       # QuadHover, native
    .venv/bin/python examples/train/fast_ppo.py --backend native sitl # and over the SITL
    .venv/bin/python examples/train/fast_ppo.py --env lander          # Lander2D-v1, static pad
    .venv/bin/python examples/train/fast_ppo.py --env lander_moving   # moving pad

Writes, per backend, `OUT/BACKEND/`: `progress.csv` (per update: env steps, wall seconds,
training episodes' success rate, mean return and length), `policy.pt` and `summary.json` (with the
held-out evaluation: the deterministic policy on `--eval-episodes` episodes seeded from
1,000,000, which training never uses), and `OUT/learning_curve.png` (success rate against env
steps and wall seconds, one line per backend; `--curve PATH` draws it there too).
Success is the preset's (training_envs.py): on hover the episode reaches its time limit
within 0.5 m of the target, on the landers it landed (info['landed']: a safe landing). The
env-specific settings (PPO's hyperparameters, env steps, evaluation episodes) are one entry
of TASKS each. The vector envs autoreset NEXT_STEP: the step after an episode ends returns
the next episode's first observation and is left out of the loss. A truncation (the time
limit) is bootstrapped from its final observation's value, except with
`Config.time_limit_terminal` (the moving pad): then it ends the return, and the value
function sees the time remaining. With `Config.select_every` (the moving pad) the run
validates its deterministic policy every few updates on episodes seeded from 5,000,000 and
saves the best one as policy.pt, not the last (progress.csv holds the validation curve,
summary.json the update kept). evaluate.py loads a saved
run folder (policy.pt with summary.json) as it loads a stable-baselines3 one.
"""

from __future__ import annotations

import sys

if __name__ == "__main__":  # torch and the envs take seconds to load: say so first
    print("fast_ppo: loading torch and the envs", file=sys.stderr, flush=True)

import argparse  # noqa: E402
import csv  # noqa: E402
import json  # noqa: E402
import time  # noqa: E402
from dataclasses import asdict, dataclass, field, replace  # noqa: E402
from pathlib import Path  # noqa: E402

import flyloop  # noqa: E402  (registers the envs)
import flyloop.multi_agent  # noqa: E402
import gymnasium as gym  # noqa: E402
import numpy as np  # noqa: E402
import torch  # noqa: E402
from separation_shaping import SeparationShaping  # noqa: E402
from torch import nn  # noqa: E402
from training_envs import FRAMES, HOVER_SUCCESS_DISTANCE_M, preset  # noqa: E402

EVAL_SEED = 1_000_000
# The validation episodes that choose the policy a run keeps (Config.select_every): disjoint
# from the held-out (1,000,000..) and held-back (2,000,000.., tests/training) episodes, and
# from training's (sub-env i's first episode seeded seed + i, the later ones from 63-bit draws).
VALIDATION_SEED = 5_000_000


@dataclass
class Config:
    """PPO's settings; the defaults learn QuadHover on 2 cores in well under a minute."""

    num_envs: int = 64
    rollout_steps: int = 128  # per env and update: 8,192 transitions
    minibatches: int = 4
    epochs: int = 8
    learning_rate: float = 1e-3
    # The learning rate falls linearly from learning_rate to learning_rate * lr_end over
    # the run (1.0: constant).
    lr_end: float = 1.0
    gamma: float = 0.99
    gae_lambda: float = 0.95
    clip: float = 0.2
    value_coef: float = 0.5
    max_grad_norm: float = 0.5
    hidden: int = 64
    # The learner sees reward * reward_scale (the reported returns are the env's own).
    reward_scale: float = 1.0
    init_log_std: float = -0.5
    # The policy's Gaussian lives in this basis: "motors" (one output per env action) or, for
    # a two-motor lander, "collective" ([mean thrust, half difference]; left = c - d, right =
    # c + d). Its diagonal covariance then explores climb and turn separately, and a policy
    # learns to hold its attitude with little turning noise while it still tries descents.
    action_basis: str = "motors"
    # Time-limit truncations: bootstrapped from the final observation's value (False), or the
    # end of the return (True) with the time remaining (1 - step / max_steps) as an extra
    # input of the value function only (the policy's inputs stay the env's observation).
    time_limit_terminal: bool = False
    # Keep the best policy: every select_every updates (0: never) from update select_after on
    # and after the last update, the deterministic policy flies select_episodes validation
    # episodes (VALIDATION_SEED..);
    # the run keeps the policy (and its observation statistics) with the most safe landings,
    # ties going to the higher mean return, then the later update. Otherwise: the last policy.
    select_every: int = 0
    select_after: int = 0
    select_episodes: int = 100
    # Multi-agent tasks: the learner's reward also takes separation_penalty per step and per
    # observed neighbour closer than separation_radius (m), times (1 − d / separation_radius)
    # (separation_shaping.py; 0: off). The reported returns stay the env's.
    separation_penalty: float = 0.0
    separation_radius: float = 1.0


@dataclass(frozen=True)
class Task:
    """One env's settings: the training_envs.py preset, PPO's configuration, the default
    env steps and held-out evaluation episodes."""

    preset: str
    config: Config
    timesteps: int
    eval_episodes: int
    title: str  # of the learning curve


# Lander2D: the learner sees rewards / 100 (the landing's +100 as 1); gamma 0.998 (a
# horizon of ~500 steps, the length of a landing: at 0.99 the +100 was too far off and PPO
# settled for hovering above the pad until the time limit); 32 minibatches of 512, 10 epochs.
# The Gaussian is over collective and differential thrust (σ 0.6 each at the start): over the
# two motors (σ 1 each), training seed 1 never landed in 1.5M env steps (it settled for
# hovering until the time limit); over collective and differential, seeds 0, 1 and 2 landed
# 100 % of their held-out episodes after 1.5M.
LANDER = Config(
    num_envs=128,
    rollout_steps=128,  # 16,384 transitions per update
    minibatches=32,
    epochs=10,
    learning_rate=3e-4,
    gamma=0.998,
    reward_scale=0.01,
    init_log_std=-0.5,
    action_basis="collective",
)
# The moving pad needs more env steps: 7M, the learning rate falling to 0. The time limit ends
# the return:
# the env's -100 at the time limit is a failure, but bootstrapping the truncation added back
# the value of a state near the pad (the critic cannot tell a hover at step 100 from one at
# step 999), so hovering until the time limit cost little more than landing late; training
# seeds found the landing late or lost it again (held-out 23.5 / 99 / 100 % at 7M, 87 / 78 /
# 57.5 % at 10M). With the time limit terminal and the time remaining as the critic's input
# (the policy's inputs unchanged), seeds 0, 1 and 2 landed 99.5 / 100 / 82.5 % of their
# held-out episodes after 7M env steps with 128 envs and 5 epochs of 16 minibatches: a run's
# success wanders (seed 2 climbed slowly, 10 epochs lost seed 0 after 2.3M). With 256 envs per
# update (~40 episode ends each, twice as many), the static pad's 10 epochs of 32 minibatches
# (of 1,024 here) and the best of the policies validated every 5 updates kept: 100 / 100 /
# 91.5 % (docs/training.md).
LANDER_MOVING = replace(
    LANDER,
    num_envs=256,
    lr_end=0.0,
    time_limit_terminal=True,
    select_every=5,
    select_after=30,
)

SWAP_LAYERS = Config(num_envs=128, rollout_steps=128, minibatches=8)
# Swap-v0: the straight line collides in the middle, and on the env's reward alone PPO met the
# collision as a cliff (0 % training success for 5M agent-steps). The learner's reward also
# charges closeness to a neighbour (separation_shaping.py), and the learning rate falls to a
# tenth over the run: seed 0 passes 90 % training success after 3.46M agent-steps, 100 %
# held-out after 4M (docs/training.md).
SWAP_V0 = replace(
    SWAP_LAYERS,
    lr_end=0.1,
    separation_penalty=0.5,
    separation_radius=0.8,
)

TASKS: dict[str, Task] = {
    # The rates interface (train_offboard.py adds its held-out checks and the export for
    # examples/px4_offboard.py): more envs per update, shorter rollouts, a slower step.
    "offboard": Task(
        "offboard",
        Config(num_envs=128, rollout_steps=64, learning_rate=5e-4),
        timesteps=4_000_000,
        eval_episodes=200,
        title="PPO, thrust + body rates through PX4's rate loop, Iris randomised",
    ),
    # Four agents, one shared policy: each agent is a sub-env of flyloop.MultiAgentVectorEnv
    # (32 worlds x 4 agents per update). Swap-v0 (a 2 m circle, all at one height): SWAP_V0.
    "swap": Task(
        "swap",
        SWAP_V0,
        timesteps=4_000_000,
        eval_episodes=100,
        title="PPO on Swap-v0, 4 agents, one shared policy",
    ),
    # Swap-v1 (layers 0.6 m, 1 m circle): training success 100 % from ~1.06M agent-steps
    # (seed 0) with PPO's plain settings (docs/training.md).
    "swap_layers": Task(
        "swap_layers",
        SWAP_LAYERS,
        timesteps=1_500_000,
        eval_episodes=100,
        title="PPO on Swap-v1, 4 agents, one shared policy",
    ),
    "hover": Task(
        "hover", Config(), timesteps=300_000, eval_episodes=100, title="PPO on QuadHover-v0"
    ),
    # QuadHover on the other frames (--frame): the quad's settings, one output per rotor, 2M
    # env steps with the learning rate falling to a tenth. The hexa at 1 kg hovers at motor
    # state 0.40, off the policy's zero (0.5); measured on the hexa (seeds 0 / 1 / 2, held-out
    # 100 episodes): 67 % (seed 0) after 300k env steps, 96 / 94 / 96 % after 1M, 97 / 97 / 94 %
    # after 2M at a constant rate, 97 / 95 / 97 % with it falling (docs/training.md).
    **{
        f"hover_{frame}": Task(
            f"hover_{frame}",
            Config(lr_end=0.1),
            timesteps=2_000_000,
            eval_episodes=100,
            title=f"PPO on QuadHover-v0, frame {frame}",
        )
        for frame in FRAMES
    },
    # QuadHover through a weak motor (training_envs.py's hover_motor_fault: one motor at
    # 50-100 % effectiveness from a time in 0-2.5 s, drawn per episode), the learning rate
    # falling to a tenth. Seed 0: 96 % held-out (200 episodes) after 1M env steps; run to 2M
    # it ended at 94.5 % (docs/training.md).
    "hover_motor_fault": Task(
        "hover_motor_fault",
        Config(lr_end=0.1),
        timesteps=1_000_000,
        eval_episodes=200,
        title="PPO on QuadHover-v0, one motor at 50-100 % effectiveness",
    ),
    "lander": Task(
        "lander",
        LANDER,
        timesteps=1_500_000,
        eval_episodes=200,
        title="PPO on Lander2D-v1, static pad",
    ),
    # The moving pad as registered from the first step: no curriculum (a slower pad first, or
    # spawns near the pad, learned no faster).
    "lander_moving": Task(
        "lander_moving",
        LANDER_MOVING,
        timesteps=7_000_000,
        eval_episodes=200,
        title="PPO on Lander2D-v1, moving pad",
    ),
}


class RunningNorm:
    """Observation mean and variance over everything seen (parallel Welford update)."""

    def __init__(self, size: int) -> None:
        self.mean = np.zeros(size, np.float64)
        self.var = np.ones(size, np.float64)
        self.count = 1e-4

    def update(self, batch: np.ndarray) -> None:
        mean, var, n = batch.mean(0), batch.var(0), batch.shape[0]
        delta, total = mean - self.mean, self.count + n
        self.mean = self.mean + delta * n / total
        self.var = (self.var * self.count + var * n + delta**2 * self.count * n / total) / total
        self.count = total

    def __call__(self, obs: np.ndarray) -> np.ndarray:
        z = (obs - self.mean) / np.sqrt(self.var + 1e-8)
        return np.clip(z, -10, 10).astype(np.float32)


BASES = {"motors": None, "collective": np.array([[1.0, -1.0], [1.0, 1.0]])}


class ActorCritic(nn.Module):
    """Gaussian policy (state-independent log std) on [-1, 1] actions, and a value function.
    The Gaussian is over the action basis' coordinates; `to_actions` maps them to the env's."""

    def __init__(
        self,
        obs_size: int,
        act_size: int,
        hidden: int,
        log_std: float = -0.5,
        basis: str = "motors",
        value_extra: int = 0,
    ) -> None:
        super().__init__()
        matrix = BASES[basis]
        if matrix is not None and matrix.shape != (act_size, act_size):
            raise ValueError(f"action basis {basis!r} is for {len(matrix)} actions, not {act_size}")
        # None: the motors themselves (the outputs pass through untouched, float32 as sampled).
        self.basis = matrix

        def mlp(out: int, gain: float, inputs: int = obs_size) -> nn.Sequential:
            layers = [nn.Linear(inputs, hidden), nn.Tanh(), nn.Linear(hidden, hidden)]
            net = nn.Sequential(*layers, nn.Tanh(), nn.Linear(hidden, out))
            for layer in net:
                if isinstance(layer, nn.Linear):
                    nn.init.orthogonal_(layer.weight, gain if layer.out_features == out else 2**0.5)
                    nn.init.zeros_(layer.bias)
            return net

        self.mu = mlp(act_size, 0.01)
        # value_extra inputs after the observation (the time remaining) for the critic only.
        self.value = mlp(1, 1.0, obs_size + value_extra)
        self.log_std = nn.Parameter(torch.full((act_size,), log_std))

    def dist(self, x: torch.Tensor) -> torch.distributions.Normal:
        return torch.distributions.Normal(self.mu(x), self.log_std.exp())

    def to_actions(self, coordinates: np.ndarray) -> np.ndarray:
        """Policy outputs (rows) in the action basis to [-1, 1] actions (not yet clipped), in
        the outputs' dtype."""
        if self.basis is None:
            return coordinates
        return (coordinates @ self.basis.T).astype(coordinates.dtype)


def make_envs(task: str, backend: str, num_envs: int, **overrides) -> gym.vector.VectorEnv:
    """The task's vector env of num_envs sub-envs; for a multi-agent task one sub-env per
    agent (num_envs / num_agents worlds)."""
    p = preset(TASKS[task].preset)
    kwargs = {**p.env_kwargs, **overrides}
    if p.env_id in flyloop.multi_agent.ENV_TASKS:
        if backend != "native":
            raise ValueError(f"{task} trains on the native backend only")
        agents = kwargs["num_agents"]
        if num_envs % agents:
            raise ValueError(f"num_envs ({num_envs}) must be a multiple of {agents} agents")
        return flyloop.MultiAgentVectorEnv(
            p.env_id, num_worlds=num_envs // agents, num_threads=2, **kwargs
        )
    return gym.make_vec(
        p.env_id,
        num_envs=num_envs,
        vectorization_mode="vector_entry_point",
        backend=backend,
        **kwargs,
    )


def to_env(action: np.ndarray, space: gym.spaces.Box) -> np.ndarray:
    """[-1, 1] policy actions (clipped) to the env's motor commands (Lander2D's already are)."""
    unit = np.clip(action, -1.0, 1.0)
    if np.all(space.low == -1.0) and np.all(space.high == 1.0):
        return unit.astype(np.float32)
    return (space.low + (unit + 1.0) * 0.5 * (space.high - space.low)).astype(np.float32)


def successes(terminated, truncated, infos) -> np.ndarray:
    """The preset's success per sub-env (meaningful for the sub-envs whose episode ended
    now): landed on Lander2D, the hover preset's success otherwise."""
    if "landed" in infos:
        return np.asarray(infos["landed"], bool)
    if "all_arrived" in infos:  # the multi-agent tasks' own success
        return np.asarray(infos["success"], bool)
    distance = np.asarray(infos["distance_to_target"], np.float64)
    return truncated & ~terminated & (distance < HOVER_SUCCESS_DISTANCE_M)


def evaluate(
    model, norm, task: str, backend: str, episodes: int, seed: int = EVAL_SEED, envs=None
) -> dict:
    """The deterministic policy on `episodes` episodes seeded seed, seed + 1, ... (one
    sub-env each, first episode only). `envs`: an open vector env of `episodes` envs to
    reuse (left open); otherwise one is made and closed."""
    own = envs is None
    if own:
        # A multi-agent episode is one world: its agents are num_agents sub-envs.
        agents = preset(TASKS[task].preset).env_kwargs.get("num_agents", 1)
        envs = make_envs(task, backend, episodes * agents)
    try:
        obs, _ = envs.reset(seed=seed)
        done = np.zeros(envs.num_envs, bool)
        success = np.zeros(envs.num_envs, bool)
        returns = np.zeros(envs.num_envs)
        while not done.all():
            with torch.no_grad():
                action = model.to_actions(model.mu(torch.as_tensor(norm(obs))).numpy())
            obs, reward, terminated, truncated, infos = envs.step(
                to_env(action, envs.single_action_space)
            )
            live = ~done
            # float32 as the learner stores it (the SITL's rewards are float32 on the wire).
            returns[live] += reward[live].astype(np.float32)
            ended = live & (terminated | truncated)
            success[ended] = successes(terminated, truncated, infos)[ended]
            done |= ended
    finally:
        if own:
            envs.close()
    return dict(
        episodes=episodes,
        seed=seed,
        success_rate=float(success.mean()),
        mean_return=float(returns.mean()),
    )


def start_from(folder: Path, model: ActorCritic, norm: RunningNorm) -> None:
    """--init: the weights and observation statistics of an earlier run's policy.pt (the same
    task and network; the optimiser starts afresh)."""
    saved = torch.load(folder / "policy.pt", weights_only=False)
    try:
        model.load_state_dict(saved["model"])
    except RuntimeError as exc:
        raise ValueError(f"--init {folder}: not a policy of this task's network: {exc}") from exc
    norm.mean, norm.var = saved["obs_mean"], saved["obs_var"]
    # The statistics weigh as the observations they were taken over (one per env step).
    norm.count = float(json.loads((folder / "summary.json").read_text())["env_steps"])


def make_model(cfg: Config, obs_size: int, act_size: int) -> ActorCritic:
    """The actor-critic of cfg; with cfg.time_limit_terminal the critic also sees the time
    remaining."""
    return ActorCritic(
        obs_size,
        act_size,
        cfg.hidden,
        cfg.init_log_std,
        cfg.action_basis,
        value_extra=int(cfg.time_limit_terminal),
    )


def time_limit(cfg: Config, task: str) -> int | None:
    """The task's episode length in steps when the time limit ends the return (the time
    remaining is then the critic's input), otherwise None."""
    if not cfg.time_limit_terminal:
        return None
    max_steps = preset(TASKS[task].preset).env_kwargs.get("max_steps")
    if not max_steps:
        raise ValueError("time_limit_terminal needs the task's max_steps")
    return max_steps


@dataclass
class EndedEpisodes:
    """The training episodes that ended during one rollout."""

    success: list = field(default_factory=list)
    returns: list = field(default_factory=list)
    lengths: list = field(default_factory=list)


class Rollout:
    """One update's transitions (rollout_steps steps of num_envs sub-envs), and what carries
    over from one rollout to the next: each sub-env's episode so far, and whether its next
    step resets (NEXT_STEP autoreset: that step is left out of the loss)."""

    def __init__(self, cfg: Config, obs_size: int, act_size: int, max_steps: int | None) -> None:
        t_len, n = cfg.rollout_steps, cfg.num_envs
        self.reward_scale = cfg.reward_scale
        self.max_steps = max_steps
        self.obs = np.zeros((t_len + 1, n, obs_size), np.float32)
        self.act = np.zeros((t_len, n, act_size), np.float32)
        self.logp = np.zeros((t_len, n), np.float32)
        self.rew = np.zeros((t_len, n), np.float32)
        self.term = np.zeros((t_len, n), bool)
        self.done = np.zeros((t_len, n), bool)
        self.valid = np.zeros((t_len, n), bool)
        # The time remaining at each observation (the critic's extra input when timed).
        self.time = np.ones((t_len + 1, n), np.float32) if max_steps is not None else None
        self.resetting = np.zeros(n, bool)  # the previous step ended: this step resets
        self.episode_return = np.zeros(n)
        self.episode_length = np.zeros(n, np.int64)
        self.shaping: SeparationShaping | None = None  # the learner's extra term, if any

    def collect(self, envs, model: ActorCritic, norm: RunningNorm, obs: np.ndarray):
        """Flies the sampled policy for the rollout from obs; returns the last observation and
        the episodes that ended. The observations are normalised with the statistics of
        earlier rollouts (the same inputs that the update's ratios compare against); norm
        takes in this rollout's new ones at the end."""
        space = envs.single_action_space
        t_len = len(self.rew)
        ended = EndedEpisodes()
        raw = []
        for t in range(t_len):
            self.obs[t] = norm(obs)
            raw.append(obs)
            if self.time is not None:
                self.time[t] = 1.0 - self.episode_length / self.max_steps
            with torch.no_grad():
                d = model.dist(torch.as_tensor(self.obs[t]))
                action = d.sample()
                self.logp[t] = d.log_prob(action).sum(-1).numpy()
            self.act[t] = action.numpy()
            obs, reward, terminated, truncated, infos = envs.step(
                to_env(model.to_actions(self.act[t]), space)
            )
            self.record(t, reward, terminated, truncated, infos, ended)
            if self.shaping is not None:
                live = self.valid[t] & infos.get("active", True)
                self.rew[t] += np.where(live, self.shaping(obs) * self.reward_scale, 0.0)
        self.obs[t_len] = norm(obs)
        if self.time is not None:
            self.time[t_len] = 1.0 - self.episode_length / self.max_steps
        norm.update(np.concatenate(raw[1:] + [obs]))
        return obs, ended

    def record(self, t: int, reward, terminated, truncated, infos, ended: EndedEpisodes) -> None:
        """Step t's outcome: the buffers, the episodes in progress, and those that ended."""
        valid = ~self.resetting
        done = valid & (terminated | truncated)
        self.rew[t], self.term[t], self.done[t], self.valid[t] = reward, terminated, done, valid
        if self.time is not None:
            self.term[t] |= truncated
        self.episode_return += np.where(valid, self.rew[t], 0.0)
        self.episode_length += valid
        if self.reward_scale != 1.0:
            self.rew[t] *= self.reward_scale
        if done.any():
            ended.success.extend(successes(terminated, truncated, infos)[done])
            ended.returns.extend(self.episode_return[done])
            ended.lengths.extend(self.episode_length[done])
            self.episode_return[done] = 0.0
            self.episode_length[done] = 0
        self.resetting = done


class Selection:
    """Config.select_every: after the due updates the deterministic policy flies the
    validation episodes, and the best policy (with its observation statistics) is kept."""

    def __init__(self, cfg: Config, task: str, backend: str, updates: int) -> None:
        self.cfg, self.task, self.backend, self.updates = cfg, task, backend, updates
        self.active = cfg.select_every > 0
        self.envs = make_envs(task, backend, cfg.select_episodes) if self.active else None
        self.best = None  # (rank, update, state, obs mean, obs var) of the best validated policy

    def due(self, update: int) -> bool:
        """Every select_every updates from select_after on, and after the last update."""
        if not self.active:
            return False
        every = update % self.cfg.select_every == 0 or update == self.updates
        return every and update >= self.cfg.select_after

    def validate(self, update: int, model: ActorCritic, norm: RunningNorm) -> dict | None:
        """The validation after `update` (counted from 1) if due, else None."""
        if not self.due(update):
            return None
        validation = evaluate(
            model,
            norm,
            self.task,
            self.backend,
            self.cfg.select_episodes,
            VALIDATION_SEED,
            envs=self.envs,
        )
        # Ties go to the later update.
        rank = (validation["success_rate"], validation["mean_return"])
        if self.best is None or rank >= self.best[0]:
            state = {key: v.clone() for key, v in model.state_dict().items()}
            self.best = (rank, update, state, norm.mean.copy(), norm.var.copy())
        return validation

    def kept(self, obs_size: int, act_size: int) -> dict:
        """The best validated policy: its model, observation statistics and record."""
        rank, update, state, mean, var = self.best
        model = make_model(self.cfg, obs_size, act_size)
        model.load_state_dict(state)
        norm = RunningNorm(obs_size)
        norm.mean, norm.var = mean, var
        selected = dict(
            update=update,
            env_steps=update * self.cfg.num_envs * self.cfg.rollout_steps,
            validation_seed=VALIDATION_SEED,
            validation_episodes=self.cfg.select_episodes,
            validation_success_rate=rank[0],
            validation_mean_return=rank[1],
        )
        return dict(model=model, norm=norm, selected=selected)

    def close(self) -> None:
        if self.envs is not None:
            self.envs.close()


def anneal_learning_rate(optimiser: torch.optim.Optimizer, cfg: Config, k: int, updates: int):
    """Before update k (from 0): linearly from learning_rate to learning_rate * lr_end."""
    if cfg.lr_end != 1.0:
        fraction = k / max(updates - 1, 1)
        for group in optimiser.param_groups:
            group["lr"] = cfg.learning_rate * (1.0 + (cfg.lr_end - 1.0) * fraction)


def progress_row(
    steps: int, wall_s: float, ended: EndedEpisodes, validation: dict | None, selecting: bool
) -> dict:
    """One line of progress.csv: the training episodes that ended in the update's rollout,
    and (when the run selects its policy) the validation, empty between validations."""
    row = dict(
        env_steps=steps,
        wall_s=round(wall_s, 3),
        episodes=len(ended.success),
        success_rate=float(np.mean(ended.success)) if ended.success else float("nan"),
        mean_return=float(np.mean(ended.returns)) if ended.returns else float("nan"),
        mean_length=float(np.mean(ended.lengths)) if ended.lengths else float("nan"),
    )
    if selecting:
        row["validation_success_rate"] = validation and validation["success_rate"]
        row["validation_mean_return"] = validation and validation["mean_return"]
    return row


def say(text: str) -> None:
    """A phase that takes seconds, said as it starts (on stderr, as the progress bar)."""
    print(f"fast_ppo: {text}", file=sys.stderr, flush=True)


def progress_bar(total: int, off: bool):
    """A tqdm bar over the env steps, or None with --no-progress-bar."""
    if off:
        return None
    from tqdm import tqdm

    return tqdm(total=total, unit="step", unit_scale=True)


def show_progress(bar, steps: int, row: dict) -> None:
    if bar is not None:
        bar.update(steps)
        bar.set_postfix(
            success=f"{row['success_rate']:.2f}",
            ret=f"{row['mean_return']:.0f}",
            len=f"{row['mean_length']:.0f}",
        )


def train(args: argparse.Namespace, backend: str, cfg: Config) -> dict:
    """PPO on `backend` for args.timesteps env steps (whole updates): the model and
    observation statistics (the kept ones with Config.select_every; then `last` holds the
    last ones), the progress rows, wall seconds and env steps."""
    torch.manual_seed(args.seed)
    torch.set_num_threads(1)
    envs = make_envs(args.env, backend, cfg.num_envs)
    obs_size = envs.single_observation_space.shape[0]
    act_size = envs.single_action_space.shape[0]
    model = make_model(cfg, obs_size, act_size)
    max_steps = time_limit(cfg, args.env)
    optimiser = torch.optim.Adam(model.parameters(), lr=cfg.learning_rate, eps=1e-5)
    norm = RunningNorm(obs_size)
    if args.init is not None:
        start_from(args.init, model, norm)
    rng = np.random.default_rng(args.seed)
    rollout = Rollout(cfg, obs_size, act_size, max_steps)
    if cfg.separation_penalty > 0.0:
        layout = envs.observation_layout
        rollout.shaping = SeparationShaping(layout, cfg.separation_penalty, cfg.separation_radius)

    obs, _ = envs.reset(seed=args.seed)
    norm.update(obs)
    rows: list[dict] = []
    steps, start = 0, time.perf_counter()
    per_update = cfg.num_envs * cfg.rollout_steps
    updates = -(-args.timesteps // per_update)
    say(
        f"training {args.env} on the {backend} backend: {updates} updates of {cfg.num_envs} "
        f"envs x {cfg.rollout_steps} steps ({updates * per_update:,} env steps)"
    )
    bar = progress_bar(updates * per_update, args.no_progress_bar)
    selection = Selection(cfg, args.env, backend, updates)
    try:
        for k in range(updates):
            anneal_learning_rate(optimiser, cfg, k, updates)
            obs, ended = rollout.collect(envs, model, norm, obs)
            steps += per_update
            update(model, optimiser, cfg, rollout, rng)
            validation = selection.validate(k + 1, model, norm)
            wall = time.perf_counter() - start
            rows.append(progress_row(steps, wall, ended, validation, selection.active))
            show_progress(bar, per_update, rows[-1])
    finally:
        if bar is not None:
            bar.close()
        envs.close()
        selection.close()
    wall = time.perf_counter() - start
    run = dict(model=model, norm=norm, rows=rows, wall_s=wall, steps=steps, selected=None)
    if selection.best is not None:
        run.update(selection.kept(obs_size, act_size), last=(model, norm))
    return run


def update(model, optimiser, cfg: Config, rollout: Rollout, rng) -> None:
    """GAE over the rollout (episode ends break the chain; a truncation bootstraps from its
    final observation, which NEXT_STEP autoreset hands over on the ending step, unless
    rollout.term marks it terminal), then PPO's clipped objective over minibatches of the
    valid transitions. rollout.time (the time remaining per observation) is the critic's
    extra input."""
    obs_buf, act_buf, logp_buf, rew_buf = rollout.obs, rollout.act, rollout.logp, rollout.rew
    term_buf, done_buf, valid_buf, time_buf = (
        rollout.term,
        rollout.done,
        rollout.valid,
        rollout.time,
    )
    t_len, n = rew_buf.shape
    critic_buf = obs_buf if time_buf is None else np.concatenate([obs_buf, time_buf[..., None]], -1)
    with torch.no_grad():
        flat = torch.as_tensor(critic_buf.reshape(-1, critic_buf.shape[-1]))
        values = model.value(flat).reshape(t_len + 1, n)
    values = values.numpy()
    advantages = np.zeros((t_len, n), np.float32)
    last = np.zeros(n, np.float32)
    for t in reversed(range(t_len)):
        bootstrap = values[t + 1] * ~term_buf[t]
        delta = rew_buf[t] + cfg.gamma * bootstrap - values[t]
        last = delta + cfg.gamma * cfg.gae_lambda * ~done_buf[t] * last
        last = np.where(valid_buf[t], last, 0.0)
        advantages[t] = last
    returns = advantages + values[:t_len]
    keep = valid_buf.reshape(-1)
    obs = torch.as_tensor(obs_buf[:t_len].reshape(-1, obs_buf.shape[-1])[keep])
    critic_obs = torch.as_tensor(critic_buf[:t_len].reshape(-1, critic_buf.shape[-1])[keep])
    act = torch.as_tensor(act_buf.reshape(-1, act_buf.shape[-1])[keep])
    old_logp = torch.as_tensor(logp_buf.reshape(-1)[keep])
    adv = torch.as_tensor(advantages.reshape(-1)[keep])
    ret = torch.as_tensor(returns.reshape(-1)[keep])
    size = obs.shape[0]
    batch = -(-size // cfg.minibatches)
    for _ in range(cfg.epochs):
        order = torch.as_tensor(rng.permutation(size))
        for k in range(0, size, batch):
            idx = order[k : k + batch]
            d = model.dist(obs[idx])
            ratio = (d.log_prob(act[idx]).sum(-1) - old_logp[idx]).exp()
            a = adv[idx]
            a = (a - a.mean()) / (a.std() + 1e-8)
            policy_loss = -torch.min(ratio * a, ratio.clamp(1 - cfg.clip, 1 + cfg.clip) * a).mean()
            value_loss = (model.value(critic_obs[idx]).squeeze(-1) - ret[idx]).pow(2).mean()
            loss = policy_loss + cfg.value_coef * value_loss
            optimiser.zero_grad()
            loss.backward()
            nn.utils.clip_grad_norm_(model.parameters(), cfg.max_grad_norm)
            optimiser.step()


# Wide and light under narrow: against env steps the two backends' curves are one (the
# same episodes bit for bit), and both stay visible.
STYLES = {
    "native": dict(color="tab:green", lw=4, alpha=0.6),
    "sitl": dict(color="tab:blue", lw=1.5),
}
VALIDATION_COLORS = {"native": "darkgreen", "sitl": "navy"}


def plot(runs: dict[str, list[dict]], path: Path, title: str) -> None:
    """Training success rate per update against env steps and wall seconds, one line per
    backend, and the validation success rate where the run validated its policy."""
    from matplotlib.figure import Figure

    fig = Figure(figsize=(9, 3.6), layout="constrained")
    left, right = fig.subplots(1, 2, sharey=True)
    for backend, rows in runs.items():
        rate = [100 * r["success_rate"] for r in rows]
        style = dict(STYLES[backend], label=f"{backend} backend")
        left.plot([r["env_steps"] for r in rows], rate, **style)
        right.plot([r["wall_s"] for r in rows], rate, **style)
        checked = [r for r in rows if r.get("validation_success_rate") is not None]
        if checked:
            # The deterministic policy on the validation episodes (Config.select_every).
            marks = dict(color=VALIDATION_COLORS[backend], marker="o", ms=3, lw=0.8)
            marks["label"] = f"{backend}: validation (deterministic)"
            valid = [100 * r["validation_success_rate"] for r in checked]
            left.plot([r["env_steps"] for r in checked], valid, **marks)
            right.plot([r["wall_s"] for r in checked], valid, **marks)
    left.set_xlabel("env steps")
    left.set_ylabel("success, % of training episodes")
    right.set_xlabel("wall seconds")
    for ax in (left, right):
        ax.axhline(90, ls="--", color="grey", lw=1)
        ax.grid(alpha=0.3)
    right.legend(loc="lower right")
    fig.suptitle(title)
    fig.savefig(path, dpi=100)


def summarise(args: argparse.Namespace, backend: str, cfg: Config, run: dict, cpu: float) -> dict:
    """summary.json without the held-out evaluation: the run's settings and figures."""
    rows, wall, steps = run["rows"], run["wall_s"], run["steps"]
    p = preset(TASKS[args.env].preset)
    return dict(
        env=p.name,
        env_id=p.env_id,
        env_kwargs=dict(p.env_kwargs),
        algo="fast_ppo",
        # The policy's [-1, 1] outputs: the hover preset's rescaled motor commands, the
        # lander's own motor commands.
        action=p.default_action,
        backend=backend,
        seed=args.seed,
        # The run this one went on from (--init), or None.
        init=None if args.init is None else str(args.init),
        config=asdict(cfg),
        env_steps=steps,
        wall_time_s=wall,
        # This process's CPU seconds while training (learner and env threads).
        cpu_time_s=cpu,
        env_steps_per_s=steps / wall,
        first_update_at_90_percent=next((r for r in rows if r["success_rate"] >= 0.9), None),
        last_training_success_rate=rows[-1]["success_rate"],
        # The policy kept (Config.select_every), or None: the last one.
        selected_policy=run["selected"],
    )


def joined(earlier: dict, later: dict) -> dict:
    """The summary of a run that went on from `earlier` (--init) as one training: the
    earlier rows first and the later ones after them (env steps and wall seconds counted on),
    env steps, wall and CPU seconds summed, the first update at 90 % over both; the rest
    (the held-out evaluation, `init`) is the later run's."""
    steps, wall = earlier["env_steps"], earlier["wall_time_s"]
    rows = earlier["rows"] + [
        {**r, "env_steps": r["env_steps"] + steps, "wall_s": round(r["wall_s"] + wall, 3)}
        for r in later["rows"]
    ]
    total_steps, total_wall = steps + later["env_steps"], wall + later["wall_time_s"]
    return {
        **later,
        "rows": rows,
        "env_steps": total_steps,
        "wall_time_s": total_wall,
        "cpu_time_s": earlier["cpu_time_s"] + later["cpu_time_s"],
        "env_steps_per_s": total_steps / total_wall,
        "first_update_at_90_percent": next((r for r in rows if r["success_rate"] >= 0.9), None),
        # The earlier run's own settings (its seed, config, env steps).
        "earlier": {k: earlier.get(k) for k in ("seed", "config", "env_steps", "init")},
    }


def save(out: Path, run: dict, summary: dict) -> None:
    """The backend's folder: progress.csv, policy.pt and summary.json."""
    rows = run["rows"]
    out.mkdir(parents=True, exist_ok=True)
    with open(out / "progress.csv", "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)
    state = {"model": run["model"].state_dict(), "obs_mean": run["norm"].mean}
    torch.save({**state, "obs_var": run["norm"].var}, out / "policy.pt")
    (out / "summary.json").write_text(json.dumps(summary, indent=2) + "\n")


def report(task: str, summary: dict) -> None:
    """The run in a few lines on stdout."""
    steps, wall, cpu = summary["env_steps"], summary["wall_time_s"], summary["cpu_time_s"]
    first, selected = summary["first_update_at_90_percent"], summary["selected_policy"]
    result = summary["evaluation"]
    name = summary["env_id"].split("/")[-1]
    print(
        f"PPO on {name} ({task}, {summary['backend']}, {summary['config']['num_envs']} envs): "
        f"{steps:,} env steps in {wall:.1f} s, {cpu:.1f} s CPU ({steps / wall:,.0f} env steps/s "
        "incl. learning)"
    )
    if first is not None:
        print(
            f"  training success >= 90 % first after {first['env_steps']:,} env steps, "
            f"{first['wall_s']:.1f} s"
        )
    else:
        print("  training success never reached 90 %")
    if selected is not None:
        last = selected["last_policy_evaluation"]
        print(
            f"  kept the policy of update {selected['update']} ({selected['env_steps']:,} env "
            f"steps): validation {100 * selected['validation_success_rate']:.1f} %; the last "
            f"policy's held-out success {100 * last['success_rate']:.1f} %"
        )
    print(
        f"  held-out evaluation ({result['episodes']} episodes, seeds {result['seed']}..): "
        f"success {100 * result['success_rate']:.1f} %, mean return {result['mean_return']:.1f}"
    )


def run_one(args: argparse.Namespace, backend: str, cfg: Config) -> dict:
    """Trains and evaluates on one backend; writes its folder; returns its summary."""
    cpu_start = time.process_time()
    run = train(args, backend, cfg)
    cpu = time.process_time() - cpu_start
    say(f"evaluating the policy on {args.eval_episodes} held-out episodes ({backend})")
    result = evaluate(run["model"], run["norm"], args.env, backend, args.eval_episodes)
    if run["selected"] is not None:
        # What keeping the best policy gained: the last policy on the same held-out episodes.
        run["selected"]["last_policy_evaluation"] = evaluate(
            *run["last"], args.env, backend, args.eval_episodes
        )
    summary = summarise(args, backend, cfg, run, cpu)
    summary.update(evaluation=result, rows=run["rows"])
    if args.init is not None:
        summary = joined(json.loads((args.init / "summary.json").read_text()), summary)
        run["rows"] = summary["rows"]
    save(args.out / backend, run, summary)
    report(args.env, summary)
    return summary


def configure(task: Task, num_envs: int | None, settings: list[str]) -> Config:
    """The task's configuration with --num-envs and --set KEY=VALUE applied."""
    cfg = task.config
    fields = asdict(cfg)
    changes = {} if num_envs is None else {"num_envs": num_envs}
    for setting in settings:
        key, _, value = setting.partition("=")
        if key not in fields or not value:
            raise ValueError(f"--set {setting!r}: expected KEY=VALUE, KEY one of {list(fields)}")
        kind = type(fields[key])
        if kind is bool:
            if value not in ("True", "False"):
                raise ValueError(f"--set {setting!r}: {key} is True or False")
            changes[key] = value == "True"
        else:
            changes[key] = kind(value)
    return replace(cfg, **changes)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--env", default="hover", choices=sorted(TASKS), help="the task")
    parser.add_argument(
        "--backend",
        nargs="+",
        default=["native"],
        choices=("native", "sitl"),
        help="one or both (trained one after the other with the same seed, side by side)",
    )
    parser.add_argument(
        "--timesteps", type=int, help="env steps to train for (default: the task's)"
    )
    parser.add_argument("--num-envs", type=int, help="default: the task's")
    parser.add_argument(
        "--set",
        action="append",
        default=[],
        metavar="KEY=VALUE",
        help="override one of the task's PPO settings (Config), e.g. --set epochs=4",
    )
    parser.add_argument(
        "--frame",
        default="quad_x",
        choices=("quad_x", *FRAMES),
        help="the multirotor of --env hover (the core's rotor tables; default the quad X)",
    )
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument(
        "--init",
        type=Path,
        help="go on from an earlier run's OUT/BACKEND folder (its policy.pt: weights and "
        "observation statistics)",
    )
    parser.add_argument("--eval-episodes", type=int, help="default: the task's")
    parser.add_argument("--out", type=Path, default=Path("runs/fast_ppo"))
    parser.add_argument("--curve", type=Path, help="also draw the learning curve to this file")
    parser.add_argument("--no-progress-bar", action="store_true")
    args = parser.parse_args(argv)
    if args.frame != "quad_x":
        if args.env != "hover":
            parser.error(f"--frame {args.frame} flies --env hover only")
        args.env = f"hover_{args.frame}"
    task = TASKS[args.env]
    if args.timesteps is None:
        args.timesteps = task.timesteps
    if args.eval_episodes is None:
        args.eval_episodes = task.eval_episodes
    if args.timesteps <= 0 or args.eval_episodes < 1 or (args.num_envs or 1) < 1:
        parser.error("--timesteps, --num-envs and --eval-episodes must be positive")
    try:
        cfg = configure(task, args.num_envs, args.set)
    except ValueError as exc:
        parser.error(str(exc))
    runs = {backend: run_one(args, backend, cfg) for backend in dict.fromkeys(args.backend)}
    title = f"{task.title}, {cfg.num_envs} envs, seed {args.seed}"
    for path in (args.out / "learning_curve.png", args.curve):
        if path is not None:
            say(f"drawing the learning curve to {path}")
            path.parent.mkdir(parents=True, exist_ok=True)
            plot({b: s["rows"] for b, s in runs.items()}, path, title)
    return 0


if __name__ == "__main__":
    sys.exit(main())
