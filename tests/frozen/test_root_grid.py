"""The nearest-root grid against its numpy twins, on generated roots with ties (points on a
coarse lattice, repeated points, clusters, queries far outside): the same indices and the same
distance bits as the all-pairs tables."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from hairtool.frozen.root_grid import distances_computed, nearest_root, nearest_root_reference, nearest_roots
from hairtool.guides.nearest import euclidean_nearest_reference


@st.composite
def clouds(draw):
    """Roots and queries: lattice points (many equal distances), a pile of copies of a few roots,
    and a dense cluster beside sparse roots, in float32 or float64."""
    seed = draw(st.integers(0, 2**32 - 1))
    rng = np.random.default_rng(seed)
    n, m = draw(st.integers(1, 400)), draw(st.integers(1, 40))
    kind = draw(st.sampled_from(["lattice", "pile", "cluster"]))
    if kind == "lattice":
        roots = rng.integers(-8, 9, size=(n, 3)).astype(np.float64)
        queries = rng.integers(-20, 21, size=(m, 3)) / 2.0
    elif kind == "pile":
        roots = np.repeat(rng.normal(size=(draw(st.integers(1, 4)), 3)), n, axis=0)
        queries = rng.normal(size=(m, 3))
    else:
        roots = np.vstack([rng.normal(size=(n, 3)) * 10.0, rng.normal(size=(n, 3)) * 1e-3])
        queries = np.vstack([rng.normal(size=(m, 3)) * 1e-3, rng.normal(size=(2, 3)) * 1e3])
    dtype = draw(st.sampled_from([np.float32, np.float64]))
    return roots.astype(dtype), queries.astype(dtype)


@settings(max_examples=40, deadline=None)
@given(clouds(), st.integers(1, 6))
def test_the_grid_finds_what_the_all_pairs_tables_find(cloud, kk):
    roots, queries = cloud
    np.testing.assert_array_equal(nearest_root(roots, queries), nearest_root_reference(roots, queries))
    ids, d = nearest_roots(roots, queries, kk)
    rid, rd = euclidean_nearest_reference(roots.astype(np.float64), queries.astype(np.float64), kk - 1)
    np.testing.assert_array_equal(ids, rid)
    np.testing.assert_array_equal(d.view(np.int64), rd.view(np.int64))


def test_non_finite_roots_are_scanned_like_the_all_pairs_search():
    roots = np.array([[0.0, 0.0, 0.0], [np.nan, 0.0, 0.0], [1.0, 0.0, 0.0]])
    ids, d = nearest_roots(roots, np.array([[0.9, 0.0, 0.0]]), 3)
    assert ids.tolist() == [[2, 0, -1]] and np.isinf(d[0, 2])


def _cap(rng: np.random.Generator, n: int) -> np.ndarray:
    """``n`` roots on the top half of a sphere of radius 10: a scalp."""
    v = rng.normal(size=(n, 3))
    v /= np.linalg.norm(v, axis=1)[:, None]
    v[:, 1] = np.abs(v[:, 1])
    return (10.0 * v).astype(np.float32)


def test_the_work_per_new_root_does_not_grow_with_the_roots():
    """999 new roots in a brush's disc beside 1,000 or 64,000 scalp roots: the all-pairs search
    computed every root's distance for each (64,000); the grid computes a few dozen either way
    (measured: 33 and 49 on average)."""
    rng = np.random.default_rng(1)
    disc = rng.uniform(-1.5, 1.5, size=(999, 2))
    queries = np.column_stack([disc[:, 0], np.full(999, 10.0), disc[:, 1]]).astype(np.float32)
    few, many = _cap(rng, 1000), _cap(rng, 64_000)
    w_few, w_many = distances_computed(few, queries, 7).mean(), distances_computed(many, queries, 7).mean()
    assert w_many < 3.0 * w_few and w_many < 64_000 / 200, (w_few, w_many)
    np.testing.assert_array_equal(nearest_root(few, queries), nearest_root_reference(few, queries))
