"""UserAlign (eqs. 8–13): rigid turn at x = 1, radius test, degenerate cases, convergence."""

from __future__ import annotations

import numba
import numpy as np
import pytest

from hairtool import samples
from hairtool.errors import ParameterError
from hairtool.frozen.align import align, align_reference
from hairtool.groom import Groom
from hairtool.io import read_groom


def _v(g: Groom) -> np.ndarray:
    """Representative direction of each strand: tip − mean (8)."""
    p = g.points.astype(np.float64)
    mean = np.add.reduceat(p, g.offsets[:-1], axis=0) / g.counts[:, None]
    return p[g.topology.tip_indices] - mean


def _unit(a):
    return a / np.linalg.norm(a, axis=-1, keepdims=True)


@pytest.mark.parametrize("mode", ["paper", "preserve-length"])
def test_full_intensity_is_a_rigid_rotation_pointing_v_along_u(mode):
    g = samples.scalp(200, 16, seed=1)
    c = np.array([2.5, 1.0, 0.5])
    out = align(g, c, radius=100.0, intensity=1.0, mode=mode)
    # rigid: distances between all vertices of a strand are kept
    for s in range(0, 200, 17):
        a, b = g.strand(s).astype(np.float64), out.strand(s).astype(np.float64)
        da = np.linalg.norm(a[:, None] - a[None], axis=-1)
        db = np.linalg.norm(b[:, None] - b[None], axis=-1)
        np.testing.assert_allclose(db, da, atol=2e-5)
    u = c - out.roots
    np.testing.assert_allclose(_unit(_v(out)), _unit(u), atol=1e-5)
    np.testing.assert_array_equal(out.roots, g.roots)


def test_strands_whose_tip_is_farther_than_r_do_not_move():
    g = samples.scalp(300, 12, seed=2)
    c = np.array([1.5, -1.0, 0.0])
    r = 1.0
    out = align(g, c, r, 0.5)
    far = np.linalg.norm(g.tips - c, axis=1) > r
    assert far.any() and (~far).any()
    vid_far = np.repeat(far, g.counts)
    np.testing.assert_array_equal(out.points[vid_far], g.points[vid_far])
    assert np.abs(out.points[~vid_far] - g.points[~vid_far]).max() > 1e-2


@pytest.mark.parametrize(("mode", "x"), [("paper", 1.0), ("preserve-length", 1.0), ("preserve-length", 0.4)])
def test_repeated_alignment_toward_one_cursor_converges(mode, x):
    g = samples.scalp(100, 16, seed=3)
    c = np.array([0.0, 3.0, 2.0])
    steps = [g]
    for _ in range(300):
        steps.append(align(steps[-1], c, 100.0, x, mode))
    last, before = steps[-1], steps[-2]
    assert np.abs(last.points - before.points).max() < 1e-5  # a fixed point: no drift
    if mode == "preserve-length":
        np.testing.assert_allclose(last.segment_lengths, g.segment_lengths, rtol=1e-4, atol=1e-6)
    np.testing.assert_allclose(_unit(_v(last)), _unit(c - last.roots), atol=1e-3)


def test_paper_mode_is_printed_formula_13():
    g = samples.scalp(20, 8, seed=4)
    c = np.array([2.0, 0.5, 1.0])
    x = 0.3
    out = align(g, c, 100.0, x, "paper")
    for s in range(20):
        p = g.strand(s).astype(np.float64)
        root, n = p[0], len(p)
        v = p[-1] - p.mean(axis=0)
        u = c - root
        a = _unit(np.cross(v, u))
        phi = np.arccos(np.dot(v, u) / (np.linalg.norm(v) * np.linalg.norm(u)))
        k = np.array([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])
        R = np.eye(3) * np.cos(phi) + (1 - np.cos(phi)) * np.outer(a, a) + np.sin(phi) * k  # (5)
        w = np.arange(n) / (n - 1) * (1 - x) + x  # (12)
        off = p - root
        expect = root + w[:, None] * (off @ R.T) + (1 - w[:, None]) * off  # (13)
        np.testing.assert_allclose(out.strand(s), expect, atol=1e-5)


