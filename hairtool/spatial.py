"""Neighbours between strands: a uniform grid of cells one search radius r wide.

The usual path groups vertices into rows along x (a 2-D grid of cells r wide over y and z,
counting sort) and sorts each row by x; a vertex then scans the non-empty rows of the 3 × 3
around it that come within r, each only over the x-window where the sphere of radius r
crosses that row, with sweep pointers that only move forward. Grooms in a box too large for a
row table fall back to a spatial hash of 3-D cells (~2V buckets; a candidate counts only if
its exact cell matches, so collisions never count twice). Lists come in the same order
whatever the thread count. :func:`pairs_within_reference` is the plain numpy twin.
Clump radius and clump membership helpers live in :mod:`hairtool.strand_clumps`.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from hairtool.errors import ParameterError

_BITS = 21  # bits per cell coordinate in a packed 64-bit cell key
_MAXC = (1 << _BITS) - 2
_HASH = np.uint64(0x9E3779B97F4A7C15)


@njit(cache=True)
def _bounds(p):
    lo = np.full(3, np.inf)
    hi = np.full(3, -np.inf)
    for i in range(p.shape[0]):
        for a in range(3):
            x = np.float64(p[i, a])
            lo[a] = min(lo[a], x)
            hi[a] = max(hi[a], x)
    return lo, hi


@njit(cache=True, parallel=True)
def _cell_keys(p, lo, inv_cell, shift, keys, buckets):
    for i in prange(p.shape[0]):
        cx = np.int64(np.floor((p[i, 0] - lo[0]) * inv_cell))
        cy = np.int64(np.floor((p[i, 1] - lo[1]) * inv_cell))
        cz = np.int64(np.floor((p[i, 2] - lo[2]) * inv_cell))
        k = cx | (cy << _BITS) | (cz << (2 * _BITS))
        keys[i] = k
        buckets[i] = np.int64((np.uint64(k) * _HASH) >> shift)


@njit(cache=True)
def _counting_sort(buckets, n_buckets, start, order):
    start[:] = 0
    for i in range(buckets.size):
        start[buckets[i] + 1] += 1
    for b in range(n_buckets):
        start[b + 1] += start[b]
    fill = start[:-1].copy()
    for i in range(buckets.size):  # stable: original order within a bucket
        b = buckets[i]
        order[fill[b]] = i
        fill[b] += 1


@njit(cache=True, parallel=True)
def _neighbour_kernel(sp, skey, sstrand, sskip, start, shift, r2, nbr, cnt):
    v_count = sp.shape[0]
    cap = nbr.shape[1]
    mask = np.int64((1 << _BITS) - 1)
    for i in prange(v_count):
        if sskip[i]:
            cnt[i] = 0
            continue
        k = skey[i]
        cx, cy, cz = k & mask, (k >> _BITS) & mask, k >> (2 * _BITS)
        px, py, pz = np.float64(sp[i, 0]), np.float64(sp[i, 1]), np.float64(sp[i, 2])
        si = sstrand[i]
        n = 0
        for dz in range(-1, 2):
            z = cz + dz
            if z < 0:
                continue
            for dy in range(-1, 2):
                y = cy + dy
                if y < 0:
                    continue
                for dx in range(-1, 2):
                    x = cx + dx
                    if x < 0:
                        continue
                    nk = x | (y << _BITS) | (z << (2 * _BITS))
                    b = np.int64((np.uint64(nk) * _HASH) >> shift)
                    for j in range(start[b], start[b + 1]):
                        if skey[j] != nk or sstrand[j] == si:
                            continue
                        ex = np.float64(sp[j, 0]) - px
                        ey = np.float64(sp[j, 1]) - py
                        ez = np.float64(sp[j, 2]) - pz
                        if ex * ex + ey * ey + ez * ez < r2:
                            if n < cap:
                                nbr[i, n] = j
                            n += 1
        cnt[i] = n


@njit(cache=True, parallel=True)
def _row_keys(p, lo, inv_cell, ny, nz, keys):
    for i in prange(p.shape[0]):
        cy = min(np.int64(np.floor((p[i, 1] - lo[1]) * inv_cell)), ny - 1)
        cz = min(np.int64(np.floor((p[i, 2] - lo[2]) * inv_cell)), nz - 1)
        keys[i] = cz * ny + cy


@njit(cache=True, parallel=True)
def _sort_rows_by_x(order, start, x):
    """Inside each row's run of ``order``, sort by x (stable, so ties keep vertex order)."""
    for r in prange(start.size - 1):
        a, b = start[r], start[r + 1]
        if b - a > 32:
            seg = order[a:b].copy()
            idx = np.argsort(x[seg], kind="mergesort")
            for k in range(b - a):
                order[a + k] = seg[idx[k]]
        else:
            for i in range(a + 1, b):  # insertion sort: rows are short
                v = order[i]
                xv = x[v]
                j = i - 1
                while j >= a and x[order[j]] > xv:
                    order[j + 1] = order[j]
                    j -= 1
                order[j + 1] = v


