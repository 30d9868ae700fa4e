"""The nearest roots of query points, found through a uniform grid of the roots instead of a
table of every pair: planting 999 strands beside 50,000 asked a 590 MB distance table and
50 million distances per sample; the grid looks at the few cells around each query.

The answers are those of the all-pairs search, bit for bit: the distance is computed the same
way (squared, in the arrays' own precision, or its float64 square root), the lists are sorted
by (distance, root) as :func:`hairtool.guides.surface.insert_nearest` keeps them, so a tie goes
to the lower root index as ``argmin`` gives it, and the search widens ring by ring until no
unvisited cell can hold a root as near as the last one kept. The ``*_reference`` functions are
the numpy twins the tests compare against.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from hairtool.kernel_arrays import readonly

PER_CELL = 4.0  # roots a root sees in its cell, on average, that the cell size aims at
_MAX_HALVINGS = 24  # halvings of the cell size at most
_MAX_DIM = 1 << 20  # cells along an axis at most
_MARGIN = 1e-5  # the ring bound is shrunk by this share: rounding never ends a search early


def _cells(roots: np.ndarray, lo: np.ndarray, h: float) -> tuple[np.ndarray, np.ndarray]:
    c = np.floor((roots - lo) / h).astype(np.int64)
    dims = c.max(axis=0) + 1
    return (c[:, 0] * dims[1] + c[:, 1]) * dims[2] + c[:, 2], dims


def _crowding(key: np.ndarray) -> float:
    """Roots a root shares its cell with, on average (its own included)."""
    _, n = np.unique(key, return_counts=True)
    return float((n.astype(np.float64) ** 2).sum() / len(key))


def _grid(roots: np.ndarray) -> tuple:
    """The occupied cells' keys in order, each one's first row of the roots sorted by cell,
    those roots and their indices, the box corner, the cell size and the grid's dims. The cell
    size starts where the distinct roots would fill their box evenly, then halves while a
    distinct root's cell stays crowded (roots on a sheet, in clusters); copies of one root
    count once, since no cell can split them."""
    lo = roots.min(axis=0).astype(np.float64)
    ext = roots.max(axis=0).astype(np.float64) - lo
    span = float(ext.max())
    rows = roots[np.lexsort(roots.T)]
    distinct = rows[np.r_[True, np.any(rows[1:] != rows[:-1], axis=1)]]
    if span > 0:
        h = float(np.cbrt(np.prod(np.maximum(ext, span * 1e-3)) * PER_CELL / len(distinct)))
        for _ in range(_MAX_HALVINGS):
            if span / (h / 2.0) >= _MAX_DIM or _crowding(_cells(distinct, lo, h)[0]) <= PER_CELL:
                break
            h /= 2.0
    else:
        h = 1.0
    key, dims = _cells(roots, lo, h)
    order = np.argsort(key, kind="stable")
    keys, first = np.unique(key[order], return_index=True)
    starts = np.append(first, len(roots)).astype(np.int64)
    return keys, starts, np.ascontiguousarray(roots[order]), order.astype(np.int64), lo, h, dims


@njit(cache=True, nogil=True, inline="always")
def _insert(out_g, out_d, q, g, d, kk):
    """(d, g) into row q's list of the kk best, sorted by (distance, root)."""
    pos = kk
    for m in range(kk):
        if d < out_d[q, m] or (d == out_d[q, m] and (out_g[q, m] < 0 or g < out_g[q, m])):
            pos = m
            break
    if pos == kk:
        return
    for m in range(kk - 1, pos, -1):
        out_g[q, m] = out_g[q, m - 1]
        out_d[q, m] = out_d[q, m - 1]
    out_g[q, pos] = g
    out_d[q, pos] = d


@njit(cache=True, nogil=True, inline="always")
def _scan(pts, ids, a, b, queries, q, kk, take_sqrt, out_g, out_d, out_n):
    out_n[q] += b - a
    px, py, pz = queries[q, 0], queries[q, 1], queries[q, 2]
    for s in range(a, b):
        dx = pts[s, 0] - px
        dy = pts[s, 1] - py
        dz = pts[s, 2] - pz
        d2 = dx * dx + dy * dy + dz * dz
        d = np.sqrt(np.float64(d2)) if take_sqrt else np.float64(d2)
        if d <= out_d[q, kk - 1]:
            _insert(out_g, out_d, q, ids[s], d, kk)


