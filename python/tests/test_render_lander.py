"""LanderView in rgb_array mode: frame format, and each element drawn where the state says
(pixel centroids and samples against the view's world-to-screen transform)."""

import math

import numpy as np
import pytest

from flyloop.rendering import LanderScene, LanderView
from flyloop.rendering import lander as ld

# A 10 m world makes the 1 m drone 78 px wide: its own colours outnumber its outline.
SMALL = dict(
    world_width=10.0,
    world_height=10.0,
    ground_height=2.0,
    platform_x=5.0,
    spawn_center=(5.0, 8.0),
    spawn_half_range=1.0,
)


def scene(**over):
    base = dict(
        time_s=1.0,
        step=50,
        position=(4.0, 6.0),
        velocity=(0.0, 0.0),
        angle=0.0,
        angular_velocity=0.0,
        thrust=(7.0, 7.0),
        battery=80.0,
        **SMALL,
    )
    base.update(over)
    return LanderScene(**base)


def to_px(point):
    """Where the 800 x 800 view draws a point of the SMALL world: 12 px margins, 77.6 px/m."""
    x, y = np.asarray(point, dtype=float)
    return np.array([12 + 77.6 * x, 788 - 77.6 * y])


def mask_of(frame, *colors):
    out = np.zeros(frame.shape[:2], dtype=bool)
    for c in colors:
        out |= np.all(frame == np.array(c, dtype=np.uint8), axis=-1)
    return out


def centroid(mask):
    ys, xs = np.nonzero(mask)
    return np.array([xs.mean(), ys.mean()]), len(xs)


@pytest.fixture
def view():
    v = LanderView("rgb_array", show_close_up=False, show_overlay=False)
    yield v
    v.close()


def test_frame_is_height_width_3_uint8():
    v = LanderView("rgb_array", width=640, height=480)
    frame = v.render(scene())
    v.close()
    assert frame.shape == (480, 640, 3) and frame.dtype == np.uint8


def test_default_world_frame_and_moving_changes_it():
    v = LanderView("rgb_array")
    default = dict(time_s=0, step=0, velocity=(0, 0), angle=0, angular_velocity=0)
    a = v.render(
        LanderScene(position=(25, 40), thrust=(7, 7), battery=100, platform_x=25, **default)
    )
    b = v.render(
        LanderScene(position=(25, 40), thrust=(7, 7), battery=100, platform_x=25, **default)
    )
    np.testing.assert_array_equal(a, b)
    default["step"] = 1
    c = v.render(
        LanderScene(position=(27, 38), thrust=(7, 7), battery=99, platform_x=25, **default)
    )
    v.close()
    assert a.shape == (800, 800, 3)
    assert np.any(a != c, axis=-1).sum() > 200


@pytest.mark.parametrize(
    ("position", "angle"),
    [((4.0, 6.0), 0.0), ((2.0, 8.5), 0.4), ((7.5, 4.0), -0.9), ((5.0, 3.2), math.pi / 2)],
)
def test_drone_pixels_follow_position_and_angle(view, position, angle):
    frame = view.render(scene(position=position, angle=angle))
    expected = to_px(position)
    got, count = centroid(mask_of(frame, ld.FRAME, ld.MOTOR))
    assert count > 300
    assert np.hypot(*(got - expected)) < 1.5, (got, expected)  # vertices snap to pixels
    # The two motors lie along the body's x axis, rotated by the angle (CCW, y up).
    ys, xs = np.nonzero(mask_of(frame, ld.MOTOR))
    d = np.stack([xs - expected[0], expected[1] - ys], axis=1)
    axis = np.array([math.cos(angle), math.sin(angle)])
    along, across = d @ axis, d @ np.array([-axis[1], axis[0]])
    assert np.abs(along).min() > 0.3 * 78 * 0.8  # both motors sit near the tips
    assert np.abs(across).max() < 0.1 * 78 + 2


@pytest.mark.parametrize("platform_x", [2.5, 5.0, 7.5])
def test_platform_is_where_the_scene_says(view, platform_x):
    s = scene(platform_x=platform_x)
    frame = view.render(s)
    got, count = centroid(mask_of(frame, ld.PLATFORM))
    expected = to_px([platform_x, 2.25])
    assert count > 1000
    assert np.hypot(*(got - expected)) < 1.5, (got, expected)


def test_sensor_line_runs_from_the_drone_to_the_platform_top(view):
    s = scene(position=(2.0, 8.0), platform_x=7.0)
    frame = view.render(s)
    a = to_px(s.position)
    b = to_px(s.platform_top)
    sensor = mask_of(frame, ld.SENSOR)

    def hits(p0, p1):
        samples = [p0 + (p1 - p0) * t for t in np.linspace(0.15, 0.85, 40)]
        near = [sensor[int(y) - 2 : int(y) + 3, int(x) - 2 : int(x) + 3].any() for x, y in samples]
        return np.mean(near)

    assert hits(a, b) > 0.4  # dashed: about half of the samples land on a dash
    assert hits(a, np.array([a[0], b[1]])) < 0.1  # a line the view does not draw


