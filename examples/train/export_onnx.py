"""Exports a fast_ppo.py hover policy (motor actions) for Policy.fmu: POLICY_DIR/model.onnx
(the actor's mean, torch.onnx) and POLICY_DIR/recipe.json (how the FMU builds the network's
input from the plant's outputs and turns its output into motor commands).

    .venv/bin/python examples/train/export_onnx.py policies/hexa_hover
    target/release/flyloop-fmu-pack policy policies/hexa_hover -o dist/fmu/HexaHoverPolicy.fmu

The recipe ("hover-motors", docs/fmu.md#policyfmu-a-trained-policy-as-an-fmu) is the gym's
QuadHover motor interface as evaluate.py flies it:
1. the observation: target - position (world ENU), velocity, acceleration, attitude
   quaternion (hemisphere w >= 0), body rates, angular acceleration (body FLU), body z axis,
   wind, motor states, the previous motor commands; each value rounded to float32 and clipped
   into the env's observation bounds (`observation_low/high`);
2. normalisation in float64: (o - mean) / sqrt(var + epsilon), clipped into +-clip, then
   float32 (fast_ppo.py's RunningNorm);
3. the network (float32): the actor's mean, with the action basis folded in;
4. the action clipped into +-1 (float32) and mapped to the env's motor commands by
   gymnasium's RescaleAction: (a - intercept) / gradient in float32.

A train_offboard.py rates policy (policy.json with interface "px4-rates-v1", e.g.
policies/px4_offboard_hover) exports with the recipe "rates-estimate": the gym's rates
interface observation (target - position and velocity in the heading frame, the body's down
axis, body rates FRD, the previous setpoint: 16 values) built from the plant's true state
(the estimate an FMU system has), the same normalisation, the actor's mean, and fast_ppo.py's
map to the setpoint, low + (a + 1) * 0.5 * (high - low) in float32 ("bounds").
"""

from __future__ import annotations

import argparse
import json
import warnings
from pathlib import Path

import numpy as np

RECIPE_FORMAT = "flyloop-policy-recipe/1"


def write_onnx(actor, size: int, folder: Path) -> None:
    """folder/model.onnx: `actor` (torch) from one observation row of `size` to the action."""
    import torch

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DeprecationWarning)
        torch.onnx.export(
            actor.eval(),
            (torch.zeros(1, size),),
            str(folder / "model.onnx"),
            dynamo=False,
            input_names=["observation"],
            output_names=["action"],
        )


def write_recipe(folder: Path, recipe: dict) -> dict:
    recipe = {"format": RECIPE_FORMAT, **recipe, "network": "model.onnx"}
    (folder / "recipe.json").write_text(json.dumps(recipe, indent=1) + "\n")
    return recipe


def export_rates(folder: Path, meta: dict) -> dict:
    """A train_offboard.py policy (policy.pt, policy.json): the "rates-estimate" recipe."""
    import fast_ppo
    import torch
    from training_envs import make_env

    saved = torch.load(folder / "policy.pt", weights_only=False)
    state = saved["model"]
    size, actions = state["mu.0.weight"].shape[1], state["log_std"].shape[0]
    model = fast_ppo.ActorCritic(size, actions, meta["training"]["config"]["hidden"])
    model.load_state_dict(state)
    # The env the policy flies, nominal (its bounds do not depend on the randomisation).
    env = make_env("offboard", overrides=dict(randomize=None, observation_noise=None))
    try:
        layout = env.unwrapped.core["observation"]
        low, high = env.observation_space.low, env.observation_space.high
        action_low, action_high = env.action_space.low, env.action_space.high
        dt = float(env.unwrapped.dt)
    finally:
        env.close()
    if low.shape[0] != size:
        raise ValueError(f"{folder}/policy.pt: takes {size} values, the env observes {len(low)}")
    write_onnx(model.mu, size, folder)
    return write_recipe(
        folder,
        {
            "observation": "rates-estimate",
            "layout": [[name, n] for name, n in layout],
            "sample_period": dt,
            "observation_low": low.astype(float).tolist(),
            "observation_high": high.astype(float).tolist(),
            "observation_mean": np.asarray(saved["obs_mean"], np.float64).tolist(),
            "observation_var": np.asarray(saved["obs_var"], np.float64).tolist(),
            "normalisation_epsilon": 1e-8,
            "normalisation_clip": 10.0,
            "action_clip": 1.0,
            "action_map": "bounds",
            "action_low": action_low.astype(float).tolist(),
            "action_high": action_high.astype(float).tolist(),
            "source": f"{folder.name}: {meta['interface']} {meta['training']['env_kwargs']}",
        },
    )


