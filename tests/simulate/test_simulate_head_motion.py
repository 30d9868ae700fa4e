"""Procedural head motions: rigid, starting and ending at rest, chained in equal slots."""

from __future__ import annotations

import numpy as np
import pytest

from hairtool.errors import ParameterError
from hairtool.simulate.head_motion import MOTIONS, check_transform, head_motion, parse_motion


@pytest.mark.parametrize("name", sorted(MOTIONS))
def test_each_motion_is_rigid_and_returns_to_rest(name):
    f = head_motion(name, 2.0)
    np.testing.assert_allclose(f(0.0), np.eye(4), atol=1e-12)
    np.testing.assert_allclose(f(2.0), np.eye(4), atol=1e-12)
    for t in np.linspace(0.0, 2.0, 41):
        check_transform(f(t), t)


@pytest.mark.parametrize("name", ["turn", "nod", "shake", "hop"])
def test_each_motion_moves(name):
    f = head_motion(name, 2.0)
    assert max(np.abs(f(t) - np.eye(4)).max() for t in np.linspace(0, 2, 41)) > 0.1


def test_chained_motions_play_in_equal_slots():
    f = head_motion("turn,nod", 2.0)
    g_turn = head_motion("turn", 1.0)
    g_nod = head_motion("nod", 1.0)
    np.testing.assert_allclose(f(0.3), g_turn(0.3), atol=1e-12)
    np.testing.assert_allclose(f(1.6), g_nod(0.6), atol=1e-12)
    np.testing.assert_allclose(f(1.0), np.eye(4), atol=1e-12)
    assert parse_motion(["hop", " shake"]) == ["hop", "shake"]


def test_bad_motions():
    with pytest.raises(ParameterError, match="motion"):
        parse_motion("turn,,nod")
    with pytest.raises(ParameterError, match="duration"):
        head_motion("turn", 0.0)
    with pytest.raises(ParameterError, match="rigid"):
        check_transform(np.diag([2.0, 1.0, 1.0, 1.0]), 0.0)
    with pytest.raises(ParameterError, match="4×4"):
        check_transform(np.eye(3), 0.0)


@pytest.mark.parametrize("name", ["turn", "nod", "hop"])
def test_motions_placed_on_another_head_are_the_unit_motion_scaled_and_moved(name):
    centre, radius = np.array([3.0, 40.0, -2.0]), 9.0
    unit, placed = head_motion(name, 2.0), head_motion(name, 2.0, centre, radius)
    x_unit = np.array([[0.3, 0.8, 0.5], [-0.7, 0.2, 0.1]])  # points of the unit head's frame
    x = centre + radius * x_unit
    for t in np.linspace(0.0, 2.0, 17):
        m, mu = placed(t), unit(t)
        check_transform(m, t)
        moved = x @ m[:3, :3].T + m[:3, 3]
        moved_unit = x_unit @ mu[:3, :3].T + mu[:3, 3]
        np.testing.assert_allclose(moved, centre + radius * moved_unit, atol=1e-9)
    with pytest.raises(ParameterError, match="head radius"):
        head_motion(name, 2.0, centre, 0.0)


def test_fit_head_finds_the_sphere_the_circle_or_falls_back():
    from hairtool import samples
    from hairtool.simulate.head_motion import fit_head

    rng = np.random.default_rng(3)
    d = rng.normal(size=(200, 3))
    d[:, 1] = np.abs(d[:, 1])  # roots on the upper half of the head, as on a scalp
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    centre, radius = fit_head(np.array([1.0, 35.0, -0.5]) + 9.5 * d)
    np.testing.assert_allclose(centre, [1.0, 35.0, -0.5], atol=1e-9)
    assert radius == pytest.approx(9.5)
    centre, radius = fit_head(samples.scalp(400, 4).roots)
    np.testing.assert_allclose(centre, 0.0, atol=0.05)
    assert radius == pytest.approx(1.0, rel=0.05)
    centre, radius = fit_head(samples.portrait().roots)  # 2-D: the circle in the plane, z = 0
    assert centre[2] == 0.0 and radius > 0
    roots = samples.portrait().roots.astype(np.float64)
    assert np.ptp(np.linalg.norm(roots - centre, axis=1)) < 0.1 * radius
    line = np.column_stack([np.linspace(0, 4, 9), np.zeros(9), np.zeros(9)])
    centre, radius = fit_head(line)  # no sphere: the centroid and half the spread
    np.testing.assert_allclose(centre, [2.0, 0.0, 0.0])
    assert radius == pytest.approx(1.0)
    with pytest.raises(ParameterError, match="roots"):
        fit_head(np.full((4, 3), np.nan))