@njit(cache=True, parallel=True)
def _gather(order, points, strand, skip, keys, sp, sx, sstrand, sskip, skeys):
    for k in prange(order.size):
        i = order[k]
        for a in range(3):
            sp[k, a] = points[i, a]
        sx[k] = np.float64(sp[k, 0])
        sstrand[k] = strand[i]
        sskip[k] = skip[i]
        skeys[k] = keys[i]


@njit(cache=True, parallel=True)
def _row_neighbour_kernel(sp, sx, sstrand, start, ny, nz, lo, cell, r2, nbr, cnt):
    """Forward half of the pairs: rows of cells along x (a 2-D grid over y, z), each sorted by x;
    vertex i (sorted position) finds the j > i within r: in its own row to its right and in the
    4 rows after it, each only over the x-window where the sphere of radius r crosses the row.
    The vertices of a row are visited in x order, so per row a pointer to the window's start
    only moves forward (a sweep line). One task per row: deterministic."""
    cap = nbr.shape[1]
    reach = np.sqrt(r2) * (1.0 + 1e-6) + 1e-12 * cell
    for r in prange(start.size - 1):
        a0, b0 = start[r], start[r + 1]
        if a0 == b0:
            continue
        cy = r % ny
        cz = r // ny
        rows = np.empty(5, np.int64)
        ptr = np.empty(5, np.int64)
        slab = np.empty((5, 4))  # y and z bounds of each row, a little wider for rounding
        m = 0
        for z in range(cz, min(cz + 2, nz)):
            for y in range(max(cy - 1, 0), min(cy + 2, ny)):
                row = z * ny + y
                if row < r or start[row] == start[row + 1]:
                    continue  # rows before this one (their pairs come from them) or empty
                rows[m] = row
                ptr[m] = start[row]
                slab[m, 0] = lo[1] + y * cell - 1e-7 * cell
                slab[m, 1] = lo[1] + (y + 1) * cell + 1e-7 * cell
                slab[m, 2] = lo[2] + z * cell - 1e-7 * cell
                slab[m, 3] = lo[2] + (z + 1) * cell + 1e-7 * cell
                m += 1
        for i in range(a0, b0):
            px, py, pz = sx[i], np.float64(sp[i, 1]), np.float64(sp[i, 2])
            si = sstrand[i]
            n = 0
            for q in range(m):
                # distance from p to the row's (y, z) square (0 inside)
                dy = max(slab[q, 0] - py, py - slab[q, 1], 0.0)
                dz = max(slab[q, 2] - pz, pz - slab[q, 3], 0.0)
                rest = r2 - dy * dy - dz * dz
                if rest <= 0.0:
                    continue
                row = rows[q]
                end = start[row + 1]
                j = ptr[q]
                while j < end and sx[j] <= px - reach:  # monotone in px: never moves back
                    j += 1
                ptr[q] = j
                if row == r:
                    j = max(j, i + 1)  # own row: only the vertices after i
                w = np.sqrt(rest) * (1.0 + 1e-6) + 1e-12 * cell  # x half-window, a hair wide
                xb = px + w  # entries left of px − w fail the distance test below
                # Branch-free body (the test outcome is unpredictable): always write, count hits.
                while j < end and sx[j] < xb:
                    ex = sx[j] - px
                    ey = np.float64(sp[j, 1]) - py
                    ez = np.float64(sp[j, 2]) - pz
                    hit = (ex * ex + ey * ey + ez * ez < r2) & (sstrand[j] != si)
                    nbr[i, min(n, cap - 1)] = j
                    n += np.int64(hit)
                    j += 1
            cnt[i] = n