def export(folder: Path) -> dict:
    """Writes folder/model.onnx and folder/recipe.json; returns the recipe."""
    meta_path = folder / "policy.json"
    if meta_path.is_file():
        meta = json.loads(meta_path.read_text())
        if meta.get("interface") != "px4-rates-v1":
            raise ValueError(f"{meta_path}: interface {meta.get('interface')!r} does not export")
        return export_rates(folder, meta)
    import torch
    from evaluate import SavedRun
    from gymnasium.wrappers.utils import rescale_box
    from training_envs import make_env

    run = SavedRun(folder)
    summary = run.summary
    if summary.get("algo") != "fast_ppo" or run.preset.env_id != "flyloop/QuadHover-v0":
        raise ValueError(f"{folder}: only fast_ppo.py QuadHover policies export (summary.json)")
    action = summary.get("action", "motors")
    if action != "motors":
        raise ValueError(f"{folder}/summary.json: action {action!r} is not 'motors'")
    env = make_env(run.preset.name, action=action)
    try:
        base_space = env.env.action_space
        unit = np.ones(base_space.shape, np.float32)
        _, forward, _ = rescale_box(base_space, -unit, unit)
        # backward(a) = (a - intercept) / gradient, with forward(o) = gradient * o + intercept.
        intercept = forward(np.zeros(base_space.shape, np.float32))
        gradient = forward(np.ones(base_space.shape, np.float32)) - intercept
        layout = env.unwrapped.core["observation"]
        low, high = env.observation_space.low, env.observation_space.high
        dt = float(env.unwrapped.dt)
    finally:
        env.close()
    model = run.model
    size = low.shape[0]

    class Actor(torch.nn.Module):
        """The actor's mean in the env's action coordinates (the basis folded in)."""

        def __init__(self) -> None:
            super().__init__()
            self.mu = model.mu
            basis = np.eye(len(unit)) if model.basis is None else model.basis
            self.register_buffer("basis_t", torch.as_tensor(basis.T, dtype=torch.float32))

        def forward(self, observation: torch.Tensor) -> torch.Tensor:
            mean = self.mu(observation)
            return mean if model.basis is None else mean @ self.basis_t

    write_onnx(Actor(), size, folder)
    return write_recipe(
        folder,
        {
            "observation": "hover-motors",
            "layout": [[name, n] for name, n in layout],
            "rotors": len(unit),
            "sample_period": dt,
            "observation_low": low.astype(float).tolist(),
            "observation_high": high.astype(float).tolist(),
            "observation_mean": np.asarray(run.norm.mean, np.float64).tolist(),
            "observation_var": np.asarray(run.norm.var, np.float64).tolist(),
            "normalisation_epsilon": 1e-8,
            "normalisation_clip": 10.0,
            "action_clip": 1.0,
            "action_gradient": gradient.astype(float).tolist(),
            "action_intercept": intercept.astype(float).tolist(),
            "source": f"{folder.name}: {summary.get('env_id')} {summary.get('env_kwargs')}",
        },
    )


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument(
        "policy", type=Path, help="a fast_ppo.py QuadHover or train_offboard.py output folder"
    )
    args = parser.parse_args(argv)
    recipe = export(args.policy)
    print(f"{args.policy}/model.onnx, recipe.json: {len(recipe['observation_low'])} inputs")


if __name__ == "__main__":
    main()
