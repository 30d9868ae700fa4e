"""ClumpWithGaps (eqs. 14–19): adhesion toward other strands, gaps, kernels vs numpy twins."""

from __future__ import annotations

import numba
import numpy as np
import pytest

from hairtool import samples
from hairtool.errors import ParameterError
from hairtool.frozen.clump import ClumpWorkspace, clump, clump_reference
from hairtool.frozen.spatial import NeighbourList, pairs_within_reference
from hairtool.frozen.strand_clumps import auto_clump_radius
from hairtool.groom import Groom
from hairtool.io import read_groom


def _nearest_other(g: Groom, reach: float) -> np.ndarray:
    """Distance of each non-root vertex to the nearest vertex of another strand (inf beyond reach)."""
    i, j = pairs_within_reference(g.points, g.topology.strand_index, reach)
    d = np.linalg.norm(g.points[j].astype(np.float64) - g.points[i], axis=1)
    out = np.full(g.vertex_count, np.inf)
    np.minimum.at(out, i, d)
    return np.delete(out, g.topology.root_indices)


def _median_nearest_other(g: Groom, reach: float) -> float:
    """The median of :func:`_nearest_other` within ``reach``, searched first within a third of it:
    a vertex found there has its exact distance, every other one is farther than all of those,
    so when more than half are found the median is already exact (a ninth of the pairs to list;
    the comb's 6.8 million pairs within ``reach`` took 14 s of CPU for the four medians)."""
    near = _nearest_other(g, reach / 3)
    if np.count_nonzero(np.isfinite(near)) > len(near) // 2:  # both middle places are found ones
        return float(np.median(near))
    return float(np.median(_nearest_other(g, reach)))


@pytest.mark.parametrize("reach", [0.3, 1.0])  # a fifth found within reach / 3, then nearly all
def test_the_median_searched_within_a_third_first_is_the_median_within_reach(reach):
    g = samples.scalp(80, 8, seed=2)
    assert _median_nearest_other(g, reach) == np.median(_nearest_other(g, reach))


def test_two_close_strands_pull_together_and_an_isolated_strand_stays():
    a = np.linspace([0, 0, 0], [0, -1, 0], 11)
    b = a + np.array([0.05, 0, 0])
    far = a + np.array([5.0, 0, 0])
    g = Groom.from_strands([a, b, far])
    out = clump(g, radius=0.1, iterations=3, step=0.05, gap_mode="off")
    gap_before = np.linalg.norm(g.strand(1) - g.strand(0), axis=1)[1:]
    gap_after = np.linalg.norm(out.strand(1) - out.strand(0), axis=1)[1:]
    assert np.all(gap_after < gap_before - 1e-4)
    np.testing.assert_array_equal(out.strand(2), g.strand(2))
    np.testing.assert_array_equal(out.roots, g.roots)


def test_a_single_step_is_formula_15_16():
    p = np.array([[0, 0, 0], [0, -1, 0.0]])
    q = p + np.array([0.3, 0, 0])
    g = Groom.from_strands([p, q])
    h, step = 0.5, 0.1
    out = clump(g, h, iterations=1, step=step, gap_mode="off")
    force = (1 - 0.3 / h) ** 2  # g(r) (14), unit direction (15)
    np.testing.assert_allclose(out.points[1], [step * force, -1, 0], atol=1e-6)
    np.testing.assert_allclose(out.points[3], [0.3 - step * force, -1, 0], atol=1e-6)


def test_vertices_of_the_same_strand_do_not_attract_each_other():
    curl = np.array([[0, 0, 0], [0.1, -0.1, 0], [0, -0.2, 0], [0.1, -0.3, 0.0]])
    g = Groom.from_strands([curl])
    np.testing.assert_array_equal(clump(g, 1.0, 5, 0.1, "off").points, g.points)


def test_gap_correction_keeps_more_space_than_plain_adhesion():
    for g in (samples.scalp(600, 20, seed=1), read_groom_or_scalp()):
        h = auto_clump_radius(g)
        before = _median_nearest_other(g, 3 * h)
        off = _median_nearest_other(clump(g, h, 3, None, "off", 0), 3 * h)
        printed = _median_nearest_other(clump(g, h, 3, None, "printed", 0), 3 * h)
        text = _median_nearest_other(clump(g, h, 3, None, "text", 0), 3 * h)
        assert off < before  # adhesion pulls strands together
        assert printed > 1.1 * off and text > 1.1 * off


def read_groom_or_scalp() -> Groom:
    return samples.comb(400, 20, seed=3, spacing=0.05)


def _random_groom(seed: int) -> Groom:
    rng = np.random.default_rng(seed)
    counts = rng.integers(2, 12, 150)
    roots = rng.uniform(-1, 1, (150, 3))
    pts = np.concatenate(
        [r + np.cumsum(rng.normal(size=(c, 3)) * 0.08, axis=0) for r, c in zip(roots, counts, strict=True)]
    )
    pts[np.r_[0, np.cumsum(counts)[:-1]]] = roots
    return Groom(pts, counts)


@pytest.mark.parametrize("gap_mode", ["printed", "text", "off"])
@pytest.mark.parametrize(
    "make", [lambda: _random_groom(2), lambda: samples.portrait(200, 20), lambda: samples.comb(100, 10)]
)
def test_kernel_matches_numpy_twin(gap_mode, make):
    g = make()
    h = auto_clump_radius(g) * 1.5
    a = clump(g, h, 4, None, gap_mode, seed=3)
    b = clump_reference(g, h, 4, None, gap_mode, seed=3)
    np.testing.assert_allclose(a.points, b.points, atol=1e-6)
    assert np.abs(a.points - g.points).max() > 1e-3 * h


