"""Procedural head motions: rigid, starting and ending at rest, chained in equal slots."""

from __future__ import annotations

import numpy as np
import pytest

from hairtool.errors import ParameterError
from hairtool.head_motion import MOTIONS, check_transform, head_motion, parse_motion


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
