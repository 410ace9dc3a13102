"""Camera and frame-convention math of flyloop.rendering (pure numpy, no pygame)."""

import math
import sys
from pathlib import Path

import numpy as np
import pytest

from flyloop.rendering import QuadScene
from flyloop.rendering.camera import OrbitCamera, Projector
from flyloop.rendering.quadrotor import ROTOR_SPIN, info_lines, rotation_matrix

# The sample scenes' quaternion from Euler angles (the one copy, in the example that draws them).
sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "examples"))
from render_samples import quaternion_from_euler  # noqa: E402

W, H = 800, 600


def test_look_at_point_lands_in_the_frame_centre():
    cam = OrbitCamera(look_at=np.array([1.0, -2.0, 0.5]), distance=5.0, azimuth_deg=70)
    uv, visible = cam.project(np.array([1.0, -2.0, 0.5]), W, H)
    assert visible
    np.testing.assert_allclose(uv, [W / 2, H / 2], atol=1e-9)
    assert cam.to_camera(cam.look_at)[2] == pytest.approx(5.0)


def test_looking_north_east_is_right_and_up_is_up():
    # Looking north (azimuth 0) from the horizon: east is screen-right, +z is screen-up.
    cam = OrbitCamera(look_at=np.zeros(3), distance=10.0, azimuth_deg=0.0, elevation_deg=0.0)
    (u_east, v_east), _ = cam.project(np.array([1.0, 0.0, 0.0]), W, H)
    (u_up, v_up), _ = cam.project(np.array([0.0, 0.0, 1.0]), W, H)
    focal = (H / 2) / math.tan(math.radians(cam.fov_deg) / 2)
    assert u_east == pytest.approx(W / 2 + focal * 1.0 / 10.0)
    assert v_east == pytest.approx(H / 2)
    assert v_up == pytest.approx(H / 2 - focal * 1.0 / 10.0)
    assert u_up == pytest.approx(W / 2)


def test_azimuth_90_looks_east_so_north_is_screen_left():
    cam = OrbitCamera(look_at=np.zeros(3), distance=10.0, azimuth_deg=90.0, elevation_deg=0.0)
    right, up, forward = cam.basis()
    np.testing.assert_allclose(forward, [1, 0, 0], atol=1e-12)
    np.testing.assert_allclose(right, [0, -1, 0], atol=1e-12)
    np.testing.assert_allclose(up, [0, 0, 1], atol=1e-12)
    (u_north, _), _ = cam.project(np.array([0.0, 1.0, 0.0]), W, H)
    assert u_north < W / 2 - 10


def test_basis_is_orthonormal_and_right_handed_at_any_pose():
    for az, el in [(0, 0), (35, 28), (200, -40), (359, 89)]:
        right, up, forward = OrbitCamera(azimuth_deg=az, elevation_deg=el).basis()
        m = np.array([right, up, forward])
        np.testing.assert_allclose(m @ m.T, np.eye(3), atol=1e-12)
        np.testing.assert_allclose(np.cross(right, up), -forward, atol=1e-12)


def test_perspective_shrinks_with_depth():
    cam = OrbitCamera(look_at=np.zeros(3), distance=4.0, azimuth_deg=0, elevation_deg=0)
    pr = Projector(cam, (W, H))
    assert pr.radius(0.1, 2.0) == pytest.approx(4 * pr.radius(0.1, 8.0))
    # A 1 m offset at depth 4 spans the projected distance that radius predicts.
    (u0, _), _ = cam.project(np.zeros(3), W, H)
    (u1, _), _ = cam.project(np.array([1.0, 0, 0]), W, H)
    assert u1 - u0 == pytest.approx(pr.radius(1.0, 4.0))


def test_points_behind_the_camera_are_not_visible_and_segments_are_clipped():
    # Looking north from (0, -5, 0): camera right = +x, up = +z, depth = y + 5.
    cam = OrbitCamera(look_at=np.zeros(3), distance=5.0, azimuth_deg=0, elevation_deg=0)
    pr = Projector(cam, (W, H))
    behind = np.array([1.0, -6.0, 0.5])  # depth -1
    _, visible = cam.project(behind, W, H)
    assert not visible
    assert pr.segment(behind, behind - [0, 1, 0]) is None
    a, b = pr.segment(behind, np.zeros(3))
    np.testing.assert_allclose(b, [W / 2, H / 2])
    # Cut where the depth is `near`: 1.05 / 6 of the way from (1, 0.5) at depth -1 to (0, 0).
    right, up = np.array([1.0, 0.5]) * (1 - 1.05 / 6)
    focal = (H / 2) / math.tan(math.radians(cam.fov_deg) / 2)
    np.testing.assert_allclose(a, [W / 2 + focal * right / cam.near, H / 2 - focal * up / cam.near])


