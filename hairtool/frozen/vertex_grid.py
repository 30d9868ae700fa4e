"""A grid of every vertex of a groom, kept across brush moves and updated where strands moved.

The brush-local engine (:mod:`hairtool.frozen.local`) asks it three things on each mouse move:
which strands have a vertex within a brush's radius, which strands have a vertex within the
clump kernel's reach (h·(1 + MARGIN)) of the vertices that moved, and the neighbour list of
each vertex it redoes. Cells are cubes one list radius wide, hashed into about 2V buckets, each
a doubly linked list of vertices, so that moving a vertex to another cell costs O(1) and the
grid never has to be rebuilt while the strands stay the same (a candidate counts only where its
exact cell matches, so hash collisions never count twice). Cell coordinates are clipped to
±2**20, which only makes far-away cells share a list.

A vertex's list comes in the order a full build of :class:`hairtool.frozen.spatial.NeighbourList`
gives it (:func:`list_frame` names that build's grid): the neighbours after the vertex in the
build's sorted order, then those before it, each increasing. So the pulls are summed in the same
order, and a brush-local run gives a full run's bits. The ``*_reference`` functions are the
numpy twins.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from hairtool.bounds import box
from hairtool.serial_twins import twin_njit

_OFF = 1 << 20  # cell coordinates are clipped to [−_OFF, _OFF − 1]
_BITS = 21
_HASH = np.uint64(0x9E3779B97F4A7C15)
IDX_BITS = 24  # vertex index bits in a list sort key: grooms of up to 16.7M vertices
_IDX_MASK = (1 << IDX_BITS) - 1
_SNAP = 16  # as hairtool.frozen.spatial.SNAP (the list build's grid lattice)


@njit(cache=True, nogil=True, inline="always")
def _coord(x, inv):
    c = np.int64(np.floor(np.float64(x) * inv))
    return min(max(c, -_OFF), _OFF - 1)


@njit(cache=True, nogil=True, inline="always")
def _pack(cx, cy, cz):
    return (cx + _OFF) | ((cy + _OFF) << _BITS) | ((cz + _OFF) << (2 * _BITS))


@njit(cache=True, nogil=True, inline="always")
def _bucket(key, shift):
    return np.int64((np.uint64(key) * _HASH) >> shift)


@njit(cache=True, nogil=True)
def _build(points, inv, shift, key, head, nxt, prv):
    head[:] = -1
    for i in range(points.shape[0] - 1, -1, -1):  # (lists then run in vertex order: any order would do)
        k = _pack(_coord(points[i, 0], inv), _coord(points[i, 1], inv), _coord(points[i, 2], inv))
        key[i] = k
        b = _bucket(k, shift)
        nxt[i] = head[b]
        prv[i] = -1
        if head[b] >= 0:
            prv[head[b]] = i
        head[b] = i


@njit(cache=True, nogil=True)
def _move(points, vids, inv, shift, key, head, nxt, prv):
    """The vertices ``vids`` into the cells of their new ``points``; returns how many changed cell."""
    moved = 0
    for n in range(vids.size):
        i = vids[n]
        k = _pack(_coord(points[i, 0], inv), _coord(points[i, 1], inv), _coord(points[i, 2], inv))
        if k == key[i]:
            continue
        moved += 1
        if prv[i] >= 0:  # out of the old cell's list
            nxt[prv[i]] = nxt[i]
        else:
            head[_bucket(key[i], shift)] = nxt[i]
        if nxt[i] >= 0:
            prv[nxt[i]] = prv[i]
        key[i] = k  # into the new one, at the front
        b = _bucket(k, shift)
        nxt[i] = head[b]
        prv[i] = -1
        if head[b] >= 0:
            prv[head[b]] = i
        head[b] = i
    return moved


@twin_njit(nogil=True, parallel=True)
def _mark_near(points, strand, qx, qy, qz, r2, inv, shift, key, head, nxt, mark):
    """Flag in ``mark`` (per strand) every strand with a vertex closer than sqrt(r2) to a query
    point (``qx``, ``qy``, ``qz``); a scan of every vertex where a query covers more cells than that.
    The queries run in parallel: each only ever sets flags, so the flags come out the same
    whichever thread sets one first (a flag another thread has not seen set yet is tested again)."""
    reach = np.sqrt(r2)
    v = points.shape[0]
    for q in prange(qx.size):
        px, py, pz = qx[q], qy[q], qz[q]
        x0, x1 = _coord(px - reach, inv), _coord(px + reach, inv)
        y0, y1 = _coord(py - reach, inv), _coord(py + reach, inv)
        z0, z1 = _coord(pz - reach, inv), _coord(pz + reach, inv)
        cells = (x1 - x0 + 1) * (y1 - y0 + 1) * (z1 - z0 + 1)
        if cells > v:
            for j in range(v):
                ex = np.float64(points[j, 0]) - px
                ey = np.float64(points[j, 1]) - py
                ez = np.float64(points[j, 2]) - pz
                if ex * ex + ey * ey + ez * ez < r2:
                    mark[strand[j]] = True
            continue
        for cz in range(z0, z1 + 1):
            for cy in range(y0, y1 + 1):
                for cx in range(x0, x1 + 1):
                    k = _pack(cx, cy, cz)
                    j = head[_bucket(k, shift)]
                    while j >= 0:
                        if key[j] == k and not mark[strand[j]]:
                            ex = np.float64(points[j, 0]) - px
                            ey = np.float64(points[j, 1]) - py
                            ez = np.float64(points[j, 2]) - pz
                            if ex * ex + ey * ey + ez * ez < r2:
                                mark[strand[j]] = True
                        j = nxt[j]


@njit(cache=True, nogil=True, inline="always")
def _order_key(x, y, z, i, dense, lo, inv_cell, ny, nz, inv_q, nq, ox, oy, oz):
    """Where vertex i comes in the list build's order: row grid (``dense``): (row, quantised x,
    index), as :func:`hairtool.frozen.spatial._row_keys` computes them; hashed grid: the 3 × 3 × 3
    offset of its cell from the query's (``ox``, ``oy``, ``oz``), then the index."""
    if dense:
        cy = min(np.int64(np.floor((y - lo[1]) * inv_cell)), ny - 1)
        cz = min(np.int64(np.floor((z - lo[2]) * inv_cell)), nz - 1)
        q = min(np.int64(np.floor((x - lo[0]) * inv_q)), nq - 1)
        return (((cz * ny + cy) * nq + q) << IDX_BITS) | i
    cx = np.int64(np.floor((x - lo[0]) * inv_cell))
    cy = np.int64(np.floor((y - lo[1]) * inv_cell))
    cz = np.int64(np.floor((z - lo[2]) * inv_cell))
    return (((cz - oz + 1) * 9 + (cy - oy + 1) * 3 + (cx - ox + 1)) << IDX_BITS) | i


