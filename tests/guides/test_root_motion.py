"""Children's roots carried by their guides' roots (:mod:`hairtool.guides.root_motion`): a head
turned and moved rigidly carries its children rigidly, roots at rest leave them bit for bit."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from hairtool import samples
from hairtool.guides.animate import RenderHairAnimation
from hairtool.guides.binding import bind_roots
from hairtool.guides.root_motion import following, following_roots
from hairtool.rotation import rigid_fit


def rotation(axis, angle) -> np.ndarray:
    k = np.asarray(axis, np.float64) / np.linalg.norm(axis)
    c, s = np.cos(angle), np.sin(angle)
    kx = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return c * np.eye(3) + s * kx + (1 - c) * np.outer(k, k)


def test_a_still_pose_keeps_the_roots_array():
    guides = samples.sample("scalp", 30, 6)
    binding = bind_roots(guides, count=40, seed=1)
    assert following_roots(binding, guides) is binding.roots
    assert following(binding, guides) is binding


@settings(max_examples=5, deadline=None)
@given(
    axis=st.tuples(*[st.floats(-1, 1) for _ in range(3)]).filter(lambda v: np.linalg.norm(v) > 0.1),
    angle=st.floats(-1.2, 1.2),
    shift=st.tuples(*[st.floats(-2, 2) for _ in range(3)]),
)
def test_a_rigid_move_of_the_guides_moves_the_children_rigidly(axis, angle, shift):
    """Without frizz: its curl is carried by the nearest guide's rotation-minimising frames,
    whose start is not turned with the head."""
    guides = samples.sample("scalp", 30, 6)
    binding = bind_roots(guides, count=40, seed=1, frizz=0.0)
    rot, t = rotation(axis, angle), np.asarray(shift)
    moved = guides.with_points(guides.points.astype(np.float64) @ rot.T + t)
    r, tt = rigid_fit(guides.roots, moved.roots)
    np.testing.assert_allclose(r, rot, atol=1e-5)
    np.testing.assert_allclose(tt, t, atol=1e-5)
    np.testing.assert_allclose(following_roots(binding, moved), binding.roots @ rot.T + t, atol=1e-5)
    anim = guides.animate(np.stack([guides.points, moved.points]), 24.0)
    frames = RenderHairAnimation(binding, anim)
    rest = frames.frame_points(0).astype(np.float64)
    np.testing.assert_array_equal(rest, binding.build().points)
    np.testing.assert_allclose(frames.frame_points(1), rest @ rot.T + t, atol=2e-4)