@pytest.mark.parametrize("name", ["sintel_hair.tfx", "ponytail_back.tfx", "ratboy_mohawk.tfx"])
def test_kernel_matches_numpy_twin_on_real_grooms(grooms_dir, name):
    g = read_groom(grooms_dir / name)
    h = auto_clump_radius(g)
    ws = ClumpWorkspace()
    a = clump(g, h, 3, None, "printed", 1, ws)
    b = clump_reference(g, h, 3, None, "printed", 1)
    np.testing.assert_allclose(a.points, b.points, atol=1e-5 * h)
    assert ws.mean_neighbours > 1
    assert np.abs(a.points - g.points).max() > 0.05 * h


def test_planar_grooms_stay_planar_and_roots_stay():
    g = samples.portrait(300, 20)
    out = clump(g, 3 * auto_clump_radius(g), 3)
    assert out.is_planar
    np.testing.assert_array_equal(out.roots, g.roots)


def test_same_seed_same_bytes_and_thread_count_does_not_matter():
    g = samples.scalp(800, 20, seed=4)
    h = auto_clump_radius(g)
    before = numba.get_num_threads()
    try:
        numba.set_num_threads(1)
        one = clump(g, h, 3, None, "printed", 7).points.tobytes()
        numba.set_num_threads(min(2, numba.config.NUMBA_NUM_THREADS))
        two = clump(g, h, 3, None, "printed", 7).points.tobytes()
    finally:
        numba.set_num_threads(before)
    assert one == two
    assert clump(g, h, 3, None, "printed", 8).points.tobytes() != one


@pytest.mark.parametrize(
    ("kwargs", "name"),
    [
        ({"radius": 0.0}, "clump_radius"),
        ({"radius": -1.0}, "clump_radius"),
        ({"radius": float("inf")}, "clump_radius"),
        ({"radius": 1.0, "iterations": 101}, "clump_iterations"),
        ({"radius": 1.0, "iterations": -1}, "clump_iterations"),
        ({"radius": 1.0, "iterations": 2.5}, "clump_iterations"),
        ({"radius": 1.0, "step": -0.1}, "clump_step"),
        ({"radius": 1.0, "gap_mode": "wide"}, "gap_mode"),
        ({"radius": 1e-12}, "clump_radius"),
    ],
)
def test_bad_parameters_are_refused_by_name(kwargs, name):
    with pytest.raises(ParameterError, match=name):
        clump(samples.comb(9, 5), **kwargs)


def test_equally_near_partners_go_to_the_lower_vertex_index():
    # The middle strand is exactly as near to the strand on its right (index 1) as to the one on
    # its left (index 2); a fourth strand pulls the right one away, so the gap correction's
    # result depends on which partner is taken (the other choice moves points by ~2e-5).
    y = np.linspace(0.0, -1.0, 6)
    strand = lambda x: np.column_stack([np.full(6, x), y, np.zeros(6)])  # noqa: E731
    g = Groom.from_strands([strand(0.0), strand(0.25), strand(-0.25), strand(0.45)])
    for gap_mode in ("printed", "text"):
        a = clump(g, 0.4, 3, 0.05, gap_mode, seed=2)
        b = clump_reference(g, 0.4, 3, 0.05, gap_mode, seed=2)
        np.testing.assert_allclose(a.points, b.points, atol=1e-7)


def test_both_grids_lists_go_through_the_pair_arrays_to_the_twins_pulls(grooms_dir, monkeypatch):
    """Every list takes each entry's r and weight from the pair arrays: the row grid's (a
    backward entry reads its pair's forward one through the map) and the hashed grid's (whole
    lists, no map, even in a workspace whose last list was a row grid's) give the numpy twin,
    the same bytes at 1 and 2 threads, and ties to the lower vertex index (the other partner
    moves points by ~2e-5)."""
    g = read_groom(grooms_dir / "sintel_hair.tfx")
    h = auto_clump_radius(g)
    want = clump_reference(g, h, 3, None, "printed", 3).points
    build = NeighbourList.build
    grid = {"dense": True}

    def one_grid(self, points, strand, skip, radius, _pick=None):
        build(self, points, strand, skip, radius, grid["dense"])

    monkeypatch.setattr(NeighbourList, "build", one_grid)
    before = numba.get_num_threads()
    try:
        for n in (1, 2):
            numba.set_num_threads(min(n, numba.config.NUMBA_NUM_THREADS))
            ws = ClumpWorkspace()
            runs = []
            for dense in (True, False):
                grid["dense"] = dense
                ws.invalidate()
                runs.append(clump(g, h, 3, None, "printed", 3, ws).points)
                assert ws.neighbours.dense == dense
                np.testing.assert_allclose(runs[-1], want, atol=1e-5 * h)
            if n == 1:
                first = runs
            else:
                assert [r.tobytes() for r in runs] == [r.tobytes() for r in first]
    finally:
        numba.set_num_threads(before)
    y = np.linspace(0.0, -1.0, 6)
    strand = lambda x: np.column_stack([np.full(6, x), y, np.zeros(6)])  # noqa: E731
    tied = Groom.from_strands([strand(0.0), strand(0.25), strand(-0.25), strand(0.45)])
    for gap_mode in ("printed", "text"):
        a = clump(tied, 0.4, 3, 0.05, gap_mode, seed=2)
        b = clump_reference(tied, 0.4, 3, 0.05, gap_mode, seed=2)
        np.testing.assert_allclose(a.points, b.points, atol=1e-7)
