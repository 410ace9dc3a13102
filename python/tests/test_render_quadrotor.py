"""QuadrotorView in rgb_array mode: frame format, and key elements drawn where the state says
(pixel centroids of the hub and target colours against the camera projection)."""

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import flyloop
from flyloop.rendering import OrbitCamera, QuadrotorView, QuadScene
from flyloop.rendering import quadrotor as qw
from flyloop.rendering.quadrotor import info_lines


def scene(**over):
    base = dict(
        time_s=1.0,
        step=100,
        position=(0.0, 0.0, 1.5),
        velocity=(0.0, 0.0, 0.0),
        quaternion=(1.0, 0.0, 0.0, 0.0),
        motors=(0.5, 0.5, 0.5, 0.5),
    )
    base.update(over)
    return QuadScene(**base)


def screen(view, points):
    """Pixels of world points through the view's camera, and whether each is in front."""
    return view.camera.project(np.asarray(points, dtype=float), *view.size)


def centroid(frame: np.ndarray, color) -> tuple[np.ndarray, int]:
    mask = np.all(frame == np.array(color, dtype=np.uint8), axis=-1)
    ys, xs = np.nonzero(mask)
    if len(xs) == 0:
        return np.array([np.nan, np.nan]), 0
    return np.array([xs.mean(), ys.mean()]), len(xs)


@pytest.fixture
def view():
    v = QuadrotorView("rgb_array", width=640, height=480, hud=False)
    yield v
    v.close()


def test_frame_is_height_width_3_uint8():
    v = QuadrotorView("rgb_array", width=320, height=240)
    frame = v.render(scene())
    v.close()
    assert frame.shape == (240, 320, 3)
    assert frame.dtype == np.uint8
    assert frame.flags["C_CONTIGUOUS"] and frame.flags["WRITEABLE"]
    assert len(np.unique(frame.reshape(-1, 3), axis=0)) > 50  # a picture, not a blank


def test_same_scene_same_frame_and_moving_changes_it(view):
    a = view.render(scene(step=1))
    again = view.render(scene(step=1))
    np.testing.assert_array_equal(a, again)
    moved = view.render(scene(step=2, position=(0.6, 0.0, 1.5)))
    changed = np.any(a != moved, axis=-1)
    assert changed.sum() > 500
    # The change is around the old and new drone positions, not all over the frame.
    (u0, v0), _ = screen(view, np.array([0.0, 0.0, 1.5]))
    (u1, v1), _ = screen(view, np.array([0.6, 0.0, 1.5]))
    ys, xs = np.nonzero(changed)
    near = (np.hypot(xs - u0, ys - v0) < 80) | (np.hypot(xs - u1, ys - v1) < 80)
    assert near.mean() > 0.6


@pytest.mark.parametrize(
    "position",
    [(0.0, 0.0, 1.5), (1.2, -0.8, 0.6), (-1.0, 1.3, 2.7), (0.4, 0.9, 0.3)],
)
def test_hub_pixels_follow_the_world_position(view, position):
    s = scene(
        position=position,
        quaternion=(0.93, 0.11, -0.01, 0.35),  # rolled, pitched and yawed
        velocity=(1.0, -0.5, 0.3),  # arrows start at the hub: they must not move its centroid
        wind=(3.0, 1.0, 0.0),
        target=(1.5, 1.5, 2.5),
    )
    frame = view.render(s)
    expected, visible = screen(view, np.array(position))
    assert visible
    got, count = centroid(frame, qw.BODY)
    assert count > 30, "the hub is not drawn"
    assert np.hypot(*(got - expected)) < 1.5, (got, expected)


def test_hub_tracks_a_moving_camera(view):
    s = scene(position=(0.5, 0.5, 1.0))
    view.render(s)
    view.camera.orbit(120.0, 15.0)
    view.camera.look_at = view.camera.look_at + [0.3, -0.2, 0.1]
    frame = view.render(s)
    expected, _ = screen(view, np.array([0.5, 0.5, 1.0]))
    got, count = centroid(frame, qw.BODY)
    assert count > 30
    assert np.hypot(*(got - expected)) < 1.5


