"""The up axis of hair from a format that says none: generated hanging hair, turned about its
up axis and with its strands swinging, is found to hang along the axis it was made with; hair
that hangs along neither axis keeps the default."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from hairtool.groom import Groom
from hairtool.io.up_axis import infer_up_axis


def hanging(up: str, seed: int, turn: float, swing: float, strands: int = 40, points: int = 8) -> Groom:
    """Strands from roots on a cap falling along −up, each swung sideways by up to ``swing``
    of its length, the whole turned by ``turn`` radians about the up axis."""
    rng = np.random.default_rng(seed)
    roots = rng.normal(size=(strands, 3))
    roots[:, 1] = np.abs(roots[:, 1]) + 1.0  # a cap above the head's middle (Y-up frame)
    side = rng.uniform(-swing, swing, (strands, 2))
    t = np.linspace(0.0, 1.0, points)[None, :, None]
    fall = np.stack([side[:, 0], -np.ones(strands), side[:, 1]], axis=1)[:, None, :]
    pts = roots[:, None, :] + 2.0 * t * fall
    c, s = np.cos(turn), np.sin(turn)
    pts = pts @ np.array([[c, 0, -s], [0, 1, 0], [s, 0, c]])
    if up == "Z":
        pts = pts[..., [0, 2, 1]] * np.array([1.0, -1.0, 1.0])  # (x, y, z) Y-up ↦ (x, −z, y) Z-up
    return Groom(pts.reshape(-1, 3).astype(np.float32), np.full(strands, points))


@settings(max_examples=60, deadline=None)
@given(
    up=st.sampled_from(["Y", "Z"]),
    seed=st.integers(0, 2**32 - 1),
    turn=st.floats(0.0, 2 * np.pi),
    swing=st.floats(0.0, 0.9),
)
def test_hanging_hair_is_found_up_along_the_axis_it_hangs_along(up, seed, turn, swing):
    assert infer_up_axis(hanging(up, seed, turn, swing)) == (up, True)


@settings(max_examples=30, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), default=st.sampled_from(["Y", "Z"]))
def test_hair_standing_up_or_lying_flat_keeps_the_default(seed, default):
    g = hanging("Y", seed, 0.0, 0.2)
    standing = Groom(g.points * np.array([1, -1, 1], np.float32), g.counts)  # tips above the roots
    assert infer_up_axis(standing, default) == (default, False)
    flat = g.points.copy()
    flat[:, 1] = 0.0
    flat[:, 2] = 0.0
    assert infer_up_axis(Groom(flat, g.counts), default) == (default, False)