def test_thrust_bars_grow_from_the_firing_motor(view):
    centre = to_px([4.0, 6.0])
    for thrust, side in (((0.0, 15.0), 1), ((15.0, 0.0), -1), ((7.5, 0.0), -1)):
        frame = view.render(scene(thrust=thrust))
        ys, xs = np.nonzero(mask_of(frame, ld.THRUST))
        assert np.all(np.sign(xs - centre[0]) == side)
        assert np.all(ys < centre[1])  # along the body's +y: up on screen
        length = ys.max() - ys.min() + 1
        assert length == pytest.approx(ld.THRUST_BAR_PX * max(thrust) / 15.0, abs=2)


@pytest.mark.parametrize("direction_deg", [0, 90, 200, 315])
def test_wind_arrow_points_along_the_wind_force(view, direction_deg):
    d = math.radians(direction_deg)
    frame = view.render(scene(wind_force=(2.5 * math.cos(d), 2.5 * math.sin(d)), wind_speed=5))
    width = frame.shape[1]
    dial = np.zeros(frame.shape[:2], dtype=bool)
    dial[30:95, width - 98 : width - 34] = True  # inside the dial's rim
    got, count = centroid(mask_of(frame, ld.WIND) & dial & _disc(frame, (width - 66, 62), 30))
    assert count > 40
    offset = got - np.array([width - 66, 62])
    seen = math.degrees(math.atan2(-offset[1], offset[0]))
    assert abs((seen - direction_deg + 180) % 360 - 180) < 15


def _disc(frame, center, radius):
    ys, xs = np.mgrid[0 : frame.shape[0], 0 : frame.shape[1]]
    return np.hypot(xs - center[0], ys - center[1]) < radius


def test_path_and_shades_mark_past_positions_and_restart_each_episode():
    with_history = LanderView("rgb_array", show_close_up=False, shade_distance_m=1.0)
    without = LanderView("rgb_array", show_close_up=False, show_path=False, show_shades=False)
    poses = [(1.0 + 0.25 * i, 8.0 - 0.1 * i) for i in range(25)]
    for step, pos in enumerate(poses):
        a = with_history.render(scene(step=step, position=pos))
        b = without.render(scene(step=step, position=pos))
    differs = np.any(a != b, axis=-1)
    # Between consecutive early poses (far from the drone now) the path is drawn...
    for p0, p1 in zip(poses[:10], poses[1:11], strict=True):
        mid = to_px((np.array(p0) + p1) / 2)
        u, v = np.round(mid).astype(int)
        assert differs[v - 1 : v + 2, u - 1 : u + 2].any()
    # ...and a shade sits at the first pose and every >1 m after it.
    for pose in (poses[0], poses[5]):
        u, v = np.round(to_px(pose)).astype(int)
        assert differs[v - 3 : v + 4, u - 20 : u + 21].sum() > 50
    # A lower step number is a new episode: the old path and shades are gone.
    a = with_history.render(scene(step=0, position=(8.0, 8.0)))
    b = without.render(scene(step=0, position=(8.0, 8.0)))
    np.testing.assert_array_equal(a, b)
    with_history.close()
    without.close()


def test_close_up_shows_the_drone_in_a_large_world():
    v = LanderView("rgb_array", show_overlay=False)
    s = LanderScene(
        time_s=0,
        step=0,
        position=(30, 25),
        velocity=(0, 0),
        angle=0.0,
        angular_velocity=0,
        thrust=(7, 7),
        battery=100,
        platform_x=25,
    )
    frame = v.render(s)
    v.close()
    inset = np.zeros(frame.shape[:2], dtype=bool)
    inset[20:200, 20:270] = True
    got, count = centroid(mask_of(frame, ld.FRAME, ld.MOTOR) & inset)
    assert count > 200  # 48 px per metre: the drone is big there
    assert got[0] == pytest.approx(20 + 125, abs=1.5)
    assert got[1] == pytest.approx(20 + 90 + 0.12 * 180, abs=1.5)


@pytest.mark.parametrize(
    ("over", "expected", "color"),
    [
        (dict(), "Flying", ld.TEXT),
        (dict(landed=True), "Landed safely!", ld.GOOD),
        (dict(crashed=True), "Crashed!", ld.BAD),
        (dict(outcome="lost control"), "Lost control!", ld.BAD),
        (dict(step=1000, max_steps=1000), "Time limit reached", ld.BAD),
    ],
)
def test_status_line(over, expected, color):
    assert ld.status_text(scene(**over)) == (expected, color)


def test_overlay_text_changes_with_the_state_in_its_panel():
    v = LanderView("rgb_array")
    a = v.render(scene(battery=80.0))
    b = v.render(scene(battery=20.0))
    v.close()
    ys, xs = np.nonzero(np.any(a != b, axis=-1))
    ground_v = 800 - 12 - 2.0 * 77.6
    assert len(ys) > 50 and ys.min() > ground_v  # the panel lives over the ground band


def test_close_is_idempotent_and_render_after_close_is_an_error():
    v = LanderView("rgb_array", width=200, height=200)
    v.render(scene())
    v.close()
    v.close()
    with pytest.raises(RuntimeError, match="closed"):
        v.render(scene())
    with pytest.raises(ValueError, match="render_mode"):
        LanderView("rgb")