@twin_njit(nogil=True, parallel=True)
def _region_lists(
    points,
    strand,
    vids,
    r2,
    inv,
    shift,
    key,
    head,
    nxt,
    dense,
    lo,
    inv_cell,
    ny,
    nz,
    inv_q,
    nq,
    cap,
    flat,
    cnt,
):
    """The list of each vertex ``vids[n]``: the other strands' vertices closer than sqrt(r2)
    (float64 differences of the float32 points, summed x, y, z: the build's test), into
    ``flat[n·cap :]`` in the build's order; ``cnt[n]`` how many (cut at cap − 1 slots: call again
    wider)."""
    for n in prange(vids.size):
        i = vids[n]
        px, py, pz = np.float64(points[i, 0]), np.float64(points[i, 1]), np.float64(points[i, 2])
        si = strand[i]
        ox = np.int64(np.floor((px - lo[0]) * inv_cell))
        oy = np.int64(np.floor((py - lo[1]) * inv_cell))
        oz = np.int64(np.floor((pz - lo[2]) * inv_cell))
        gx, gy, gz = _coord(points[i, 0], inv), _coord(points[i, 1], inv), _coord(points[i, 2], inv)
        base = n * cap
        m = 0
        for cz in range(max(gz - 1, -_OFF), min(gz + 1, _OFF - 1) + 1):
            for cy in range(max(gy - 1, -_OFF), min(gy + 1, _OFF - 1) + 1):
                for cx in range(max(gx - 1, -_OFF), min(gx + 1, _OFF - 1) + 1):
                    k = _pack(cx, cy, cz)
                    j = head[_bucket(k, shift)]
                    while j >= 0:
                        if key[j] == k and strand[j] != si:
                            x, y, z = (
                                np.float64(points[j, 0]),
                                np.float64(points[j, 1]),
                                np.float64(points[j, 2]),
                            )
                            ex, ey, ez = x - px, y - py, z - pz
                            if ex * ex + ey * ey + ez * ez < r2:
                                if m < cap - 1:
                                    flat[base + m] = _order_key(
                                        x, y, z, j, dense, lo, inv_cell, ny, nz, inv_q, nq, ox, oy, oz
                                    )
                                m += 1
                        j = nxt[j]
        cnt[n] = m
        if m >= cap - 1:
            continue
        row = flat[base : base + m]
        row.sort()
        split = 0  # the row grid's list: those after i in sorted order, then those before
        if dense:
            own = _order_key(px, py, pz, i, dense, lo, inv_cell, ny, nz, inv_q, nq, ox, oy, oz)
            while split < m and row[split] < own:
                split += 1
        # rotate by split in place: reverse the two parts, then the whole
        _reverse(flat, base, base + split)
        _reverse(flat, base + split, base + m)
        _reverse(flat, base, base + m)
        for e in range(base, base + m):
            flat[e] = flat[e] & _IDX_MASK


