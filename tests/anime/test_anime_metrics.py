"""The paper's error measures on chains with known angles and displacements."""

from __future__ import annotations

import numpy as np
import pytest

from hairtool import samples
from hairtool.anime.metrics import chain_errors, compare_cycle, node_angle_errors
from hairtool.anime.wave import WaveParams, cycle_animation
from hairtool.errors import ParameterError
from hairtool.groom import Animation, Groom
from hairtool.rotation import axis_angle_matrix


def planar_chain(turns_deg, seg=1.0) -> np.ndarray:
    """Nodes of a chain whose node j turns by ``turns_deg[j]`` relative to its parent (node 0: from +x)."""
    theta = np.cumsum(np.radians(turns_deg))
    pts = np.zeros((len(turns_deg) + 1, 3))
    pts[1:, 0] = np.cumsum(seg * np.cos(theta))
    pts[1:, 1] = np.cumsum(seg * np.sin(theta))
    return pts


def test_ten_degrees_at_every_node_against_a_straight_chain():
    bent = planar_chain([10.0] * 7)
    straight = planar_chain([0.0] * 7)
    np.testing.assert_allclose(np.degrees(node_angle_errors(bent, straight)), 10.0, atol=1e-12)
    e = chain_errors(bent[None, None], straight[None, None])
    assert e.angular_deg == pytest.approx(10.0, abs=1e-12)
    # position: node j of the bent chain is at distance |Σ e^{iθ}| … from the straight node (j, 0)
    d = np.linalg.norm(bent[1:] - straight[1:], axis=1).mean()
    assert e.position_pct == pytest.approx(100 * d / 7.0, rel=1e-12)


def test_known_turn_differences_and_symmetry():
    a = planar_chain([5, -20, 30, 0, 12])
    b = planar_chain([0, 10, 10, 15, -8])
    expected = np.abs(np.array([5, -20, 30, 0, 12]) - np.array([0, 10, 10, 15, -8]))
    np.testing.assert_allclose(np.degrees(node_angle_errors(a, b)), expected, atol=1e-10)
    np.testing.assert_allclose(node_angle_errors(a, b), node_angle_errors(b, a), atol=1e-12)


def test_rigid_3d_rotation_shows_only_at_the_root_node():
    a = np.random.default_rng(1).normal(size=(6, 3)).cumsum(axis=0)
    a -= a[0]
    axis = np.cross(a[1], [0.3, -0.2, 1.0])  # ⟂ to the first segment: it turns by the full 30°
    axis /= np.linalg.norm(axis)
    rot = axis_angle_matrix(axis, np.radians(30.0))
    b = a @ rot.T
    err = np.degrees(node_angle_errors(b, a))
    assert err[0] == pytest.approx(30.0, abs=1e-9)
    np.testing.assert_allclose(err[1:], 0.0, atol=1e-6)
    e = chain_errors(b[None, None], a[None, None])
    assert e.angular_deg == pytest.approx(30.0 / 5, abs=1e-6)
    # chord of a 30° turn about an axis through the root: 2 r sin 15° (r = distance from the axis)
    r = np.linalg.norm(a[1:] - np.outer(a[1:] @ axis, axis), axis=1)
    length = np.linalg.norm(np.diff(a, axis=0), axis=1).sum()
    assert e.position_pct == pytest.approx(100 * np.mean(2 * r * np.sin(np.radians(15))) / length, rel=1e-9)


def test_identical_chains_and_reversed_segments():
    a = planar_chain([3, 4, 5, 6])
    e = chain_errors(a[None, None], a[None, None])
    assert e.angular_deg == 0.0 and e.position_pct == 0.0
    folded = planar_chain([0, 180, 0])  # a parent turned right round: no NaN, 180° where it folds
    err = np.degrees(node_angle_errors(folded, planar_chain([0, 0, 0])))
    np.testing.assert_allclose(err, [0, 180, 0], atol=1e-9)


def test_known_sideways_displacement_in_percent():
    ref = planar_chain([0] * 4)  # length 4
    gen = ref.copy()
    gen[1:, 1] += 0.2  # every non-root node 0.2 off = 5 % of the length
    e = chain_errors(gen[None, None], ref[None, None])
    assert e.position_pct == pytest.approx(5.0, abs=1e-12)


def test_shape_mismatch_is_refused():
    with pytest.raises(ParameterError):
        chain_errors(np.zeros((1, 2, 5, 3)), np.zeros((1, 2, 4, 3)))


def test_compare_cycle_matches_frames_and_broadcasts_a_static_reference():
    g = samples.portrait(12, 10)
    anim = cycle_animation(g, WaveParams(), seed=2)
    same = compare_cycle(anim, anim)
    assert same.n_frames == 11 and same.angular_deg == 0.0 and same.position_pct == 0.0
    static = compare_cycle(anim, g)  # the rest groom against every frame
    assert static.n_frames == 11 and static.angular_deg > 1.0
    assert static.per_frame_angular_deg.shape == (11,)
    short = Animation(anim.frames[:4], anim.topology, 24)
    assert compare_cycle(anim, short).n_frames == 4
    d = static.to_dict()
    assert {"angular_error_deg", "position_error_pct", "frames_compared"} <= set(d)


def test_compare_resamples_chains_with_other_node_counts():
    line = lambda n: np.column_stack([np.linspace(0, 2, n), np.zeros(n), np.zeros(n)])  # noqa: E731
    coarse = Groom.from_strands([line(5), line(9)])
    fine = Groom.from_strands([line(17), line(3)])
    e = compare_cycle(coarse, fine)
    assert e.angular_deg == pytest.approx(0.0, abs=1e-6) and e.position_pct == pytest.approx(0.0, abs=1e-5)
    with pytest.raises(ParameterError) as err:
        compare_cycle(coarse, Groom.from_strands([line(5)]))
    assert err.value.name == "reference"