@pytest.mark.parametrize("target", [(1.0, -1.0, 2.0), (-1.2, 0.5, 0.8)])
def test_target_marker_is_where_the_target_is(view, target):
    frame = view.render(scene(position=(0.0, 0.0, 1.5), target=target))
    expected, _ = screen(view, np.array(target))
    got, count = centroid(frame, qw.TARGET)
    assert count > 30
    # The crosshair arms are foreshortened unevenly by perspective: a few pixels of slack.
    assert np.hypot(*(got - expected)) < 3.0, (got, expected)


@pytest.mark.parametrize("frame", ["quad_x", "hexa_x", "octo_x"])
def test_each_rotor_is_drawn_coloured_by_spin_at_its_px4_position(frame):
    # Straight down from above, north up on screen; nose east (yaw 0).
    cam = OrbitCamera(look_at=np.array([0.0, 0.0, 1.0]), distance=3.0, azimuth_deg=0.0)
    cam.elevation_deg = 89.0
    v = QuadrotorView("rgb_array", width=640, height=480, hud=False, camera=cam)
    table = flyloop._native.frames()[frame]  # (forward, left) in arm lengths, spin
    s = scene(position=(0.0, 0.0, 1.0), motors=np.zeros(len(table)), frame=frame)
    frame_px = v.render(s).astype(float)
    # Level, the nose (body +x, forward) points east and the left (+y) north.
    arm = s.arm_length * v.drone_scale
    rotors = s.position + arm * np.array([(x, y, 0.0) for x, y, _ in table])
    uv, _ = screen(v, rotors)
    ys, xs = np.mgrid[0 : frame_px.shape[0], 0 : frame_px.shape[1]]
    drawn = []
    for u, w in uv:
        # Sample a ring between the arm and the rim: the disc's own colour.
        r = np.hypot(xs - u, ys - w)
        ring = (r > 4) & (r < 9)
        red, green = frame_px[ring, 0].mean(), frame_px[ring, 1].mean()
        drawn.append("CCW" if green > red + 30 else "CW" if red > green + 30 else "none")
    assert drawn == ["CCW" if spin < 0 else "CW" for _, _, spin in table]
    # Forward rotors east of the hub on screen, left ones north (up): the frame is not mirrored.
    centre, _ = screen(v, s.position)
    for (u, w), (x, y, _) in zip(uv, table, strict=True):
        assert abs(x) < 0.1 or np.sign(u - centre[0]) == np.sign(x)
        assert abs(y) < 0.1 or np.sign(centre[1] - w) == np.sign(y)
    v.close()


def test_motor_bars_fill_in_proportion():
    v = QuadrotorView("rgb_array", width=800, height=600)
    frame = v.render(scene(motors=(1.0, 0.0, 0.5, 0.25)))
    v.close()
    corner = frame[300:, 500:]
    counts = {
        level: centroid(corner, (255, round(230 * (1 - level)), 0))[1] for level in (1.0, 0.5, 0.25)
    }
    assert counts[1.0] == 24 * 118  # a 26 x 120 bar inside its 1 px black border
    assert counts[0.5] == pytest.approx(counts[1.0] / 2, rel=0.03)
    assert counts[0.25] == pytest.approx(counts[1.0] / 4, rel=0.05)


def test_info_panel_text_carries_the_state():
    s = scene(
        time_s=2.5,
        step=250,
        position=(1.0, 2.0, 1.6),
        velocity=(3.0, 4.0, 0.0),
        wind=(0.0, 2.0, 0.0),
        quaternion=(0.943714, 0.127679, -0.144878, 0.268536),  # roll 10, pitch -20, yaw 30 deg
        target=(1.0, 2.0, 2.6),
        reward=0.25,
        episode_return=12.5,
        waypoints_reached=4,
        status="crashed",
    )
    text = "\n".join(line for line, _ in info_lines(s))
    for expected in [
        "Time 2.50 s",
        "Step 250",
        "Distance 1.00 m",
        "Height 1.60 m",
        "Speed 5.00 m/s",
        "Wind 2.00 m/s",
        "Roll +10.0°",
        "Pitch -20.0°",
        "Yaw +30.0°",
        "Reward +0.250",
        "Return 12.50",
        "Waypoints reached 4",
        "Crashed",
    ]:
        assert expected in text


def test_hud_changes_with_the_step_only_in_its_panel():
    v = QuadrotorView("rgb_array", width=800, height=600)
    a = v.render(scene(step=7))
    b = v.render(scene(step=7000))
    v.close()
    ys, xs = np.nonzero(np.any(a != b, axis=-1))
    assert len(xs) > 20
    assert xs.max() < 400 and ys.max() < 200  # the top-left info panel