@njit(cache=True, nogil=True, parallel=True)
def _kernel(keys, starts, pts, ids, lo, h, dims, queries, kk, take_sqrt, out_g, out_d, out_n):
    nx, ny, nz = dims[0], dims[1], dims[2]
    for q in prange(queries.shape[0]):
        out_n[q] = 0
        for m in range(kk):
            out_g[q, m] = -1
            out_d[q, m] = np.inf
        r = 0
        cx, cy, cz = 0, 0, 0
        if len(keys) > 1:  # one cell (non-finite input among them): every root at once
            cx = np.int64(min(max(np.floor((np.float64(queries[q, 0]) - lo[0]) / h), 0.0), nx - 1.0))
            cy = np.int64(min(max(np.floor((np.float64(queries[q, 1]) - lo[1]) / h), 0.0), ny - 1.0))
            cz = np.int64(min(max(np.floor((np.float64(queries[q, 2]) - lo[2]) / h), 0.0), nz - 1.0))
        while True:
            if (2 * r + 1) ** 3 >= len(keys):  # a ring of more cells than are held: every root
                for m in range(kk):
                    out_g[q, m] = -1
                    out_d[q, m] = np.inf
                _scan(pts, ids, 0, len(ids), queries, q, kk, take_sqrt, out_g, out_d, out_n)
                break
            for ix in range(max(cx - r, 0), min(cx + r, nx - 1) + 1):
                for iy in range(max(cy - r, 0), min(cy + r, ny - 1) + 1):
                    step = 1 if (abs(ix - cx) == r or abs(iy - cy) == r) else max(2 * r, 1)
                    iz = cz - r
                    while iz <= cz + r:
                        if 0 <= iz < nz:
                            key = (ix * ny + iy) * nz + iz
                            at = np.searchsorted(keys, key)
                            if at < len(keys) and keys[at] == key:
                                a, b = starts[at], starts[at + 1]
                                _scan(pts, ids, a, b, queries, q, kk, take_sqrt, out_g, out_d, out_n)
                        iz += step
            reach = r * h * (1.0 - _MARGIN)  # every root in an unvisited cell lies at least this far
            if not take_sqrt:
                reach = reach * reach
            if out_d[q, kk - 1] < reach:
                break
            r += 1


def _search(roots: np.ndarray, queries: np.ndarray, kk: int, take_sqrt: bool) -> tuple:
    dtype = np.result_type(roots.dtype, queries.dtype, np.float32)
    roots = np.ascontiguousarray(roots, dtype).reshape(-1, 3)
    queries = np.ascontiguousarray(queries, dtype).reshape(-1, 3)
    out_g = np.empty((len(queries), kk), np.int64)
    out_d = np.empty((len(queries), kk))
    out_n = np.zeros(len(queries), np.int64)
    if len(roots) == 0 or len(queries) == 0:
        out_g.fill(-1)
        out_d.fill(np.inf)
        return out_g, out_d, out_n
    if np.all(np.isfinite(roots)) and np.all(np.isfinite(queries)):
        keys, starts, pts, ids, lo, h, dims = _grid(roots)
    else:  # one cell: every query scans every root, as the all-pairs search did
        keys, starts = np.zeros(1, np.int64), np.array([0, len(roots)], np.int64)
        pts, ids, lo, h, dims = roots, np.arange(len(roots)), np.zeros(3), 1.0, np.ones(3, np.int64)
    # read-only inputs: one compilation per precision, whoever made the arrays (a groom's own
    # read-only roots, a brush's fresh queries)
    inputs = (readonly(a) for a in (keys, starts, pts, ids, lo))
    _kernel(*inputs, h, readonly(dims), readonly(queries), kk, take_sqrt, out_g, out_d, out_n)
    return out_g, out_d, out_n


def nearest_root(roots: np.ndarray, queries: np.ndarray) -> np.ndarray:
    """For each query, the index of the root at the smallest squared distance in the arrays'
    common precision, the lowest index on a tie: ``argmin(((q[:, None] − r[None]) ** 2).sum(−1),
    axis=1)`` without the table.

    Parameters
    ----------
    roots : ndarray
        ``(R ≥ 1, 3)`` roots.
    queries : ndarray
        ``(N, 3)`` points.

    Returns
    -------
    ndarray
        ``(N,)`` int64 root indices.
    """
    return _search(np.asarray(roots), np.asarray(queries), 1, False)[0][:, 0]


def nearest_root_reference(roots: np.ndarray, queries: np.ndarray) -> np.ndarray:
    """Numpy twin of :func:`nearest_root`: the all-pairs table and ``argmin``."""
    dtype = np.result_type(np.asarray(roots).dtype, np.asarray(queries).dtype, np.float32)
    r, q = np.asarray(roots, dtype), np.asarray(queries, dtype)
    return np.argmin(((q[:, None, :] - r[None, :, :]) ** 2).sum(-1), axis=1)


def nearest_roots(roots: np.ndarray, queries: np.ndarray, kk: int) -> tuple[np.ndarray, np.ndarray]:
    """``(N, kk)`` nearest roots of each query in float64 and their distances, sorted by
    (distance, root); −1 / inf past the last root (what
    :func:`hairtool.guides.nearest.euclidean_nearest` returns).

    Parameters
    ----------
    roots : ndarray
        ``(R, 3)`` roots.
    queries : ndarray
        ``(N, 3)`` points.
    kk : int
        Roots per query.

    Returns
    -------
    tuple of (ndarray, ndarray)
        ``(N, kk)`` roots and distances.
    """
    return _search(np.asarray(roots, np.float64), np.asarray(queries, np.float64), int(kk), True)[:2]


def distances_computed(roots: np.ndarray, queries: np.ndarray, kk: int = 1) -> np.ndarray:
    """The work of :func:`nearest_roots`: how many root distances each query computed (the
    all-pairs search computed ``len(roots)`` each). Tests and benchmarks count it.

    Parameters
    ----------
    roots, queries, kk
        As :func:`nearest_roots` takes them.

    Returns
    -------
    ndarray
        ``(N,)`` int64 distances computed per query.
    """
    return _search(np.asarray(roots, np.float64), np.asarray(queries, np.float64), int(kk), True)[2]
