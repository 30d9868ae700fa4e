"""The orbit camera: projection conventions, framing, interaction and saving (no GL)."""

from __future__ import annotations

import json

import numpy as np
import pyrr
import pytest

from app.render.camera import Camera
from hairtool.errors import ParameterError

W, H = 640, 480


def test_default_camera_looks_down_minus_z():
    cam = Camera(target=(0, 0, 0), distance=5.0)
    np.testing.assert_allclose(cam.eye(), [0, 0, 5], atol=1e-12)
    right, up, fwd = cam.basis()
    np.testing.assert_allclose(right, [1, 0, 0], atol=1e-12)
    np.testing.assert_allclose(up, [0, 1, 0], atol=1e-12)
    np.testing.assert_allclose(fwd, [0, 0, -1], atol=1e-12)
    # The target lands in the middle of the picture; +x goes right, +y goes up (pixel y down).
    px = cam.project([[0, 0, 0], [0.1, 0, 0], [0, 0.1, 0]], W, H)
    np.testing.assert_allclose(px[0], [W / 2, H / 2], atol=1e-9)
    assert px[1, 0] > W / 2 and px[2, 1] < H / 2


def test_matrices_follow_pyrr_row_vector_convention():
    cam = Camera(target=(1, 2, 3), distance=4.0, yaw=0.7, pitch=-0.3)
    view = cam.view_matrix()
    assert view.dtype == np.float32 and view.shape == (4, 4)
    expected = pyrr.matrix44.create_look_at(cam.eye(), cam.target, cam.basis()[1])
    np.testing.assert_allclose(view, expected, atol=1e-5)
    # The target sits straight ahead of the eye at depth −distance in eye space.
    eye_space = np.array([1, 2, 3, 1.0]) @ view.astype(np.float64)
    np.testing.assert_allclose(eye_space[:3], [0, 0, -4.0], atol=1e-5)


@pytest.mark.parametrize("ortho", [False, True])
def test_project_unproject_round_trip(ortho):
    cam = Camera(target=(0.2, -0.1, 0.3), distance=3.0, yaw=0.4, pitch=0.25, ortho=ortho, ortho_height=2.5)
    rng = np.random.default_rng(1)
    pts = rng.uniform(-0.5, 0.5, (20, 3))
    px = cam.project(pts, W, H)
    for p, (x, y) in zip(pts, px, strict=True):
        back = cam.unproject_to_plane(x, y, W, H, p)
        np.testing.assert_allclose(back, p, atol=1e-6)
    # Unprojecting onto a plane gives a point on that plane (it faces the camera).
    q = cam.unproject_to_plane(100.0, 50.0, W, H, (0.0, 0.0, 0.0))
    assert abs(np.dot(q, cam.forward())) < 1e-9
    np.testing.assert_allclose(cam.project([q], W, H)[0], [100.0, 50.0], atol=1e-6)


@pytest.mark.parametrize("ortho", [False, True])
def test_frame_fits_the_box_in_view(ortho):
    lo, hi = np.array([-3.0, 1.0, -0.5]), np.array([5.0, 2.0, 0.5])
    if ortho:
        lo[2] = hi[2] = 0.0
    cam = Camera(ortho=ortho, yaw=0.3, pitch=0.2) if not ortho else Camera(ortho=True)
    cam.frame(lo, hi, aspect=W / H)
    corners = np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])])
    px = cam.project(corners, W, H)
    assert np.all(px[:, 0] >= 0) and np.all(px[:, 0] <= W)
    assert np.all(px[:, 1] >= 0) and np.all(px[:, 1] <= H)
    # …and not lost in a corner: the box spans a good part of the picture.
    span = px.max(axis=0) - px.min(axis=0)
    assert span[0] > 0.5 * W or span[1] > 0.5 * H
    near, far = cam.near_far()
    depth = cam.depth(corners)
    assert np.all(depth > near) and np.all(depth < far)


def test_orbit_turns_in_3d_and_is_a_no_op_in_ortho():
    cam = Camera()
    cam.orbit(50, 20)
    assert cam.yaw == pytest.approx(-0.5) and cam.pitch == pytest.approx(0.2)
    np.testing.assert_allclose(np.linalg.norm(cam.eye() - cam.target), cam.distance)
    cam.orbit(0, 10_000)
    assert cam.pitch < np.pi / 2  # clamped short of the pole, the view stays defined
    assert np.all(np.isfinite(cam.view_matrix()))
    flat = Camera(ortho=True)
    flat.orbit(50, 20)
    assert flat.yaw == 0.0 and flat.pitch == 0.0