@njit(cache=True, nogil=True, inline="always")
def _reverse(a, b, e):
    e -= 1
    while b < e:
        a[b], a[e] = a[e], a[b]
        b += 1
        e -= 1


def list_frame(points: np.ndarray, radius: float) -> tuple:
    """The grid a full :meth:`~hairtool.frozen.spatial.NeighbourList.build` of ``points`` at
    ``radius`` lays out (its corner, rows, x quantisation, row or hashed), which decides the
    order of its lists: ``(dense, lo, inv_cell, ny, nz, inv_q, nq)``, computed as the build does."""
    v = points.shape[0]
    lo, hi = (b.astype(np.float64) for b in box(points))
    radius = float(radius)
    snap = _SNAP * radius
    lo, hi = np.floor(lo / snap) * snap, (np.floor(hi / snap) + 1.0) * snap
    dims = (np.floor((hi - lo) / radius).astype(np.int64) + 1).tolist()
    dense = dims[1] * dims[2] <= max(8 * v, 1 << 16)
    nq = int(min(1 << 16, max(64 * dims[0], 1)))
    width = max(float(hi[0] - lo[0]), 1e-300)
    return dense, lo, 1.0 / radius, int(dims[1]), int(dims[2]), nq / width, nq


class VertexGrid:
    """Every vertex of one topology in hashed cells ``cell`` wide (see the module doc)."""

    def __init__(self, points: np.ndarray, strand: np.ndarray, cell: float) -> None:
        v = points.shape[0]
        self.cell = float(cell)
        self.inv = 1.0 / self.cell
        bits = max(6, int(np.ceil(np.log2(max(2 * v, 2)))))
        self.shift = np.uint64(64 - bits)
        self.key = np.empty(v, np.int64)
        self.head = np.empty(1 << bits, np.int64)
        self.nxt = np.empty(v, np.int64)
        self.prv = np.empty(v, np.int64)
        self.strand = np.ascontiguousarray(strand, np.int64)
        self.capacity = 64  # list slots per vertex (grows to the longest list + 1)
        _build(points, self.inv, self.shift, self.key, self.head, self.nxt, self.prv)

    @property
    def vertex_count(self) -> int:
        return self.key.size

    def reserve(self, longest: int) -> None:
        """Room in :meth:`lists` for lists of ``longest`` neighbours (it grows by itself too)."""
        if longest + 1 >= self.capacity:
            self.capacity = (longest + 1 + 32) // 32 * 32

    def move(self, points: np.ndarray, vids: np.ndarray) -> int:
        """The vertices ``vids`` now at ``points[vids]``; returns how many changed cell."""
        ids = np.ascontiguousarray(vids, np.int64)
        return int(_move(points, ids, self.inv, self.shift, self.key, self.head, self.nxt, self.prv))

    def strands_near(self, points: np.ndarray, queries: np.ndarray, radius: float, mark: np.ndarray) -> None:
        """Flag in ``mark`` ((S,) bool) the strands with a vertex of ``points`` (where the grid
        holds them) closer than ``radius`` to one of ``queries`` ((n, 3))."""
        q = np.asarray(queries, np.float64).reshape(-1, 3)
        _mark_near(
            points, self.strand, np.ascontiguousarray(q[:, 0]), np.ascontiguousarray(q[:, 1]),
            np.ascontiguousarray(q[:, 2]), float(radius) ** 2, self.inv, self.shift, self.key, self.head,
            self.nxt, mark,
        )  # fmt: skip

    def lists(self, points: np.ndarray, vids: np.ndarray, radius: float, frame: tuple) -> tuple:
        """``(flat, cnt, cap)``: the list of each vertex ``vids[n]`` (other strands within
        ``radius``, original indices) at ``flat[n·cap :][: cnt[n]]``, in the order of a full build
        whose grid is ``frame`` (:func:`list_frame`); ``radius`` must not exceed the cell."""
        dense, lo, inv_cell, ny, nz, inv_q, nq = frame
        ids = np.ascontiguousarray(vids, np.int64)
        r2 = float(radius) ** 2
        while True:
            cap = self.capacity
            flat = np.empty(ids.size * cap, np.int64)
            cnt = np.empty(ids.size, np.int64)
            _region_lists(
                points, self.strand, ids, r2, self.inv, self.shift, self.key, self.head, self.nxt, dense, lo,
                inv_cell, ny, nz, inv_q, nq, cap, flat, cnt,
            )  # fmt: skip
            most = int(cnt.max(initial=0))
            if most < cap - 1:
                return flat, cnt, cap
            self.reserve(most)


