"""Episode recording: GIF and MP4 files read back frame by frame, record_episode on a gym
env, and gymnasium's RecordVideo wrapper over an env that renders with the views."""

import gymnasium as gym
import imageio_ffmpeg
import numpy as np
import pytest
from PIL import Image

from flyloop.rendering import (
    LanderScene,
    LanderView,
    QuadrotorView,
    QuadScene,
    record_episode,
    save_video,
)


class DriftingLander(gym.Env):
    """The smallest env with a LanderView: the drone drifts right by the action each step."""

    metadata = {"render_modes": ["rgb_array"], "render_fps": 20}

    def __init__(self, render_mode="rgb_array", steps=12):
        self.render_mode = render_mode
        self.action_space = gym.spaces.Box(-1.0, 1.0, (2,), np.float32)
        self.observation_space = gym.spaces.Box(-100.0, 100.0, (2,), np.float32)
        self.steps = steps
        self.view = LanderView(render_mode, width=320, height=240)

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        self.t, self.x = 0, 20.0
        self.view.reset()
        return np.array([self.x, 30.0], np.float32), {}

    def step(self, action):
        self.t += 1
        self.x += 0.5 + float(action[0])
        done = self.t >= self.steps
        return np.array([self.x, 30.0], np.float32), 1.0, False, done, {}

    def render(self):
        return self.view.render(
            LanderScene(
                time_s=self.t * 0.05,
                step=self.t,
                position=(self.x, 30.0),
                velocity=(1.0, 0.0),
                angle=0.0,
                angular_velocity=0.0,
                thrust=(7.0, 7.0),
                battery=100.0,
                platform_x=25.0,
            )
        )

    def close(self):
        self.view.close()


def quad_frames(n=6, size=(161, 121)):
    view = QuadrotorView("rgb_array", width=size[0], height=size[1], hud=False)
    frames = []
    for i in range(n):
        frames.append(
            view.render(
                QuadScene(
                    time_s=i * 0.1,
                    step=i,
                    position=(0.3 * i - 1.0, 0.0, 1.5),
                    velocity=(3.0, 0, 0),
                    quaternion=(1, 0, 0, 0),
                )
            )
        )
    view.close()
    return frames


def test_gif_holds_every_frame_at_the_rate(tmp_path):
    frames = quad_frames()
    path = save_video(frames, tmp_path / "out" / "episode.gif", fps=20)
    with Image.open(path) as gif:
        assert gif.n_frames == len(frames)
        assert gif.size == (161, 121)
        assert gif.info["duration"] == 50
        gif.seek(len(frames) - 1)
        last = np.asarray(gif.convert("RGB"), dtype=float)
    # GIF quantises to 256 colours: close to the source, not equal.
    assert np.abs(last - frames[-1]).mean() < 6.0


def test_mp4_decodes_to_the_frames_even_with_odd_sizes(tmp_path):
    frames = quad_frames(n=8)
    path = save_video(frames, tmp_path / "episode.mp4", fps=25)
    reader = imageio_ffmpeg.read_frames(str(path))
    meta = reader.__next__()
    decoded = [np.frombuffer(b, np.uint8).reshape(122, 162, 3) for b in reader]
    assert meta["size"] == (162, 122)  # padded by one edge pixel to even sides
    assert meta["fps"] == pytest.approx(25)
    assert len(decoded) == len(frames)
    for got, want in zip(decoded, frames, strict=True):
        assert np.abs(got[:121, :161].astype(float) - want).mean() < 8.0
    # The video keeps the order: where the drone moved, its last frame matches the last
    # rendered frame far better than the first one.
    moved = np.abs(frames[-1].astype(float) - frames[0]).sum(axis=-1) > 60
    last = decoded[-1][:121, :161].astype(float)
    assert moved.sum() > 100
    assert np.abs(last - frames[-1])[moved].mean() < 0.3 * np.abs(last - frames[0])[moved].mean()


def test_bad_input_is_refused_before_writing(tmp_path):
    frames = quad_frames(n=2)
    with pytest.raises(ValueError, match="no frames"):
        save_video([], tmp_path / "a.gif")
    with pytest.raises(ValueError, match="unsupported file type '.png'"):
        save_video(frames, tmp_path / "a.png")
    with pytest.raises(ValueError, match=r"frame 1 is \(10, 10, 3\)"):
        save_video([frames[0], np.zeros((10, 10, 3), np.uint8)], tmp_path / "a.gif")
    with pytest.raises(ValueError, match="uint8"):
        save_video([frames[0].astype(np.float32)], tmp_path / "a.gif")
    with pytest.raises(ValueError, match="fps"):
        save_video(frames, tmp_path / "a.gif", fps=0)
    assert not list(tmp_path.iterdir())


def test_record_episode_saves_one_frame_per_step(tmp_path):
    env = DriftingLander(steps=12)
    rec = record_episode(env, tmp_path / "lander.gif", policy=lambda obs: np.zeros(2), seed=3)
    env.close()
    assert (rec.frames, rec.steps, rec.total_reward) == (13, 12, 12.0)
    with Image.open(rec.path) as gif:
        assert gif.n_frames == 13
        assert gif.info["duration"] == 50  # the env's render_fps (20)
    with pytest.raises(ValueError, match="render_mode='rgb_array'"):
        record_episode(gym.make("CartPole-v1"), tmp_path / "x.gif")


def test_gymnasium_record_video_works_with_a_view_backed_env(tmp_path):
    env = gym.wrappers.RecordVideo(
        DriftingLander(steps=10),
        str(tmp_path / "videos"),
        episode_trigger=lambda e: True,
        name_prefix="ep",
    )
    env.reset(seed=0)
    done = False
    while not done:
        _, _, terminated, truncated, _ = env.step(np.zeros(2, np.float32))
        done = terminated or truncated
    env.close()
    videos = sorted((tmp_path / "videos").glob("ep-episode-0.mp4"))
    assert len(videos) == 1
    reader = imageio_ffmpeg.read_frames(str(videos[0]))
    meta = reader.__next__()
    assert meta["size"] == (320, 240)
    # 11 frames are captured (reset + 10 steps); moviepy's writer may drop the last one.
    assert sum(1 for _ in reader) in (10, 11)
