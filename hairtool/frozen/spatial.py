"""Neighbours between strands: a uniform grid of cells one search radius r wide.

The usual path groups vertices into rows along x (a 2-D grid of cells r wide over y and z,
counting sort) and sorts each row by x; a vertex then scans the non-empty rows of the 3 × 3
around it, each over the x-window within r of the vertex's x, with sweep pointers that only
move forward. Only the forward half of the
pairs is searched (in parallel over chunks of rows balanced by vertex count); a parallel
transpose mirrors them into backward lists (CSR: ``start``/``cnt`` into ``flat``), with a map
from each backward entry to its pair's forward one, so that ClumpWithGaps can compute a pair's
distance once for both its vertices. Grooms in a box too large for a row table fall
back to a spatial hash of 3-D cells (~2V buckets; a candidate counts only if its exact cell
matches, so collisions never count twice). Lists come in the same order whatever the thread
count or the chunking, and the grid's corners lie on a lattice of :data:`SNAP` radii, so that an
edit which moves the box a little leaves every list's order as it was. :func:`pairs_within_reference`
is the plain numpy twin.
Clump radius and clump membership helpers live in :mod:`hairtool.frozen.strand_clumps`.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from hairtool import budget
from hairtool.bounds import box
from hairtool.errors import GroomError, ParameterError
from hairtool.kernel_arrays import readonly
from hairtool.serial_twins import twin_njit

_BITS = 21  # bits per cell coordinate in a packed 64-bit cell key
_MAXC = (1 << _BITS) - 2
_HASH = np.uint64(0x9E3779B97F4A7C15)
_CHUNKS = 64  # search tasks (the lists do not depend on them): many, so that threads stay balanced
_CHUNK_MIN = 256  # vertices per task at least
SNAP = 16  # radii: the grid's corners lie on a lattice this coarse


# -- the hashed fallback (sparse hair in a huge box) ---------------------------------------------
@njit(cache=True, nogil=True, parallel=True)
def _cell_keys(p, lo, inv_cell, shift, keys, buckets):
    for i in prange(p.shape[0]):
        cx = np.int64(np.floor((p[i, 0] - lo[0]) * inv_cell))
        cy = np.int64(np.floor((p[i, 1] - lo[1]) * inv_cell))
        cz = np.int64(np.floor((p[i, 2] - lo[2]) * inv_cell))
        k = cx | (cy << _BITS) | (cz << (2 * _BITS))
        keys[i] = k
        buckets[i] = np.int64((np.uint64(k) * _HASH) >> shift)


@njit(cache=True, nogil=True)
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


@njit(cache=True, nogil=True, parallel=True)
def _gather_hashed(order, points, strand, skip, keys, sx, sy, sz, sstrand, sskip, skeys):
    for k in prange(order.size):
        i = order[k]
        sx[k] = points[i, 0]
        sy[k] = points[i, 1]
        sz[k] = points[i, 2]
        sstrand[k] = strand[i]
        sskip[k] = skip[i]
        skeys[k] = keys[i]


@njit(cache=True, nogil=True, parallel=True)
def _hashed_kernel(sx, sy, sz, skey, sstrand, start, shift, r2, nbr, cnt):
    """All pairs of a vertex from the 27 hashed cells around it, into padded rows of ``nbr``."""
    cap = nbr.shape[1]
    mask = np.int64((1 << _BITS) - 1)
    for i in prange(sx.size):
        k = skey[i]
        cx, cy, cz = k & mask, (k >> _BITS) & mask, k >> (2 * _BITS)
        px, py, pz = sx[i], sy[i], sz[i]
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
                        ex = sx[j] - px
                        ey = sy[j] - py
                        ez = sz[j] - pz
                        if ex * ex + ey * ey + ez * ez < r2:
                            if n < cap:
                                nbr[i, n] = j
                            n += 1
        cnt[i] = n


@njit(cache=True, nogil=True)
def _compact_padded(nbr, cnt, start, flat):
    """Padded rows → CSR (``start`` (V+1,) filled here, ``flat`` large enough)."""
    start[0] = 0
    for i in range(cnt.size):
        start[i + 1] = start[i] + cnt[i]
        for n in range(cnt[i]):
            flat[start[i] + n] = nbr[i, n]


# -- the row grid (the usual path) ---------------------------------------------------------------
@twin_njit(nogil=True, parallel=True)
def _row_keys(p, lo, inv_cell, ny, nz, inv_q, nq, keys, qx):
    """Each vertex's row ``cz·ny + cy`` and quantised x."""
    for i in prange(p.shape[0]):
        cy = min(np.int64(np.floor((p[i, 1] - lo[1]) * inv_cell)), ny - 1)
        cz = min(np.int64(np.floor((p[i, 2] - lo[2]) * inv_cell)), nz - 1)
        keys[i] = cz * ny + cy
        qx[i] = min(np.int64(np.floor((p[i, 0] - lo[0]) * inv_q)), nq - 1)