def test_a_polygon_crossing_the_near_plane_is_cut_there():
    # Looking north from (0, -5, 0): camera right = +x, up = +z, depth = y + 5.
    cam = OrbitCamera(look_at=np.zeros(3), distance=5.0, azimuth_deg=0, elevation_deg=0)
    pr = Projector(cam, (W, H))
    square = np.array([[-1, -6, -1.0], [1, -6, -1.0], [1, -2, 1.0], [-1, -2, 1.0]])
    t = (cam.near + 1) / 4  # depth -1 to 3 along the sides: near is crossed a fraction t in
    corners = [(x, -1 + 2 * t, cam.near) for x in (-1, 1)] + [(x, 1, 3.0) for x in (-1, 1)]
    focal = (H / 2) / math.tan(math.radians(cam.fov_deg) / 2)
    expected = sorted((W / 2 + focal * x / d, H / 2 - focal * u / d) for x, u, d in corners)
    np.testing.assert_allclose(sorted(map(tuple, pr.polygon(square))), expected)
    assert len(pr.polygon(square - [0, 10, 0])) == 0  # wholly behind


def test_orbit_wraps_azimuth_and_clamps_elevation():
    cam = OrbitCamera(look_at=np.array([0.0, 0.0, 1.0]), azimuth_deg=10, elevation_deg=20)
    cam.orbit(355, 500)
    assert cam.azimuth_deg == pytest.approx(5.0)
    assert cam.elevation_deg == 89.0  # clamped short of straight down
    cam.orbit(0, -400)
    assert cam.elevation_deg == -89.0


def test_rotor_spin_is_px4_quad_x():
    assert ROTOR_SPIN == (-1, -1, 1, 1)  # CCW, CCW, CW, CW: the core's quad_x (frame.rs)


def test_quaternion_rotation_and_euler_round_trip():
    yaw90 = quaternion_from_euler(0.0, 0.0, math.pi / 2)
    # Yaw +90 deg (ENU, counter-clockwise from above): the nose points north.
    np.testing.assert_allclose(rotation_matrix(yaw90) @ [1, 0, 0], [0, 1, 0], atol=1e-12)
    roll = quaternion_from_euler(0.3, 0.0, 0.0)
    # Positive roll about the forward axis lifts the left (+y) side: body z tips toward -y.
    assert (rotation_matrix(roll) @ [0, 0, 1])[1] < -0.25
    for angles in [(0.1, -0.2, 0.3), (-1.0, 0.7, -2.5), (0.05, 1.2, 3.0)]:
        q = quaternion_from_euler(*angles)
        assert np.linalg.norm(q) == pytest.approx(1.0)
        # The info panel reads the angles back.
        s = QuadScene(time_s=0, step=0, position=(0, 0, 1), velocity=(0, 0, 0), quaternion=q)
        roll, pitch, yaw = np.degrees(angles)
        assert info_lines(s)[3][0] == f"Roll {roll:+.1f}°  Pitch {pitch:+.1f}°  Yaw {yaw:+.1f}°"
        m = rotation_matrix(q)
        np.testing.assert_allclose(m @ m.T, np.eye(3), atol=1e-12)


def test_batched_segments_match_one_by_one_clipping():
    cam = OrbitCamera(look_at=np.zeros(3), distance=3.0, azimuth_deg=20, elevation_deg=10)
    pr = Projector(cam, (W, H))
    rng = np.random.default_rng(7)
    a = rng.uniform(-8, 8, (200, 3))
    b = rng.uniform(-8, 8, (200, 3))
    batched = pr.segments(a, b)
    single = [pr.segment(x, y) for x, y in zip(a, b, strict=True)]
    single = [s for s in single if s is not None]
    assert 20 < len(single) < 200  # some segments lie wholly behind the camera
    assert len(batched) == len(single)
    for (pa, pb), (qa, qb) in zip(batched, single, strict=True):
        np.testing.assert_allclose(pa, qa, atol=1e-6)
        np.testing.assert_allclose(pb, qb, atol=1e-6)