@pytest.mark.parametrize("ortho", [False, True])
def test_pan_keeps_the_grabbed_point_under_the_cursor(ortho):
    cam = Camera(distance=4.0, yaw=0.3, ortho=ortho, ortho_height=3.0)
    before = cam.project([cam.target], W, H)[0]
    grabbed = cam.target.copy()
    cam.pan(30.0, -12.0, H)
    after = cam.project([grabbed], W, H)[0]
    np.testing.assert_allclose(after - before, [30.0, -12.0], atol=1e-6)


def test_zoom_in_and_out():
    cam = Camera(distance=4.0)
    cam.zoom(2)
    assert cam.distance == pytest.approx(4.0 / 1.15**2)
    cam.zoom(-2)
    assert cam.distance == pytest.approx(4.0)
    flat = Camera(ortho=True, ortho_height=2.0)
    flat.zoom(1)
    assert flat.ortho_height < 2.0
    with pytest.raises(ParameterError):
        cam.zoom(float("nan"))


@pytest.mark.parametrize("ortho", [False, True])
def test_pixels_per_unit_matches_projection(ortho):
    cam = Camera(distance=3.0, yaw=0.5, ortho=ortho, ortho_height=2.0)
    p = np.array([0.1, 0.2, -0.3])
    right = cam.basis()[0]
    a, b = cam.project([p, p + 0.01 * right], W, H)
    assert cam.pixels_per_unit_at(p, H) == pytest.approx(np.linalg.norm(b - a) / 0.01, rel=1e-4)


def test_state_round_trips_through_json():
    cam = Camera(target=(1, 2, 3), distance=2.5, yaw=0.1, pitch=-0.2, fov_y=40, ortho=False)
    cam.frame((-1, -1, -1), (1, 2, 1))
    again = Camera.from_state(json.loads(json.dumps(cam.state())))
    np.testing.assert_array_equal(again.view_matrix(), cam.view_matrix())
    np.testing.assert_array_equal(again.projection_matrix(1.5), cam.projection_matrix(1.5))
    with pytest.raises(ParameterError):
        Camera.from_state({"target": [0, 0, 0]})


def test_bad_parameters_name_themselves():
    with pytest.raises(ParameterError, match="distance"):
        Camera(distance=-1)
    with pytest.raises(ParameterError, match="fov_y"):
        Camera(fov_y=0)
    with pytest.raises(ParameterError, match="target"):
        Camera(target=(0, float("nan"), 0))
    with pytest.raises(ParameterError, match="aspect"):
        Camera().projection_matrix(0)


@pytest.mark.parametrize("ortho", [False, True])
def test_a_z_up_camera_is_the_y_up_one_turned_by_the_dccs_frame(ortho):
    turn = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]])  # (x, y, z) ↦ (x, −z, y)
    lo, hi = np.array([-1.0, -2.0, -0.5]), np.array([1.0, 3.0, 0.5])
    y_up = Camera.for_bounds(lo, hi, ortho=ortho, aspect=1.5)
    z_lo, z_hi = np.minimum(turn @ lo, turn @ hi), np.maximum(turn @ lo, turn @ hi)
    z_up = Camera.for_bounds(z_lo, z_hi, ortho=ortho, aspect=1.5, up_axis="Z")
    for a, b in zip(y_up.basis(), z_up.basis(), strict=True):
        np.testing.assert_allclose(turn @ a, b, atol=1e-12)
    rng = np.random.default_rng(1)
    p = rng.uniform(-1, 1, (20, 3))
    np.testing.assert_allclose(y_up.project(p, 300, 200), z_up.project(p @ turn.T, 300, 200), atol=1e-6)
    top = z_up.project([[0.0, 0.0, 2.0], [0.0, 0.0, -2.0]], 300, 200)
    assert top[0, 1] < top[1, 1]  # +z is up on screen
    assert Camera.from_state(z_up.state()).up_axis == "Z"
    with pytest.raises(ParameterError, match="up axis"):
        Camera(up_axis="X")
