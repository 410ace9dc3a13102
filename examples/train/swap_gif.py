"""A GIF of a fast_ppo.py swap policy flying one held-out Swap world: the four agents from
above (each with its target) and their heights, frame by frame.

    .venv/bin/python examples/train/swap_gif.py runs/swap_fast/native --seed 1000000 \\
        --out docs/img/swap_fast_ppo.gif

Prints the episode's outcome (all swapped places, or which agents collided or crashed).
"""

from __future__ import annotations

import argparse
import io
import json
from pathlib import Path

import flyloop
import matplotlib
import numpy as np
import torch
from fast_ppo import ActorCritic, RunningNorm, to_env
from PIL import Image

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

COLOURS = ["tab:blue", "tab:orange", "tab:green", "tab:red", "tab:purple", "tab:brown"]


def load(folder: Path):
    summary = json.loads((folder / "summary.json").read_text())
    saved = torch.load(folder / "policy.pt", weights_only=False)
    state = saved["model"]
    obs_size, act_size = state["mu.0.weight"].shape[1], state["log_std"].shape[0]
    model = ActorCritic(obs_size, act_size, summary["config"]["hidden"])
    model.load_state_dict(state)
    model.eval()
    norm = RunningNorm(obs_size)
    norm.mean, norm.var = saved["obs_mean"], saved["obs_var"]
    return summary, model, norm


def frame(track, targets, t, radius) -> Image.Image:
    fig, (top, side) = plt.subplots(1, 2, figsize=(8, 4), dpi=60)
    lim = radius + 1.0
    for i in range(track.shape[1]):
        c = COLOURS[i % len(COLOURS)]
        top.plot(track[: t + 1, i, 0], track[: t + 1, i, 1], color=c, lw=1)
        top.plot(*track[t, i, :2], "o", color=c, ms=8)
        top.plot(*targets[i, :2], "x", color=c, ms=10)
        side.plot(np.arange(t + 1) * 0.02, track[: t + 1, i, 2], color=c)
    top.set(xlim=(-lim, lim), ylim=(-lim, lim), aspect="equal", title="from above (m)")
    side.set(xlim=(0, len(track) * 0.02), ylim=(0, 3), title="height (m) against time (s)")
    fig.tight_layout()
    buf = io.BytesIO()
    fig.savefig(buf, format="png")
    plt.close(fig)
    return Image.open(buf).convert("P", palette=Image.Palette.ADAPTIVE)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("folder", type=Path, help="a fast_ppo.py swap run's OUT/native")
    parser.add_argument("--seed", type=int, default=1_000_000)
    parser.add_argument("--out", type=Path, default=Path("runs/swap.gif"))
    parser.add_argument("--every", type=int, default=5, help="steps per frame")
    args = parser.parse_args()
    summary, model, norm = load(args.folder)
    env = flyloop.parallel_env(summary["env_id"], **summary["env_kwargs"])
    space = env.action_space("drone_0")
    obs, _ = env.reset(seed=args.seed)
    positions, targets = env.positions()
    track = [positions]
    info = {}
    while env.agents:
        batch = np.stack([obs[a] for a in env.agents])
        with torch.no_grad():
            mean = model.mu(torch.as_tensor(norm(batch))).numpy()
        actions = dict(zip(env.agents, to_env(mean, space), strict=True))
        obs, _, _, _, info = env.step(actions)
        track.append(env.positions()[0])
    track = np.array(track)
    last = next(iter(info.values()))
    outcome = "all swapped places" if last["success"] else "the swap failed"
    hits = [a for a, i in info.items() if i["collisions"] or i["crashed"]]
    print(f"seed {args.seed}: {len(track) - 1} steps, {outcome}" + (f" ({hits})" if hits else ""))
    radius = float(np.linalg.norm(track[0, 0, :2]))
    frames = [frame(track, targets, t, radius) for t in range(0, len(track), args.every)]
    args.out.parent.mkdir(parents=True, exist_ok=True)
    frames[0].save(args.out, save_all=True, append_images=frames[1:], duration=100, loop=0)
    print(f"wrote {args.out} ({len(frames)} frames)")


if __name__ == "__main__":
    main()