@twin_njit(nogil=True)
def _row_sort(p, lo, inv_cell, ny, nz, inv_q, nq, keys, qx, start, order, tmp):
    """Vertices by row ``cz·ny + cy``, inside a row by x quantised to ``nq`` steps over the box:
    two stable counting sorts (quantised x, then row), no comparisons. ``start``: row offsets."""
    n_rows = ny * nz
    v = p.shape[0]
    _row_keys(p, lo, inv_cell, ny, nz, inv_q, nq, keys, qx)
    count = np.zeros(nq + 1, np.int64)
    for i in range(v):
        count[qx[i] + 1] += 1
    for q in range(nq):
        count[q + 1] += count[q]
    for i in range(v):
        q = qx[i]
        tmp[count[q]] = i
        count[q] += 1
    start[: n_rows + 1] = 0
    for i in range(v):
        start[keys[i] + 1] += 1
    for r in range(n_rows):
        start[r + 1] += start[r]
    for k in range(v):  # start[r] runs ahead while filling, then is shifted back
        i = tmp[k]
        r = keys[i]
        order[start[r]] = i
        start[r] += 1
    for r in range(n_rows, 0, -1):
        start[r] = start[r - 1]
    start[0] = 0


@twin_njit(nogil=True, parallel=True)
def _gather(order, points, strand, skip, sx, sy, sz, sstrand, sskip):
    """The sorted coordinates (float64), strands and skip flags."""
    for k in prange(order.size):
        i = order[k]
        sx[k] = points[i, 0]
        sy[k] = points[i, 1]
        sz[k] = points[i, 2]
        sstrand[k] = strand[i]
        sskip[k] = skip[i]


@njit(cache=True, nogil=True)
def _scan_row(sx, sy, sz, sstrand, j, end, px, py, pz, si, sweep, xb, r2, jmin, flat, pos, lim):
    """One row for vertex p: move the row's sweep pointer ``j`` past the entries left of
    ``sweep``, then test the entries of [max(j, jmin), …) left of ``xb``. Returns (pointer,
    write position). (Narrowing each row's window to where the sphere crosses it tested fewer
    entries but cost a square root per row: 22 % slower on the sparse scalps, no faster on the
    bear.)"""
    while j < end and sx[j] <= sweep:  # monotone in p's x: never moves back
        j += 1
    k = max(j, jmin)
    # Branch-free body (the test outcome is unpredictable): always write, count hits.
    while k < end and sx[k] < xb:
        ex = sx[k] - px
        ey = sy[k] - py
        ez = sz[k] - pz
        hit = (ex * ex + ey * ey + ez * ez < r2) & (sstrand[k] != si)
        flat[min(pos, lim)] = k
        pos += np.int64(hit)
        k += 1
    return j, pos


@njit(cache=True, nogil=True)
def search_reach(r2, slack, cell):
    """How far right of a vertex's x its forward search looks: r, and the slack of the sort's
    quantised x on both sides (each row is in x order to within it)."""
    return np.sqrt(r2) * (1.0 + 1e-6) + 2.0 * slack + 1e-12 * cell