def strands_near_reference(
    points: np.ndarray, strand: np.ndarray, queries: np.ndarray, radius: float, strand_count: int
) -> np.ndarray:
    """Numpy twin of :meth:`VertexGrid.strands_near`: every vertex against every query."""
    p = np.asarray(points, np.float64)
    mark = np.zeros(strand_count, bool)
    for q in np.asarray(queries, np.float64).reshape(-1, 3):
        e = p - q
        d2 = e[:, 0] * e[:, 0] + e[:, 1] * e[:, 1] + e[:, 2] * e[:, 2]
        mark[strand[d2 < float(radius) ** 2]] = True
    return mark


def lists_reference(
    points: np.ndarray, strand: np.ndarray, vids: np.ndarray, radius: float
) -> list[np.ndarray]:
    """Numpy twin of :meth:`VertexGrid.lists`: each vertex's list read off a full
    :class:`~hairtool.frozen.spatial.NeighbourList` build (forward run, then backward, original indices)."""
    from hairtool.frozen.spatial import neighbour_list

    nl = neighbour_list(points, strand, radius)
    pos = np.empty(points.shape[0], np.int64)
    pos[nl.order] = np.arange(points.shape[0])
    return [nl.order[nl.of(int(pos[i]))] for i in np.asarray(vids, np.int64)]
