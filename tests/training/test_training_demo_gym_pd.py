"""examples/demo_gym_pd.py: the scripted PD controller flies QuadHover through the gym env
and the real SITL, holds the target, and the demo writes its GIF."""

from __future__ import annotations

import demo_gym_pd
import numpy as np
from PIL import Image


def test_pd_controller_holds_the_target_in_wind(sitl_binary):
    # Seed 3: target 1.2 m away, default wind (mean 0–5 m/s plus turbulence).
    flight = demo_gym_pd.fly(seed=3, seconds=6.0)
    d = flight["distances"]
    assert flight["truncated"] and not flight["terminated"]
    assert len(d) == 600
    assert d[0] > 1.0
    # From 3 s on, the vehicle stays within 0.3 m of the target (measured: at most 0.16 m).
    assert d[300:].max() < 0.3, d[300:].max()
    assert flight["episode_return"] > 400  # measured 459 (600 steps, reward ≤ 1 each)


def test_pd_controller_converges_without_wind(sitl_binary):
    flights = [
        demo_gym_pd.fly(seed=s, seconds=6.0, use_wind=False, frame_every=600) for s in (0, 1)
    ]
    for flight in flights:
        d = flight["distances"]
        assert flight["truncated"]
        assert d[0] >= 0.9  # targets are drawn at least 1 m from the start
        assert d[-1] < 0.05, d[-1]


def test_demo_writes_the_gif(sitl_binary, tmp_path, capsys):
    gif = tmp_path / "demo.gif"
    assert demo_gym_pd.main(["--seed", "3", "--seconds", "2", "--out", str(gif)]) == 0
    out = capsys.readouterr().out
    assert "time limit reached after 200 steps" in out
    image = Image.open(gif)
    assert image.size == (480, 360)
    assert image.n_frames == 50  # one frame every 4 steps of 10 ms: 25 fps
    # The frames differ: the vehicle moves toward the target.
    image.seek(0)
    first = np.asarray(image.convert("RGB"), dtype=np.int16)
    image.seek(image.n_frames - 1)
    last = np.asarray(image.convert("RGB"), dtype=np.int16)
    assert np.abs(first - last).sum(axis=2).astype(bool).mean() > 0.001


def test_euler_angles_of_known_rotations():
    half = np.sqrt(0.5)
    assert np.allclose(demo_gym_pd.euler_from_quaternion(1, 0, 0, 0), (0, 0, 0))
    # 90° about z (yaw), about x (roll), about y (pitch).
    assert np.allclose(demo_gym_pd.euler_from_quaternion(half, 0, 0, half), (0, 0, np.pi / 2))
    assert np.allclose(demo_gym_pd.euler_from_quaternion(half, half, 0, 0), (np.pi / 2, 0, 0))
    assert np.allclose(
        demo_gym_pd.euler_from_quaternion(0.9238795, 0, 0.3826834, 0), (0, np.pi / 4, 0)
    )