@twin_njit(nogil=True, parallel=True)
def _forward_kernel(
    sx, sy, sz, sstrand, start, ny, nz, cell, r2, slack, chunks, base, limit, flat, fcnt, used
):
    """Forward half of the pairs: vertex i (sorted position) finds the j > i within r: in its
    own row to its right and in the 4 rows after it ((y+1, z), (y−1..y+1, z+1)), each over the
    x-window within r of p's x. The vertices of a row come in
    x order (to within ``slack``, the quantisation of the sort), so per row a pointer to the
    window's start only moves forward (a sweep line). One task per chunk of rows; vertex i's
    entries go to ``flat[base[c] + …]`` in the order found, ``fcnt[i]`` of them; ``used[c]``
    counts what chunk c needed (it overflowed when that exceeds its room)."""
    reach = search_reach(r2, slack, cell)  # windows a little longer, for the quantised order
    first = np.int64(0)  # (a literal 0 would compile _scan_row once more, for Literal[int](0))
    for c in prange(chunks.size - 1):
        pos = base[c]
        lim = limit[c]  # the last slot is scratch for the branch-free writes
        for r in range(chunks[c], chunks[c + 1]):
            a0, b0 = start[r], start[r + 1]
            if a0 == b0:
                continue
            cy = r % ny
            cz = r // ny
            # Missing rows (outside the grid) are empty runs [0, 0).
            r1 = r + 1 if cy + 1 < ny else -1
            r2_ = r + ny - 1 if cz + 1 < nz and cy >= 1 else -1
            r3 = r + ny if cz + 1 < nz else -1
            r4 = r + ny + 1 if cz + 1 < nz and cy + 1 < ny else -1
            j1, e1 = (start[r1], start[r1 + 1]) if r1 >= 0 else (0, 0)
            j2, e2 = (start[r2_], start[r2_ + 1]) if r2_ >= 0 else (0, 0)
            j3, e3 = (start[r3], start[r3 + 1]) if r3 >= 0 else (0, 0)
            j4, e4 = (start[r4], start[r4 + 1]) if r4 >= 0 else (0, 0)
            for i in range(a0, b0):
                px, py, pz = sx[i], sy[i], sz[i]
                si = sstrand[i]
                p0 = pos
                sw, xb = px - reach, px + reach  # entries right of xb fail the distance test
                _, pos = _scan_row(
                    sx, sy, sz, sstrand, i + 1, b0, px, py, pz, si, -np.inf, xb, r2, i + 1, flat, pos, lim
                )
                j1, pos = _scan_row(
                    sx, sy, sz, sstrand, j1, e1, px, py, pz, si, sw, xb, r2, first, flat, pos, lim
                )
                j2, pos = _scan_row(
                    sx, sy, sz, sstrand, j2, e2, px, py, pz, si, sw, xb, r2, first, flat, pos, lim
                )
                j3, pos = _scan_row(
                    sx, sy, sz, sstrand, j3, e3, px, py, pz, si, sw, xb, r2, first, flat, pos, lim
                )
                j4, pos = _scan_row(
                    sx, sy, sz, sstrand, j4, e4, px, py, pz, si, sw, xb, r2, first, flat, pos, lim
                )
                fcnt[i] = pos - p0
        used[c] = pos - base[c]


@twin_njit(nogil=True, parallel=True)
def _window_counts(chunks, start, base, fflat, fcnt, lo, woff, wcnt):
    """Per chunk, how many of its entries point at each vertex of its window [lo[c], …)."""
    for c in prange(chunks.size - 1):
        w = woff[c] - lo[c]
        for k in range(woff[c], woff[c + 1]):
            wcnt[k] = 0
        p = base[c]
        for i in range(start[chunks[c]], start[chunks[c + 1]]):
            for n in range(p, p + fcnt[i]):
                wcnt[w + fflat[n]] += 1
            p += fcnt[i]


@njit(cache=True, nogil=True)
def _chunk_offsets(c, vlo, lo, hi, woff, wcnt, count):
    """:func:`_window_offsets` for chunk c's own vertices; returns their total."""
    c = np.int64(c)  # (a prange index may come unsigned: c − 1 would be a float)
    t = 0
    first = c
    for j in range(vlo[c], vlo[c + 1]):
        while first > 0 and hi[first - 1] > j:
            first -= 1
        while first < c and hi[first] <= j:
            first += 1
        s = 0
        for b in range(first, c + 1):
            k = woff[b] + j - lo[b]
            n = wcnt[k]
            wcnt[k] = s
            s += n
        count[j] = s
        t += s
    return t