@njit(cache=True)
def _mirror_pairs(nbr, cnt, sskip):
    """Complete the forward lists: each pair (i, j > i) is added to j's list after j's own
    forward entries, in increasing i (deterministic). Skipped vertices end with no list."""
    cap = nbr.shape[1]
    forward = cnt.copy()
    for i in range(cnt.size):
        for n in range(min(forward[i], cap - 1)):
            j = nbr[i, n]
            if not sskip[j]:
                if cnt[j] < cap - 1:
                    nbr[j, cnt[j]] = i
                cnt[j] += 1
    for i in range(cnt.size):
        if sskip[i]:
            cnt[i] = 0


class NeighbourList:
    """Vertices of other strands within ``radius``, in cell-sorted order.

    ``order[k]``: the original vertex at sorted position k; ``nbr[k, :cnt[k]]``: sorted positions
    of its neighbours. Vertices flagged in ``skip`` get no list (they still appear as neighbours).
    """

    def __init__(self) -> None:
        self.capacity = 16  # list slots per vertex; grows (and shrinks) with the densest vertex
        self.nbr = np.empty((0, self.capacity), np.int32)

    def build(
        self,
        points: np.ndarray,
        strand: np.ndarray,
        skip: np.ndarray,
        radius: float,
        dense: bool | None = None,
    ) -> None:
        """``dense``: force the dense grid (True) or the hashed one (False); None picks by size."""
        v = points.shape[0]
        lo, hi = _bounds(points)
        extent = float((hi - lo).max())
        if not np.isfinite(radius) or radius <= 0 or extent / radius >= _MAXC:
            raise ParameterError("clump_radius", radius, f"a distance above {extent / _MAXC:.3g}")
        inv = 1.0 / radius
        dims = (np.floor((hi - lo) * inv).astype(np.int64) + 1).tolist()
        row_cell = float(radius)  # rows are r wide in y and z (2r: fewer rows, longer sorts: slower)
        row_dims = (np.floor((hi - lo) / row_cell).astype(np.int64) + 1).tolist()
        if getattr(self, "_v", -1) != v:  # buffers reused while the size stays
            self._v = v
            self._keys = np.empty(v, np.int64)
            self.order = np.empty(v, np.int64)
            self.points = np.empty((v, 3), np.float32)
            self.sx = np.empty(v, np.float64)
            self.strand = np.empty(v, np.int64)
            self.skip = np.empty(v, np.bool_)
            self.keys = np.empty(v, np.int64)
            self.cnt = np.empty(v, np.int32)
        keys, order = self._keys, self.order
        self.dense = row_dims[1] * row_dims[2] <= max(8 * v, 1 << 16) if dense is None else dense
        if self.dense:
            # Rows along x over the bounding box's (y, z) cells (the usual case).
            dims = row_dims
            n_rows = dims[1] * dims[2]
            _row_keys(points, lo, 1.0 / row_cell, dims[1], dims[2], keys)
            start = np.empty(n_rows + 1, np.int64)
            _counting_sort(keys, n_rows, start, order)
            _sort_rows_by_x(order, start, points[:, 0])
            shift = np.uint64(0)
        else:
            # Sparse hair in a large box: hash the 3-D cells into ~2V buckets.
            bits = max(6, int(np.ceil(np.log2(2 * v))))
            shift = np.uint64(64 - bits)
            buckets = np.empty(v, np.int64)
            _cell_keys(points, lo, inv, shift, keys, buckets)
            start = np.empty((1 << bits) + 1, np.int64)
            _counting_sort(buckets, 1 << bits, start, order)
        self.dims = dims
        _gather(order, points, strand, skip, keys, self.points, self.sx, self.strand, self.skip, self.keys)
        self.start = start
        self.radius = float(radius)
        r2 = float(radius) ** 2
        while True:
            if self.nbr.shape[0] < v or self.nbr.shape[1] != self.capacity:
                self.nbr = np.empty((v, self.capacity), np.int32)
            if self.dense:
                _row_neighbour_kernel(
                    self.points,
                    self.sx,
                    self.strand,
                    start,
                    dims[1],
                    dims[2],
                    lo,
                    row_cell,
                    r2,
                    self.nbr,
                    self.cnt,
                )
                if int(self.cnt.max()) < self.capacity:  # else: grow and redo below
                    _mirror_pairs(self.nbr, self.cnt, self.skip)
            else:
                _neighbour_kernel(
                    self.points, self.keys, self.strand, self.skip, start, shift, r2, self.nbr, self.cnt
                )
            most = int(self.cnt.max()) if v else 0
            if most < self.capacity:  # the last slot is scratch for the branch-free writes
                if 2 * (most + 1) < self.capacity and self.capacity > 16:
                    self.capacity = max(16, (most + 16) // 16 * 16)  # next build: smaller rows
                break
            self.capacity = (most + 16) // 16 * 16


def neighbour_list(
    points: np.ndarray, strand: np.ndarray, radius: float, skip=None, dense: bool | None = None
) -> NeighbourList:
    """Build a :class:`NeighbourList` (``points`` (V,3), ``strand`` (V,) strand of each vertex)."""
    nl = NeighbourList()
    skip = np.zeros(len(points), bool) if skip is None else skip
    nl.build(points, np.asarray(strand, np.int64), skip, radius, dense)
    return nl


def pairs_within_reference(
    points: np.ndarray, strand: np.ndarray, radius: float
) -> tuple[np.ndarray, np.ndarray]:
    """All ordered pairs (i, j) of vertices of different strands closer than ``radius`` (numpy twin).

    Sorted cell keys and ``searchsorted`` per neighbour-cell offset; distances in float64.
    """
    p = np.asarray(points, dtype=np.float64)
    c = np.floor((p - p.min(axis=0)) / radius).astype(np.int64)
    dims = c.max(axis=0) + 1
    key = (c[:, 2] * dims[1] + c[:, 1]) * dims[0] + c[:, 0]
    order = np.argsort(key, kind="stable")
    skey = key[order]
    out_i, out_j = [], []
    for off in np.stack(np.meshgrid([-1, 0, 1], [-1, 0, 1], [-1, 0, 1], indexing="ij"), -1).reshape(-1, 3):
        nc = c + off[::-1]
        ok = np.all((nc >= 0) & (nc < dims), axis=1)
        rows = np.flatnonzero(ok)
        nk = (nc[rows, 2] * dims[1] + nc[rows, 1]) * dims[0] + nc[rows, 0]
        lo = np.searchsorted(skey, nk, "left")
        n = np.searchsorted(skey, nk, "right") - lo
        i = np.repeat(rows, n)
        j = order[np.repeat(lo - np.cumsum(n) + n, n) + np.arange(int(n.sum()))]
        d = p[j] - p[i]
        r2 = d[:, 0] * d[:, 0] + d[:, 1] * d[:, 1] + d[:, 2] * d[:, 2]
        keep = (r2 < radius * radius) & (strand[i] != strand[j])
        out_i.append(i[keep])
        out_j.append(j[keep])
    return np.concatenate(out_i), np.concatenate(out_j)
