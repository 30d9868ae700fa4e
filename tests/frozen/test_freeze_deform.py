"""FreezeDeform (eqs. 2–7): stiffness bounds, determinism, kernel vs numpy twin."""

from __future__ import annotations

import numba
import numpy as np
import pytest

from hairtool import samples
from hairtool.errors import ParameterError
from hairtool.frozen.freeze import freeze, freeze_reference, strand_multipliers
from hairtool.frozen.noise import hash_u01
from hairtool.groom import Groom
from hairtool.io import read_groom


def _random_groom(seed: int = 0, strands: int = 60) -> Groom:
    rng = np.random.default_rng(seed)
    counts = rng.integers(2, 12, strands)
    pts = np.cumsum(rng.normal(size=(int(counts.sum()), 3)) * 0.1, axis=0)
    return Groom(pts, counts)


def _angles(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    cos = np.einsum("ij,ij->i", a, b) / (np.linalg.norm(a, axis=1) * np.linalg.norm(b, axis=1))
    return np.arccos(np.clip(cos, -1.0, 1.0))


def test_huge_stiffness_leaves_the_groom_unchanged():
    g = samples.scalp(200, 16)
    out = freeze(g, 1e9, 1e9, np.radians(60), seed=3)
    np.testing.assert_allclose(out.points, g.points, atol=1e-5)


@pytest.mark.parametrize("ks", [1.5, 3.0, 7.0])
def test_segment_lengths_stay_within_one_over_ks(ks):
    g = samples.scalp(300, 20)
    out = freeze(g, ks, 7.0, np.radians(30), seed=1)
    ratio = out.segment_lengths / g.segment_lengths
    assert np.all(ratio >= 1 - 1 / ks - 1e-5) and np.all(ratio <= 1 + 1 / ks + 1e-5)
    # the noise uses the range: some segments come close to each bound
    assert ratio.min() < 1 - 0.9 / ks and ratio.max() > 1 + 0.9 / ks


@pytest.mark.parametrize("kb", [1.0, 3.0, 7.0])
def test_each_bend_rotation_is_at_most_theta_max_over_kb(kb):
    g = samples.scalp(300, 20)
    theta = np.radians(40)
    out = freeze(g, 1e9, kb, theta, seed=2)
    turn = _angles(g.segment_vectors.astype(np.float64), out.segment_vectors.astype(np.float64))
    assert turn.max() <= theta / kb + 1e-3
    assert turn.max() > 0.9 * theta / kb


def test_roots_never_move_and_planar_grooms_stay_planar():
    g = samples.portrait(120, 20)
    out = freeze(g, 2.0, 1.0, np.radians(90), seed=5, strand_variation=2.0)
    np.testing.assert_array_equal(out.roots, g.roots)
    assert out.is_planar
    g3 = samples.scalp(50, 10)
    np.testing.assert_array_equal(freeze(g3, 2.0, 2.0, 1.0).roots, g3.roots)


def test_same_seed_same_bytes_different_seed_different_noise():
    g = samples.scalp(100, 12)
    a = freeze(g, 3, 3, 0.5, seed=11)
    b = freeze(g, 3, 3, 0.5, seed=11)
    c = freeze(g, 3, 3, 0.5, seed=12)
    assert a.points.tobytes() == b.points.tobytes()
    assert np.abs(a.points - c.points).max() > 1e-3


def test_noise_of_a_strand_does_not_depend_on_the_other_strands():
    g = samples.scalp(40, 10)
    full = freeze(g, 3, 3, 0.5, seed=4)
    # strand 0 alone in a groom still has index 0, so it gets the same noise
    alone = freeze(g.subset([0]), 3, 3, 0.5, seed=4)
    np.testing.assert_array_equal(alone.points, full.strand(0))


def test_hash_is_uniform_and_seeded():
    u = hash_u01(7, np.arange(100_000), 3, 1)
    assert 0.0 <= u.min() and u.max() < 1.0
    assert abs(u.mean() - 0.5) < 0.01 and abs(u.var() - 1 / 12) < 0.002
    assert not np.array_equal(u, hash_u01(8, np.arange(100_000), 3, 1))


@pytest.mark.parametrize("make", [lambda: _random_groom(1), lambda: samples.portrait(80, 15), samples.comb])
def test_kernel_matches_numpy_twin(make):
    g = make()
    for variation in (0.0, 1.5):
        a = freeze(g, 2.5, 1.5, np.radians(50), seed=9, strand_variation=variation)
        b = freeze_reference(g, 2.5, 1.5, np.radians(50), seed=9, strand_variation=variation)
        np.testing.assert_allclose(a.points, b.points, atol=2e-6)


@pytest.mark.parametrize("name", ["sintel_hair.tfx", "ponytail_tail.tfx", "ratboy_mohawk.tfx"])
def test_kernel_matches_numpy_twin_on_real_grooms(grooms_dir, name):
    g = read_groom(grooms_dir / name)
    a = freeze(g, 3.0, 3.0, np.radians(30), seed=1)
    b = freeze_reference(g, 3.0, 3.0, np.radians(30), seed=1)
    scale = float(np.abs(g.points).max())
    np.testing.assert_allclose(a.points, b.points, atol=1e-6 * scale)
    assert np.abs(a.points - g.points).max() > 1e-3 * scale


def test_result_is_identical_whatever_the_thread_count():
    g = samples.scalp(500, 20)
    before = numba.get_num_threads()
    try:
        numba.set_num_threads(1)
        one = freeze(g, 3, 3, 0.5, seed=2, strand_variation=1.0).points.tobytes()
        numba.set_num_threads(min(2, numba.config.NUMBA_NUM_THREADS))
        two = freeze(g, 3, 3, 0.5, seed=2, strand_variation=1.0).points.tobytes()
    finally:
        numba.set_num_threads(before)
    assert one == two


def test_strand_variation_spread_and_array():
    m = strand_multipliers(1000, 1.0, seed=3)
    assert m.min() >= 0.5 and m.max() <= 2.0 and m.std() > 0.2
    g = samples.scalp(30, 10)
    stiff = np.full(30, 1e9)
    stiff[0] = 1e-9  # strand 0 soft (clamped to k_s = 1), the rest rigid
    out = freeze(g, 7.0, 7.0, 0.5, seed=1, strand_variation=stiff)
    moved = np.abs(out.points - g.points).max(axis=1)
    assert moved[: g.counts[0]].max() > 1e-3
    assert moved[g.counts[0] :].max() < 1e-5


@pytest.mark.parametrize(
    ("kwargs", "name"),
    [
        ({"stretch_stiffness": -1.0}, "stretch_stiffness"),
        ({"stretch_stiffness": 0.5}, "stretch_stiffness"),
        ({"bend_stiffness": 0.0}, "bend_stiffness"),
        ({"bend_stiffness": float("nan")}, "bend_stiffness"),
        ({"max_bend_angle": 4.0}, "max_bend_angle"),
        ({"seed": -1}, "seed"),
        ({"strand_variation": 9.0}, "strand_variation"),
        ({"strand_variation": np.ones(3)}, "strand_variation"),
    ],
)
def test_bad_parameters_are_refused_by_name(kwargs, name):
    with pytest.raises(ParameterError, match=name):
        freeze(samples.comb(9, 5), **kwargs)