@twin_njit(nogil=True, parallel=True)
def _window_offsets(vlo, lo, hi, woff, wcnt, count, total):
    """For each vertex j (chunk c's own vertices [vlo[c], vlo[c + 1])): the chunks whose windows
    hold it are consecutive, ending at c (windows start at their chunk and end no earlier than
    the windows before); their counts become offsets in chunk order, ``count[j]`` the sum,
    ``total[c]`` the chunk's."""
    for c in prange(vlo.size - 1):
        total[c] = _chunk_offsets(np.int64(c), vlo, lo, hi, woff, wcnt, count)  # one type: int64


@twin_njit(nogil=True, parallel=True)
def _backward_starts(vlo, count, chunk_start, bstart):
    """``bstart`` from the counts, each chunk's run from its start (a prefix of the totals)."""
    for c in prange(vlo.size - 1):
        s = chunk_start[c]
        for j in range(vlo[c], vlo[c + 1]):
            bstart[j] = s
            s += count[j]
        if c == vlo.size - 2:
            bstart[vlo[c + 1]] = s


@twin_njit(nogil=True, parallel=True)
def _window_fill(chunks, start, base, fflat, fcnt, lo, woff, wcnt, bstart, bflat, bmap):
    for c in prange(chunks.size - 1):
        w = woff[c] - lo[c]
        p = base[c]
        for i in range(start[chunks[c]], start[chunks[c + 1]]):
            for n in range(p, p + fcnt[i]):
                k = w + fflat[n]
                e = bstart[fflat[n]] + wcnt[k]
                bflat[e] = i
                bmap[e] = n
                wcnt[k] += 1
            p += fcnt[i]


@twin_njit(nogil=True)
def _transpose(chunks, start, ny, base, fflat, fcnt, bstart, bflat, bmap):
    """The backward lists: every i that found j (i < j), in increasing i (deterministic), as CSR
    ``bstart`` (V+1,) into ``bflat`` (which holds them all), and ``bmap``: for each backward
    entry, where the same pair is among i's forward entries (a pair's distance and weight are
    computed once there, :mod:`hairtool.frozen.clump`). In parallel over the chunks: chunk
    c's entries point into a window of vertices from its own first one to the end of the rows
    after its last (the forward search reaches ``ny + 1`` rows on), so each chunk counts into a
    window of its own, the windows' counts become each chunk's offsets per vertex, and each chunk
    writes its own entries; the result is :func:`transpose_reference`'s."""
    n = chunks.size - 1
    n_rows = start.size - 1
    lo = np.empty(n, np.int64)
    hi = np.empty(n, np.int64)
    vlo = np.empty(n + 1, np.int64)
    woff = np.zeros(n + 1, np.int64)
    for c in range(n):
        lo[c] = start[chunks[c]]
        vlo[c] = lo[c]
        hi[c] = start[min(chunks[c + 1] - 1 + ny + 2, n_rows)]
        woff[c + 1] = woff[c] + hi[c] - lo[c]
    vlo[n] = start[chunks[n]]
    wcnt = np.empty(woff[n], np.int64)
    _window_counts(chunks, start, base, fflat, fcnt, lo, woff, wcnt)
    count = np.empty(fcnt.size, np.int64)
    total = np.empty(n, np.int64)
    _window_offsets(vlo, lo, hi, woff, wcnt, count, total)
    chunk_start = np.zeros(n, np.int64)
    for c in range(1, n):
        chunk_start[c] = chunk_start[c - 1] + total[c - 1]
    _backward_starts(vlo, count, chunk_start, bstart)
    _window_fill(chunks, start, base, fflat, fcnt, lo, woff, wcnt, bstart, bflat, bmap)


