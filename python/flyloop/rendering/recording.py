"""Save rgb_array frames as a GIF (Pillow) or a video (imageio-ffmpeg's ffmpeg); unlike
gymnasium's `RecordVideo` wrapper, which also works with flyloop's envs, without moviepy."""

from __future__ import annotations

from collections.abc import Callable, Iterable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

VIDEO_SUFFIXES = (".mp4", ".mkv", ".mov", ".avi", ".webm")


def save_video(frames: Iterable[np.ndarray], path: str | Path, fps: float = 30.0) -> Path:
    """Write frames ((H, W, 3) uint8, all one size) to path; the suffix picks the format:
    .gif (Pillow) or .mp4/.mkv/.mov/.avi/.webm (imageio-ffmpeg's bundled ffmpeg)."""
    if not fps > 0:
        raise ValueError(f"fps must be > 0, got {fps}")
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix != ".gif" and suffix not in VIDEO_SUFFIXES:
        raise ValueError(f"unsupported file type {suffix!r}: use .gif or one of {VIDEO_SUFFIXES}")
    frames = [np.asarray(f) for f in frames]
    if not frames:
        raise ValueError("no frames to save")
    for i, f in enumerate(frames):
        if f.ndim != 3 or f.shape[2] != 3 or f.dtype != np.uint8:
            raise ValueError(f"frame {i} must be (H, W, 3) uint8, got {f.shape} {f.dtype}")
        if f.shape != frames[0].shape:
            raise ValueError(f"frame {i} is {f.shape}, the first frame is {frames[0].shape}")
    path.parent.mkdir(parents=True, exist_ok=True)
    (_save_gif if suffix == ".gif" else _save_ffmpeg)(frames, path, fps)
    return path


def _save_gif(frames: list[np.ndarray], path: Path, fps: float, colors: int = 128) -> None:
    """A looping GIF with ONE palette from a sample of the frames: Pillow then stores each
    frame as its change from the last (a few kB, against ~50 kB with a palette per frame)."""
    from PIL import Image  # the "render" extra's, as pygame

    images = [Image.fromarray(f) for f in frames]
    sample = images[:: max(1, len(images) // 10)]
    width, height = images[0].size
    sheet = Image.new("RGB", (width, height * len(sample)))
    for i, image in enumerate(sample):
        sheet.paste(image, (0, height * i))
    palette = sheet.quantize(colors=colors, method=Image.Quantize.MAXCOVERAGE)
    quantized = [im.quantize(palette=palette, dither=Image.Dither.NONE) for im in images]
    # GIF delays are in 1/100 s, so rates above 50 fps cannot be shown faithfully.
    duration_ms = max(20, round(1000.0 / fps))
    quantized[0].save(
        path,
        save_all=True,
        append_images=quantized[1:],
        duration=duration_ms,
        loop=0,
        optimize=True,
    )


def _save_ffmpeg(frames: list[np.ndarray], path: Path, fps: float) -> None:
    try:
        import imageio_ffmpeg
    except ImportError as exc:
        raise ImportError(
            f"saving {path.suffix} needs imageio-ffmpeg (it bundles ffmpeg): "
            "pip install imageio-ffmpeg, or save a .gif"
        ) from exc
    height, width = frames[0].shape[:2]
    # H.264 in yuv420p needs even sides: pad by one edge pixel rather than rescale.
    pad_h, pad_w = height % 2, width % 2
    size = (width + pad_w, height + pad_h)
    writer = imageio_ffmpeg.write_frames(
        str(path), size, fps=fps, macro_block_size=1, ffmpeg_log_level="error"
    )
    writer.send(None)
    try:
        for f in frames:
            if pad_h or pad_w:
                f = np.pad(f, ((0, pad_h), (0, pad_w), (0, 0)), mode="edge")
            writer.send(np.ascontiguousarray(f))
    finally:
        writer.close()


@dataclass(frozen=True)
class Recording:
    """What record_episode saved: where, how many frames and steps, and the episode's return."""

    path: Path
    frames: int
    steps: int
    total_reward: float


def record_episode(
    env: Any,
    path: str | Path,
    policy: Callable[[Any], Any] | None = None,
    *,
    seed: int | None = None,
    max_steps: int | None = None,
    fps: float | None = None,
) -> Recording:
    """Run one episode of a gymnasium env made with render_mode="rgb_array" and save a frame
    after reset and one per step. policy(observation) -> action (random when None); fps: the
    env's metadata["render_fps"] (30 if absent) unless given."""
    if (mode := getattr(env, "render_mode", None)) != "rgb_array":
        raise ValueError(f"record_episode needs an env made with render_mode='rgb_array': {mode!r}")
    rate = fps if fps is not None else float(env.metadata.get("render_fps") or 30)
    observation, _ = env.reset(seed=seed)
    frames = [env.render()]
    steps, total = 0, 0.0
    while max_steps is None or steps < max_steps:
        action = policy(observation) if policy is not None else env.action_space.sample()
        observation, reward, terminated, truncated, _ = env.step(action)
        frames.append(env.render())
        steps += 1
        total += float(reward)
        if terminated or truncated:
            break
    return Recording(save_video(frames, path, rate), len(frames), steps, total)