def test_far_and_behind_camera_states_do_not_break_drawing(view):
    for position in [(1e6, -1e6, 1e6), (0.0, -40.0, 30.0), (0.0, 0.0, -5.0)]:
        frame = view.render(scene(position=position, target=(1e5, 0.0, 0.0)))
        assert frame.shape == (480, 640, 3)


def test_the_trail_restarts_with_each_episode_and_records_a_step_once():
    v = QuadrotorView("rgb_array", width=160, height=120, trail_steps=3)
    for step in range(5):
        v.render(scene(step=step, position=(step, 0.0, 1.0)))
    assert [p[0] for p in v.path] == [2, 3, 4]  # bounded, oldest dropped
    v.render(scene(step=4, position=(40.0, 0.0, 1.0)))  # the same step again replaces it
    assert [p[0] for p in v.path] == [2, 3, 40]
    v.render(scene(step=0, position=(7.0, 7.0, 1.0)))  # the step went back: a new episode
    assert np.array(v.path).tolist() == [[7.0, 7.0, 1.0]]
    v.reset()
    assert len(v.path) == 0
    v.close()


def test_close_is_idempotent_and_render_after_close_is_an_error():
    v = QuadrotorView("rgb_array", width=200, height=150)
    v.render(scene())
    v.close()
    v.close()
    assert not v.is_open
    with pytest.raises(RuntimeError, match="closed"):
        v.render(scene())


def test_a_bad_render_mode_is_a_clear_error():
    with pytest.raises(ValueError, match="render_mode must be one of"):
        QuadrotorView(None)


def _env_without_display(**extra):
    env = {k: val for k, val in os.environ.items() if k not in ("DISPLAY", "WAYLAND_DISPLAY")}
    env.pop("SDL_VIDEODRIVER", None)
    # The child finds flyloop where this process did (installed or on pytest's pythonpath).
    root = str(Path(flyloop.__file__).resolve().parents[1])
    env["PYTHONPATH"] = os.pathsep.join([root, env.get("PYTHONPATH", "")])
    env.update(extra)
    return env


PROBE = """
import os
from flyloop.rendering import QuadrotorView, QuadScene
v = QuadrotorView("rgb_array", width=160, height=120)
f = v.render(QuadScene(time_s=0, step=0, position=(0, 0, 1), velocity=(0, 0, 0),
                       quaternion=(1, 0, 0, 0)))
v.close()
print(os.environ.get("SDL_VIDEODRIVER"), f.shape)
"""


def test_headless_rgb_array_uses_the_dummy_driver_without_clobbering_a_choice():
    run = subprocess.run(
        [sys.executable, "-c", PROBE],
        env=_env_without_display(),
        capture_output=True,
        text=True,
        check=True,
    )
    assert run.stdout.strip() == "dummy (120, 160, 3)"
    run = subprocess.run(
        [sys.executable, "-c", PROBE],
        env=_env_without_display(SDL_VIDEODRIVER="offscreen"),
        capture_output=True,
        text=True,
        check=True,
    )
    assert run.stdout.strip() == "offscreen (120, 160, 3)"


FAR_PROBE = """
import resource
resource.setrlimit(resource.RLIMIT_AS, (3 << 30, 3 << 30))
from flyloop.rendering import QuadrotorView, QuadScene
v = QuadrotorView("rgb_array", width=641, height=479)
v.render(QuadScene(time_s=0, step=0, position=(0, 0, 1), velocity=(0, 0, 0),
                   quaternion=(1, 0, 0, 0)))
v.camera.orbit(100, 40)
f = v.render(QuadScene(time_s=1, step=1, position=(1e6, -1e6, 1e6), velocity=(0, 0, 0),
                       quaternion=(1, 0, 0, 0), target=(1e5, 0, 0)))
print(f.shape)
"""


def test_a_far_state_seen_from_a_turned_camera_draws_in_bounded_memory():
    # The drop line and shadow of a drone 1e6 m away reach far off screen; sized by the
    # state, their dashes and translucent layer would need ~20 GB.
    run = subprocess.run(
        [sys.executable, "-c", FAR_PROBE],
        env=_env_without_display(),
        capture_output=True,
        text=True,
    )
    assert run.returncode == 0, run.stderr[-800:]
    assert run.stdout.strip() == "(479, 641, 3)"