def transpose_reference(
    order_i: np.ndarray, order_j: np.ndarray, entry: np.ndarray, v: int
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """numpy twin of :func:`_transpose`: forward pairs (i finds j, at ``entry`` among the
    forward entries) → (bstart, bflat, bmap), each j's finders in increasing i.

    Parameters
    ----------
    order_i, order_j : ndarray
        The forward pairs' finders and found.
    entry : ndarray
        Each pair's place among the forward entries.
    v : int
        Vertices.

    Returns
    -------
    tuple of (ndarray, ndarray, ndarray)
        ``bstart``, ``bflat`` and ``bmap``.
    """
    by_j = np.lexsort((order_i, order_j))
    bstart = np.zeros(v + 1, np.int64)
    np.cumsum(np.bincount(order_j, minlength=v), out=bstart[1:])
    return bstart, order_i[by_j], entry[by_j]


def _chunk_rows(start: np.ndarray, vertex_count: int) -> np.ndarray:
    """Row boundaries of chunks of about equal vertex counts (the lists do not depend on them)."""
    n = max(1, min(_CHUNKS, vertex_count // _CHUNK_MIN))
    targets = np.linspace(0, vertex_count, n + 1)
    rows = np.searchsorted(start, targets, side="left")
    rows[0], rows[-1] = 0, start.size - 1
    return np.unique(rows).astype(np.int64)


class NeighbourList:
    """Vertices of other strands within ``radius``, in cell-sorted order.

    ``order[k]``: the original vertex at sorted position k. Its neighbours (sorted positions)
    come in two runs: ``aflat[aoff[k] : aoff[k] + acnt[k]]`` (found from k: the forward half)
    then ``bflat[bstart[k] : bstart[k + 1]]`` (those that found k), see :meth:`of`; on the row
    grid (``dense``) ``bmap`` names each backward entry's pair among the forward entries (the
    hashed grid's lists are whole in ``aflat``, ``bstart`` all zero). ``x``, ``y``,
    ``z``, ``strand``, ``skip``: the sorted coordinates (float64) and attributes. Vertices flagged
    in ``skip`` still have lists, and appear in others'; kernels skip them. Buffers are reused
    while the vertex count stays, so a build per mouse move allocates (almost) nothing.
    """

    def __init__(self) -> None:
        self._v = -1
        self._per_vertex = 8.0  # forward entries per vertex to reserve room for (adapts)
        self.aflat = np.empty(0, np.int32)
        self.bflat = np.empty(0, np.int32)
        self.bmap = np.empty(0, np.int64)  # backward entry → the same pair's forward entry (row grid)
        self.forward_entries = 0  # of the row grid's last build
        self.capacity = 16  # padded row width of the hashed path; grows with the densest vertex
        self._nbr = np.empty((0, self.capacity), np.int32)
        self._start = np.empty(0, np.int64)
        self.dense = False
        self.chunks: np.ndarray | None = None  # the row grid's search chunks (rows), kept for updates

    def of(self, k: int) -> np.ndarray:
        """Sorted positions of the neighbours of the vertex at sorted position ``k``.

        Parameters
        ----------
        k : int
            A sorted position.

        Returns
        -------
        ndarray
            Sorted positions.
        """
        a = self.aflat[self.aoff[k] : self.aoff[k] + self.acnt[k]]
        return np.concatenate([a, self.bflat[self.bstart[k] : self.bstart[k + 1]]])

    @property
    def cnt(self) -> np.ndarray:
        """``(V,)`` list length of each sorted position."""
        return self.acnt + np.diff(self.bstart)

    @property
    def pairs(self) -> int:
        """Entries in all lists (each pair twice)."""
        return int(self.acnt.sum() + self.bstart[-1])

    def _buffers(self, v: int) -> None:
        if self._v == v:
            return
        self._v = v
        self.keys = np.empty(v, np.int64)
        self._qx = np.empty(v, np.int64)
        self._tmp = np.empty(v, np.int64)
        self.order = np.empty(v, np.int64)
        self.x = np.empty(v)
        self.y = np.empty(v)
        self.z = np.empty(v)
        self.strand = np.empty(v, np.int64)
        self.skip = np.empty(v, np.bool_)
        self.acnt = np.empty(v, np.int64)
        self.aoff = np.empty(v, np.int64)
        self.bstart = np.zeros(v + 1, np.int64)

    def build(
        self,
        points: np.ndarray,
        strand: np.ndarray,
        skip: np.ndarray,
        radius: float,
        dense: bool | None = None,
    ) -> None:
        """``dense``: force the row grid (True) or the hashed one (False); None picks by size.

        Parameters
        ----------
        points : ndarray
            ``(V, 3)``.
        strand : ndarray
            ``(V,)`` each vertex's strand.
        skip : ndarray
            ``(V,)`` bool, vertices left out (roots).
        radius : float
            The search radius.
        dense : bool, optional
            Force the row grid (True) or the hashed one (False); None picks by size.
        """
        self.chunks = None
        # read-only and C-ordered: the kernels compile one signature per dtype whoever holds them
        points, strand, skip = readonly(points), readonly(strand), readonly(skip)
        lo, hi, dims = self._grid(points, radius, dense)
        if self.dense:
            self._sort_rows(points, strand, skip, lo, hi, dims)
            self._search_rows(points.shape[0])
        else:
            self._build_hashed(points, strand, skip, lo, float(radius))

    def _grid(self, points, radius, dense, raw_box=None):
        """The grid of ``points``' box (``raw_box``: that box, when the caller knows it)."""
        v = points.shape[0]
        lo, hi = (b.astype(np.float64) for b in (box(points) if raw_box is None else raw_box))
        self.raw_box = (lo, hi)
        extent = float((hi - lo).max())
        if not np.isfinite(extent):
            raise GroomError("the points have a non-finite coordinate")
        if not np.isfinite(radius) or radius <= 0 or extent / radius >= _MAXC:
            raise ParameterError("clump_radius", radius, f"a distance above {extent / _MAXC:.3g}")
        self._buffers(v)
        self.radius = float(radius)
        # The grid on a lattice of SNAP radii around the box: an edit that moves the box a little
        # leaves the grid, and so the order of every list, as it was (brush-local moves sum their
        # lists in that order, hairtool.frozen.vertex_grid.list_frame).
        snap = SNAP * self.radius
        lo, hi = np.floor(lo / snap) * snap, (np.floor(hi / snap) + 1.0) * snap
        dims = (np.floor((hi - lo) / self.radius).astype(np.int64) + 1).tolist()  # rows r wide in y, z
        self.dense = dims[1] * dims[2] <= max(8 * v, 1 << 16) if dense is None else dense
        return lo, hi, dims

    def _sort_rows(self, points, strand, skip, lo, hi, dims) -> None:
        n_rows = dims[1] * dims[2]
        if self._start.size < n_rows + 1:
            self._start = np.empty(max(n_rows + 1, 2 * self._start.size), np.int64)
        start = self._start[: n_rows + 1]
        # x quantised to 1/64 of a cell (at most 2**16 steps): the sweep allows for that slack.
        nq = int(min(1 << 16, max(64 * dims[0], 1)))
        width = max(float(hi[0] - lo[0]), 1e-300)
        _row_sort(
            points, lo, 1.0 / self.radius, dims[1], dims[2], nq / width, nq, self.keys, self._qx, start,
            self.order, self._tmp,
        )  # fmt: skip
        _gather(self.order, points, strand, skip, self.x, self.y, self.z, self.strand, self.skip)
        self.slack = width / nq
        self.nq, self.inv_q = nq, nq / width
        self.dims = dims
        self.start = start
        self.lo, self.hi = lo, hi

    def _search_rows(self, v) -> None:
        start, dims, cell = self.start, self.dims, self.radius
        chunks = _chunk_rows(start, v)
        per_chunk = np.diff(start[chunks])
        r2 = self.radius**2
        while True:
            room = (per_chunk * self._per_vertex).astype(np.int64) + 64
            base = np.zeros(room.size, np.int64)
            np.cumsum(room[:-1], out=base[1:])
            total = int(base[-1] + room[-1])
            what = f"the clumping neighbour search of {v} vertices (clump_radius={self.radius:g})"
            budget.check("pairs", total, what)  # before the lists' room is asked for
            if self.aflat.size < total:
                self.aflat = np.empty(int(total * 1.25), np.int32)
            used = np.empty(room.size, np.int64)
            _forward_kernel(
                self.x, self.y, self.z, self.strand, start, dims[1], dims[2], cell, r2, self.slack,
                chunks, base, base + room - 1, self.aflat, self.acnt, used,
            )  # fmt: skip
            need = float(np.max(used / np.maximum(per_chunk, 1)))
            if np.all(used < room):  # the last slot of each room is scratch
                # Room for next time: what this build needed plus a margin (shrinks slowly).
                self._per_vertex = max(0.8 * self._per_vertex, 1.3 * need + 1.0)
                break
            self._per_vertex = 1.5 * need + 2.0
        _vertex_offsets(chunks, start, base, self.acnt, self.aoff)
        # Kept for hairtool.frozen.neighbour_update: chunk c's entries stay in [base, limit].
        self.chunks, self.base, self.limit = chunks, base, base + room - 1
        backward = int(self.acnt.sum())  # each forward entry (i finds j) is one of j's backward ones
        self.forward_entries = backward
        if self.bflat.size < backward:  # so the transpose always has its room, in one pass
            self.bflat = np.empty(int(backward * 1.25) + 16, np.int32)
            self.bmap = np.empty(self.bflat.size, np.int64)
        _transpose(
            chunks, start, self.dims[1], base, self.aflat, self.acnt, self.bstart, self.bflat, self.bmap
        )

    def _build_hashed(self, points, strand, skip, lo, radius) -> None:
        # Sparse hair in a large box: hash the 3-D cells into ~2V buckets.
        v = points.shape[0]
        bits = max(6, int(np.ceil(np.log2(2 * v))))
        shift = np.uint64(64 - bits)
        buckets = np.empty(v, np.int64)
        _cell_keys(points, lo, 1.0 / radius, shift, self.keys, buckets)
        start = np.empty((1 << bits) + 1, np.int64)
        _counting_sort(buckets, 1 << bits, start, self.order)
        skeys = np.empty(v, np.int64)
        _gather_hashed(
            self.order, points, strand, skip, self.keys, self.x, self.y, self.z, self.strand, self.skip, skeys
        )
        self.dims = None
        self.chunks = None
        self.start = start
        cnt = self.acnt
        while True:
            if self._nbr.shape[0] < v or self._nbr.shape[1] != self.capacity:
                self._nbr = np.empty((v, self.capacity), np.int32)
            _hashed_kernel(
                self.x, self.y, self.z, skeys, self.strand, start, shift, radius**2, self._nbr, cnt
            )  # fmt: skip
            most = int(cnt.max()) if v else 0
            if most <= self.capacity:
                break
            self.capacity = (most + 16) // 16 * 16
        total = int(cnt.sum())
        if self.aflat.size < total:
            self.aflat = np.empty(int(total * 1.25) + 16, np.int32)
        offsets = np.empty(v + 1, np.int64)
        _compact_padded(self._nbr, cnt, offsets, self.aflat)
        self.aoff[:] = offsets[:-1]
        self.bstart[:] = 0  # the hashed lists are complete


@njit(cache=True, nogil=True)
def _vertex_offsets(chunks, start, base, fcnt, off):
    """Where each vertex's forward entries start in the chunked buffer."""
    for c in range(chunks.size - 1):
        p = base[c]
        for i in range(start[chunks[c]], start[chunks[c + 1]]):
            off[i] = p
            p += fcnt[i]


def neighbour_list(
    points: np.ndarray, strand: np.ndarray, radius: float, skip=None, dense: bool | None = None
) -> NeighbourList:
    """Build a :class:`NeighbourList` (``points`` (V,3), ``strand`` (V,) strand of each vertex).

    Parameters
    ----------
    points : ndarray
        ``(V, 3)``.
    strand : ndarray
        ``(V,)`` each vertex's strand.
    radius : float
        The search radius.
    skip : ndarray, optional
        ``(V,)`` bool, vertices left out.
    dense : bool, optional
        Force the row grid or the hashed one.

    Returns
    -------
    NeighbourList
        The list (a BudgetError where its entries would not fit).
    """
    nl = NeighbourList()
    skip = np.zeros(len(points), bool) if skip is None else skip
    nl.build(points, np.asarray(strand, np.int64), skip, radius, dense)
    return nl


def pairs_within_reference(
    points: np.ndarray, strand: np.ndarray, radius: float
) -> tuple[np.ndarray, np.ndarray]:
    """All ordered pairs (i, j) of vertices of different strands closer than ``radius`` (numpy twin).

    Sorted cell keys and ``searchsorted`` per neighbour-cell offset; distances in float64.

    Parameters
    ----------
    points : ndarray
        ``(V, 3)``.
    strand : ndarray
        ``(V,)`` each vertex's strand.
    radius : float
        The distance.

    Returns
    -------
    tuple of (ndarray, ndarray)
        ``i`` and ``j``.
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
