"""A move's reach walked in one compiled call (:meth:`VertexGrid.reach`) against its numpy twin
(:func:`hairtool.frozen.local.reach_reference`): generated grooms, moves and nearest
neighbours, both gap modes, the limit, and the flags it keeps between calls left clear."""

from __future__ import annotations

import numpy as np
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from hairtool.frozen.local import reach_reference
from hairtool.frozen.spatial import pairs_within_reference
from hairtool.frozen.vertex_grid import VertexGrid, _reach_walks
from hairtool.groom import Groom, vertex_ids_of

R = 1.1  # the list radius (and the grid's cell)


def _groom(seed: int, strands: int) -> Groom:
    """Straight-ish strands of 6 vertices, roots scattered over a few list radii."""
    rng = np.random.default_rng(seed)
    out = []
    for _ in range(strands):
        root = np.array([*rng.uniform(0.0, 3.5, 2), 0.0])
        t = np.linspace(0.0, 1.0, 6)[:, None]
        line = root + t * np.array([0.0, 0.0, 3.0]) + rng.normal(scale=0.3, size=(6, 3))
        line[0] = root
        out.append(line)
    return Groom.from_strands(out)


def _nearest(points, strand, iterations, rng) -> np.ndarray:
    """``(iterations, V)`` nearest neighbours as a run records them: each a vertex of the
    vertex's list (another strand within R), drawn, or −1 (an empty list, or none drawn)."""
    ci, cj = pairs_within_reference(points, strand, R)
    best = np.full((iterations, points.shape[0]), -1, np.int64)
    for it in range(iterations):
        pick = rng.random(ci.size)
        for i, j, p in zip(ci, cj, pick, strict=True):
            if p < 0.5:
                best[it, i] = j
    return best


@settings(max_examples=30, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    seed=st.integers(0, 2**16),
    strands=st.integers(2, 40),
    moved=st.integers(1, 4),
    iterations=st.integers(0, 3),
    gap=st.booleans(),
    still=st.booleans(),
)
def test_the_compiled_reach_is_its_numpy_twin_and_leaves_its_flags_clear(
    seed, strands, moved, iterations, gap, still
):
    g = _groom(seed, strands)
    top = g.topology
    rng = np.random.default_rng(seed + 1)
    grid = VertexGrid(g.points, top.strand_index, R)
    hit = rng.choice(g.strand_count, min(moved, g.strand_count), replace=False)
    changed = vertex_ids_of(top, np.sort(hit))
    pts = g.points.copy()
    if not still:  # (still: the clump strength changed, not the points)
        pts[changed] += rng.normal(scale=0.6, size=(changed.size, 3)).astype(np.float32)
    grid.move(pts, changed)
    best = _nearest(pts, top.strand_index, iterations, rng)
    mode = "printed" if gap else "off"
    want = reach_reference(g.points, pts, top.strand_index, changed, R, best, mode)

    def reach(most):
        return grid.reach(pts, g.points[changed], changed, best, gap, iterations, R, most)

    for _ in range(2):  # twice: what the first call flagged is clear for the second
        got = reach(g.vertex_count)
        assert got is not None and np.array_equal(got, want)
        assert not grid._flags.any()
    if want.size > changed.size:  # past the limit: none, and the flags clear still
        assert reach(want.size - 1) is None
        assert not grid._flags.any()
        assert np.array_equal(reach(want.size), want)


def test_the_reach_compiles_once_whoever_holds_the_points():
    """Writable, read-only or Fortran-ordered points, the same answer and one signature (its
    inputs read-only and C-ordered: :func:`hairtool.kernel_arrays.readonly`)."""
    g = _groom(3, 12)
    top = g.topology
    changed = vertex_ids_of(top, np.array([2, 5]))
    pts = g.points.copy()
    pts[changed] += np.float32(0.4)
    best = _nearest(pts, top.strand_index, 2, np.random.default_rng(0))
    got = []
    for p in (pts.copy(), _readonly(pts), np.asfortranarray(pts)):
        grid = VertexGrid(p, top.strand_index, R)
        got.append(grid.reach(p, g.points[changed], changed, best, True, 2, R, g.vertex_count))
    assert all(np.array_equal(x, got[0]) for x in got)
    for sig in _reach_walks.signatures:
        assert all(t.layout == "C" and not t.mutable for t in sig[:7]), sig


def _readonly(a: np.ndarray) -> np.ndarray:
    b = a.copy()
    b.flags.writeable = False
    return b