def test_degenerate_strands_are_left_alone():
    straight = np.linspace([0, 0, 0], [0, -1, 0], 5)
    folded = np.array([[2, 0, 0], [2, -1, 0], [2, 1, 0], [2, 0, 0.0]])  # tip = mean: v = 0
    g = Groom.from_strands([straight, folded])
    # cursor on the root of strand 0, near the tip of strand 1
    out = align(g, [0.0, 0.0, 0.0], radius=10.0, intensity=1.0)
    np.testing.assert_array_equal(out.points, g.points)
    # cursor straight along v: nothing to turn
    out = align(g, [0.0, -3.0, 0.0], radius=10.0, intensity=1.0)
    np.testing.assert_array_equal(out.strand(0), g.strand(0))


def test_v_opposite_u_turns_by_pi_and_stays_finite():
    straight = np.linspace([0, 0, 0], [0, -1, 0], 6)
    g = Groom.from_strands([straight, straight + np.array([0, 0, 1.0])])
    out = align(g, [0.0, 2.0, 0.0], radius=100.0, intensity=1.0)
    assert np.all(np.isfinite(out.points))
    np.testing.assert_allclose(out.strand(0), straight * [1, -1, 1], atol=1e-6)
    planar = Groom.from_strands([straight[:, :2]])
    out2 = align(planar, [0.0, 2.0], radius=100.0, intensity=1.0)
    assert out2.is_planar
    np.testing.assert_allclose(out2.strand(0), straight * [1, -1, 1], atol=1e-6)


def test_planar_grooms_stay_in_their_plane_even_for_an_off_plane_cursor():
    g = samples.portrait(100, 20)
    out = align(g, [1.5, 2.0, 0.7], 5.0, 0.2, "preserve-length")
    assert out.is_planar
    assert np.abs(out.points - g.points).max() > 0.1


@pytest.mark.parametrize("mode", ["paper", "preserve-length"])
@pytest.mark.parametrize("x", [0.0, 0.2, 0.8, 1.0])
def test_kernel_matches_numpy_twin(mode, x):
    rng = np.random.default_rng(5)
    counts = rng.integers(2, 15, 80)
    g = Groom(np.cumsum(rng.normal(size=(int(counts.sum()), 3)) * 0.1, axis=0), counts)
    for g_ in (g, samples.portrait(60, 12)):
        c = g_.points.mean(axis=0) + np.array([0.8, 0.4, 0.2])
        a = align(g_, c, 1.5, x, mode)
        b = align_reference(g_, c, 1.5, x, mode)
        np.testing.assert_allclose(a.points, b.points, atol=1e-5)


@pytest.mark.parametrize("name", ["sintel_hair.tfx", "ponytail_front_top.tfx"])
def test_kernel_matches_numpy_twin_on_real_grooms(grooms_dir, name):
    g = read_groom(grooms_dir / name)
    lo, hi = g.bounds
    c = (lo + hi) / 2 + (hi - lo) * [0.6, 0.3, 0.1]
    r = 0.6 * float(np.linalg.norm(hi - lo))
    for mode in ("paper", "preserve-length"):
        a, b = align(g, c, r, 0.6, mode), align_reference(g, c, r, 0.6, mode)
        scale = float(np.abs(g.points).max())
        np.testing.assert_allclose(a.points, b.points, atol=2e-6 * scale)
        assert np.abs(a.points - g.points).max() > 1e-2 * scale


def test_result_is_identical_whatever_the_thread_count():
    g = samples.scalp(500, 20)
    before = numba.get_num_threads()
    try:
        numba.set_num_threads(1)
        one = align(g, [1, 2, 3], 3.0, 0.3, "preserve-length").points.tobytes()
        numba.set_num_threads(min(2, numba.config.NUMBA_NUM_THREADS))
        two = align(g, [1, 2, 3], 3.0, 0.3, "preserve-length").points.tobytes()
    finally:
        numba.set_num_threads(before)
    assert one == two


@pytest.mark.parametrize(
    ("args", "name"),
    [
        (([0, 0, np.nan], 1.0, 0.5, "paper"), "cursor"),
        (([0, 0, 0, 0], 1.0, 0.5, "paper"), "cursor"),
        (([0, 0, 0], 0.0, 0.5, "paper"), "radius"),
        (([0, 0, 0], 1.0, 1.5, "paper"), "intensity"),
        (([0, 0, 0], 1.0, -0.1, "paper"), "intensity"),
        (([0, 0, 0], 1.0, 0.5, "rubber"), "mode"),
    ],
)
def test_bad_parameters_are_refused_by_name(args, name):
    with pytest.raises(ParameterError, match=name):
        align(samples.comb(9, 5), *args)
