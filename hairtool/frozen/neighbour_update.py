"""A neighbour list brought up to date where vertices moved, instead of built again.

A brush stroke moves the strands under the brush; the full run on release wants the list of
the new points, and a build from scratch costs half of that run on a big groom. On the row grid
(:class:`~hairtool.frozen.spatial.NeighbourList`), a vertex's list is the vertices of other
strands within r in the rows (y, z cells) around it, in those rows' order, so an update:

1. re-sorts the rows that held or now hold a moved vertex (the others keep their order and
   only shift by their row's new start);
2. searches again from the moved vertices and from the vertices whose search found a moved
   vertex where it was (its backward list) or can find it where it is (those near it in the
   rows before it): no other list gained or lost an entry, so every other vertex of the
   stretch keeps its old entries, each moved to its vertex's new sorted position;
3. transposes again the backward lists of the stretch of rows the change reaches.

Everything outside that stretch stays as it was. The result is the list a build from scratch
gives, entry for entry and in the same order (tests compare the two on real grooms), so a
clump run's bytes do not depend on how its list came about; the build is this module's oracle.
An update declines (returns False, and the caller builds) when the grid moved, when so much
moved or the re-sorted stretch is so long that a build costs less (:func:`update_pays`), or when
a chunk of the forward entries outgrew its room.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from hairtool.bounds import moved_box
from hairtool.frozen.spatial import NeighbourList, _gather, _scan_row, search_reach
from hairtool.kernel_arrays import readonly
from hairtool.serial_twins import twin_njit

BACKWARD_BLOCKS = 16  # tasks of the backward lists' transpose at most (the lists do not depend on them)
BLOCK_REACHES = 6  # a task's rows at least this many times the ny + 1 rows its sources reach back
# (each task scans those again: 16 tasks over a 100k-vertex scalp's stretch of 2,700 rows scanned
# 1.6x its entries, 0.69 ms; 4 tasks 0.39 ms)
# An update's cost against a build's: per moved vertex (its searches and the marked vertices'),
# per vertex of the re-sorted stretch, and a fixed part that matters on small grooms. Fitted on
# the 2-core VM (update / build: 1M-vertex scalp 0.29 at 1.3 % moved over 0.28 of the groom, 0.84
# at 7.6 % over 0.38, 1.85 at 20 % over 0.5; bear 0.43 at 3.5 % over 0.28, 1.26 at 18 % over 0.38;
# mohawk 0.65 at 2 % over 0.8; a ponytail piece of 8,000 vertices 1.17 at 0.5 % over 0.85;
# Sintel 0.6 at 1.7 % over 0.16, 1.14 at 14 % over 0.47).
PER_MOVED, PER_SPAN, FIXED_VERTICES = 6.0, 0.8, 3000.0


def update_pays(moved_share: float, span_share: float, vertices: int) -> bool:
    """Whether an update that moves ``moved_share`` of the vertices and re-sorts ``span_share``
    of them costs less than a build (the cost model above).

    Parameters
    ----------
    moved_share : float
        The share of the vertices that moved.
    span_share : float
        The share re-sorted.
    vertices : int
        V.

    Returns
    -------
    bool
        True where updating is cheaper.
    """
    return PER_MOVED * moved_share + PER_SPAN * span_share + FIXED_VERTICES / max(vertices, 1) < 1.0


@twin_njit(nogil=True, parallel=True)
def _moved_mask(points, ref, mask):
    for i in prange(points.shape[0]):
        mask[i] = (points[i, 0] != ref[i, 0]) | (points[i, 1] != ref[i, 1]) | (points[i, 2] != ref[i, 2])


def moved_vertices(points: np.ndarray, ref: np.ndarray) -> np.ndarray:
    """Indices of the vertices whose point differs from ``ref``'s (NaN counts as moved).

    Parameters
    ----------
    points : ndarray
        ``(V, 3)`` now.
    ref : ndarray
        ``(V, 3)`` before.

    Returns
    -------
    ndarray
        int64 indices, increasing.
    """
    mask = np.empty(points.shape[0], np.bool_)
    _moved_mask(readonly(points), readonly(ref), mask)
    return np.flatnonzero(mask)


def moved_vertices_reference(points: np.ndarray, ref: np.ndarray) -> np.ndarray:
    """numpy twin of :func:`moved_vertices`.

    Parameters
    ----------
    points, ref : ndarray
        As :func:`moved_vertices` takes them.

    Returns
    -------
    ndarray
        As :func:`moved_vertices` gives them.
    """
    return np.flatnonzero(np.any(points != ref, axis=1))


@twin_njit(nogil=True, parallel=True)
def _resort_rows(ra, rb, old_start, start, old_order, moved, arrivals, arr_start, qx, order, came, mold):
    """The new order of rows [ra, rb]: a row without a moved vertex, old or new, is its old run
    moved to its new start; another merges its unmoved vertices (already in (quantised x, index)
    order) with the moved vertices that now lie in it, in the same order, as the build's stable
    counting sorts would. ``came[w − p0]``: the old position of the vertex now at w (−1: moved);
    ``mold[m]``: the old position of moved vertex m."""
    p0 = old_start[0]
    for r in prange(ra, rb + 1):
        a, b = old_start[r - ra] - p0, old_start[r - ra + 1] - p0
        m, e = arr_start[r - ra], arr_start[r - ra + 1]
        w = start[r]
        while a < b or m < e:
            if a < b and moved[old_order[a]]:
                mold[old_order[a]] = p0 + a
                a += 1
                continue
            take_old = m == e
            if a < b and m < e:
                i, j = old_order[a], arrivals[m]
                take_old = qx[i] < qx[j] or (qx[i] == qx[j] and i < j)
            if a < b and take_old:
                order[w] = old_order[a]
                came[w - p0] = p0 + a
                a += 1
            else:
                order[w] = arrivals[m]
                came[w - p0] = -1
                m += 1
            w += 1


@twin_njit(nogil=True, parallel=True)
def _inverse(came, p0, to_new):
    """``to_new[o − p0]``: where the vertex at old position o is now (−1: it moved)."""
    for k in prange(to_new.size):
        to_new[k] = -1
    for k in prange(came.size):
        if came[k] >= 0:
            to_new[came[k] - p0] = p0 + k


@njit(cache=True, nogil=True)
def _first_at(order, qx, a, b, q):
    """The first position in [a, b) of a row (in quantised-x order) whose vertex's quantised x
    is at least q (b: none)."""
    while a < b:
        m = (a + b) // 2
        if qx[order[m]] < q:
            a = m + 1
        else:
            b = m
    return a


@twin_njit(nogil=True, parallel=True)
def _mark_finders(moved, mold, bstart, bflat, p0, to_new, mark):
    """Mark the vertices that found a moved vertex where it was: its backward list before."""
    p1 = p0 + to_new.size
    for k in prange(moved.size):
        o = mold[moved[k]]
        for e in range(bstart[o], bstart[o + 1]):
            i = bflat[e]
            if p0 <= i < p1:
                i = to_new[i - p0]
            if i >= 0:
                mark[i] = True


@twin_njit(nogil=True, parallel=True)
def _mark_new_finders(p0, came, lo0, inv_q, ny, nz, reach, sx, sy, sz, start, order, qx, keys, mark):
    """Mark the vertices whose search can find a moved vertex where it is now: those within
    ``reach`` of it before it in its row and in the rows before its own among the 3 × 3 around
    it (the rows whose search reaches its row)."""
    for k in prange(came.size):
        if came[k] >= 0:
            continue
        w = p0 + k
        x, y, z = sx[w], sy[w], sz[w]
        qlo = np.int64(np.floor((x - reach - lo0) * inv_q)) - 1
        qhi = np.int64(np.floor((x + reach - lo0) * inv_q)) + 1
        r = keys[order[w]]
        cy, cz = r % ny, r // ny
        for dz in range(-1, 1):
            if cz + dz < 0:
                continue
            for dy in range(-1, 2):
                if (dz == 0 and dy > 0) or cy + dy < 0 or cy + dy >= ny:
                    continue
                row = r + dz * ny + dy
                end = w if dz == 0 and dy == 0 else start[row + 1]
                j = _first_at(order, qx, start[row], end, qlo)
                while j < end and qx[order[j]] <= qhi:
                    ex, ey, ez = sx[j] - x, sy[j] - y, sz[j] - z
                    if ex * ex + ey * ey + ez * ez < reach * reach:
                        mark[j] = True
                    j += 1


@njit(cache=True, nogil=True)
def _search_vertex(
    i, r, sx, sy, sz, sstrand, start, order, qx, lo0, inv_q, ny, nz, reach, r2, flat, pos, lim
):
    """Vertex i's forward entries (it lies in row r), as the build's search
    (:func:`~hairtool.frozen.spatial._forward_kernel`) finds them, each row's scan started where
    its quantised x reaches the window (the build's starts where the row's earlier vertices left
    it: the entries in between are not within reach, so the hits are the same, in the same
    order)."""
    cy, cz = r % ny, r // ny
    px, py, pz = sx[i], sy[i], sz[i]
    si = sstrand[i]
    xb = px + reach
    q = np.int64(np.floor((px - reach - lo0) * inv_q)) - 1
    first = np.int64(0)  # (not a literal 0: _scan_row as the full search compiled it)
    _, pos = _scan_row(
        sx, sy, sz, sstrand, i + 1, start[r + 1], px, py, pz, si, -np.inf, xb, r2, i + 1, flat, pos, lim
    )
    for k in range(4):
        if k == 0:
            row = r + 1 if cy + 1 < ny else -1
        elif k == 1:
            row = r + ny - 1 if cz + 1 < nz and cy >= 1 else -1
        elif k == 2:
            row = r + ny if cz + 1 < nz else -1
        else:
            row = r + ny + 1 if cz + 1 < nz and cy + 1 < ny else -1
        if row < 0:
            continue
        a, e = start[row], start[row + 1]
        j = _first_at(order, qx, a, e, q)
        _, pos = _scan_row(sx, sy, sz, sstrand, j, e, px, py, pz, si, -np.inf, xb, r2, first, flat, pos, lim)
    return pos


@twin_njit(nogil=True, parallel=True)
def _rewrite_forward(
    c0, c1, chunks, base, limit, rw0, rb, mark, p0, came, to_new,
    old_aflat, old_aoff, old_acnt, a0,
    sx, sy, sz, sstrand, start, order, qx, lo0, inv_q, ny, nz, reach, r2, aflat, aoff, acnt, over,
):  # fmt: skip
    """Chunks c0..c1 of the forward entries again, each from its base: rows before ``rw0`` as
    they were; in rows [rw0, rb] the moved vertices and those ``mark``ed searched again, the
    others given their old entries; later rows their old entries. An old entry's sorted
    position o in [p0, p0 + to_new.size) becomes ``to_new[o − p0]``, a vertex's old position
    is ``came[p − p0]`` there (−1: moved). ``old_*``: the chunks' entries and each vertex's
    offset and count before (vertices from ``a0`` on); ``over[c − c0]``: the chunk outgrew its
    room."""
    p1 = p0 + came.size
    for c in prange(c0, c1 + 1):
        pos = base[c]
        lim = limit[c]
        for r in range(chunks[c], chunks[c + 1]):
            if r < rw0:  # untouched (positions before the re-sorted rows do not move)
                for p in range(start[r], start[r + 1]):
                    pos += old_acnt[p - a0]
                continue
            for p in range(start[r], start[r + 1]):
                po = came[p - p0] if p0 <= p < p1 else p
                aoff[p] = pos
                if r <= rb and (po < 0 or mark[p]):
                    q = pos
                    pos = _search_vertex(
                        p, r, sx, sy, sz, sstrand, start, order, qx, lo0, inv_q, ny, nz, reach, r2,
                        aflat, pos, lim,
                    )  # fmt: skip
                    acnt[p] = pos - q
                    continue
                o, n = old_aoff[po - a0] - base[c0], old_acnt[po - a0]
                acnt[p] = n
                for k in range(o, o + n):
                    j = old_aflat[k]
                    if p0 <= j < p1:
                        j = to_new[j - p0]
                    aflat[min(pos, lim)] = j
                    pos += 1
        over[c - c0] = pos > lim


@twin_njit(nogil=True, parallel=True)
def _backward_lists(blocks, sources, aflat, aoff, acnt, q0, count, bstart, bflat, bmap, write):
    """The backward lists of the vertices [q0, …) in blocks of targets [blocks[b], blocks[b + 1]),
    each from the vertices [sources[b], blocks[b + 1]) (the only ones whose search reaches it):
    without ``write``, how many entries each gets (``count``); with it, the entries from
    ``bstart`` on (``count`` the fill), each j's finders in increasing i and ``bmap`` each
    entry's forward one, as the build's transpose writes them."""
    for b in prange(blocks.size - 1):
        t0, t1 = blocks[b], blocks[b + 1]
        for j in range(t0, t1):
            count[j - q0] = 0
        for i in range(sources[b], t1):
            for n in range(aoff[i], aoff[i] + acnt[i]):
                j = aflat[n]
                if t0 <= j < t1:
                    if write:
                        e = bstart[j] + count[j - q0]
                        bflat[e] = i
                        bmap[e] = n
                    count[j - q0] += 1


def _target_blocks(start, ny, q0, q1, n):
    """[q0, q1) in n blocks of positions, and for each the first vertex whose forward search
    reaches it (ny + 1 rows before the block's first row)."""
    blocks = np.unique(np.linspace(q0, q1, n + 1).astype(np.int64))
    first_row = np.searchsorted(start, blocks[:-1], side="right") - 1
    return blocks, start[np.maximum(first_row - ny - 1, 0)]


def update_list(
    nl: NeighbourList,
    points: np.ndarray,
    before: np.ndarray,
    strand: np.ndarray,
    skip: np.ndarray,
    moved: np.ndarray,
) -> bool:
    """Bring ``nl``, a row-grid list built for the same vertices (``strand``, ``skip`` as then)
    at its radius, up to date for ``points``, where only the vertices ``moved`` (indices,
    increasing) differ from ``before``, the points of its last build or update. False: not
    updated, and ``nl`` is left for a build only.

    Parameters
    ----------
    nl : NeighbourList
        A row-grid list.
    points : ndarray
        ``(V, 3)`` now.
    before : ndarray
        ``(V, 3)`` the points it was built for.
    strand : ndarray
        ``(V,)`` each vertex's strand.
    skip : ndarray
        ``(V,)`` bool, vertices left out.
    moved : ndarray
        The vertices that moved, increasing.

    Returns
    -------
    bool
        True where updated, False where a build is needed.
    """
    v = len(nl.order)
    if not nl.dense or nl.chunks is None or points.shape[0] != v:
        return False
    if moved.size == 0:
        return True
    if not update_pays(moved.size / v, 0.0, v):
        return False
    lo, hi, dims = nl._grid(points, nl.radius, True, moved_box(nl.raw_box, before[moved], points[moved]))
    if dims != nl.dims or not (np.array_equal(lo, nl.lo) and np.array_equal(hi, nl.hi)):
        return False
    ny, nz = dims[1], dims[2]
    p = points[moved].astype(np.float64)
    inv_cell = 1.0 / nl.radius
    new_key = np.minimum(np.floor((p[:, 1] - lo[1]) * inv_cell).astype(np.int64), ny - 1)
    new_key += ny * np.minimum(np.floor((p[:, 2] - lo[2]) * inv_cell).astype(np.int64), nz - 1)
    new_qx = np.minimum(np.floor((p[:, 0] - lo[0]) * nl.inv_q).astype(np.int64), nl.nq - 1)
    old_key = nl.keys[moved]
    ra = int(min(old_key.min(), new_key.min()))
    rb = int(max(old_key.max(), new_key.max()))
    if not update_pays(moved.size / v, (nl.start[rb + 1] - nl.start[ra]) / v, v):
        return False
    came, mold, to_new = _resort(nl, points, strand, skip, moved, old_key, new_key, new_qx, ra, rb)
    mark = np.zeros(v, np.bool_)
    _mark_finders(moved, mold, nl.bstart, nl.bflat, int(nl.start[ra]), to_new, mark)
    if not _forward(nl, ra, rb, came, to_new, mark):
        nl.chunks = None  # half rewritten: only a build can follow
        return False
    return True


def _resort(nl, points, strand, skip, moved, old_key, new_key, new_qx, ra, rb):
    """Step 1: rows [ra, rb] sorted again, their vertices gathered again. Returns (``came``,
    ``mold``, ``to_new``) as :func:`_resort_rows` and :func:`_inverse` give them."""
    v = len(nl.order)
    start = nl.start
    p0, p1 = int(start[ra]), int(start[rb + 1])
    old_start = start[ra : rb + 2].copy()
    counts = np.diff(old_start)
    np.subtract.at(counts, old_key - ra, 1)
    np.add.at(counts, new_key - ra, 1)
    start[ra + 1 : rb + 2] = p0 + np.cumsum(counts)
    nl.keys[moved] = new_key
    nl._qx[moved] = new_qx
    by = np.lexsort((moved, new_qx, new_key))
    arrivals = moved[by]
    arr_start = np.searchsorted(new_key[by], np.arange(ra, rb + 2)).astype(np.int64)
    is_moved = np.zeros(v, np.bool_)
    is_moved[moved] = True
    old_order = nl.order[p0:p1].copy()
    came = np.empty(p1 - p0, np.int64)
    mold = np.empty(v, np.int64)  # (read at the moved vertices only)
    sort = (is_moved, arrivals, arr_start, nl._qx)
    _resort_rows(ra, rb, old_start, start, old_order, *sort, nl.order, came, mold)
    k = slice(p0, p1)
    inputs = readonly(points), readonly(strand), readonly(skip)  # the build's signature
    _gather(nl.order[k], *inputs, nl.x[k], nl.y[k], nl.z[k], nl.strand[k], nl.skip[k])
    to_new = np.empty(p1 - p0, np.int64)
    _inverse(came, p0, to_new)
    return came, mold, to_new


def _forward(nl, ra, rb, came, to_new, mark) -> bool:
    """Steps 2 and 3: the forward entries of the chunks that hold rows [rw0, rb] (rw0 the first
    row whose search reaches row ra), searched again from the moved vertices and the ``mark``ed
    ones (those that found a moved vertex where it was; here also those that can find it where
    it is); then the backward lists those entries point into. False: a chunk outgrew its room."""
    ny, nz = nl.dims[1], nl.dims[2]
    start = nl.start
    p0 = int(start[ra])
    r2 = nl.radius**2
    reach = search_reach(r2, nl.slack, nl.radius)
    lo0 = nl.lo[0]
    grid = (lo0, nl.inv_q, ny, nz, reach, nl.x, nl.y, nl.z, start, nl.order, nl._qx)
    _mark_new_finders(p0, came, *grid, nl.keys, mark)
    rw0 = max(0, ra - ny - 1)
    chunks, base, limit = nl.chunks, nl.base, nl.limit
    c0 = int(np.searchsorted(chunks, rw0, side="right") - 1)
    c1 = int(np.searchsorted(chunks, rb, side="right") - 1)
    a0, a1 = int(start[chunks[c0]]), int(start[chunks[c1 + 1]])
    old_aoff = nl.aoff[a0:a1].copy()
    old_acnt = nl.acnt[a0:a1].copy()
    old_aflat = nl.aflat[base[c0] : limit[c1] + 1].copy()
    over = np.zeros(c1 - c0 + 1, np.bool_)
    _rewrite_forward(
        c0, c1, chunks, base, limit, rw0, rb, mark, p0, came, to_new,
        old_aflat, old_aoff, old_acnt, a0,
        nl.x, nl.y, nl.z, nl.strand, start, nl.order, nl._qx, lo0, nl.inv_q, ny, nz, reach, r2,
        nl.aflat, nl.aoff, nl.acnt, over,
    )  # fmt: skip
    if over.any():
        return False
    nl.forward_entries += int(nl.acnt[a0:a1].sum() - old_acnt.sum())
    # The backward lists from rw0 to the rows the last rewritten chunk's search reaches.
    qb = min(ny * nz - 1, int(chunks[c1 + 1]) - 1 + ny + 1)
    _backward(nl, rw0, qb + 1)
    return True


def _backward(nl, r0, r1) -> None:
    """The backward lists of the vertices of rows [r0, r1) transposed again; those after them
    moved along by the change in their number."""
    ny = nl.dims[1]
    q0, q1 = int(nl.start[r0]), int(nl.start[r1])
    tasks = int(min(BACKWARD_BLOCKS, max(2, (r1 - r0) // (BLOCK_REACHES * (ny + 1)))))
    blocks, sources = _target_blocks(nl.start, ny, q0, q1, tasks)
    count = np.empty(q1 - q0, np.int64)
    lists = (nl.aflat, nl.aoff, nl.acnt, q0, count)
    _backward_lists(blocks, sources, *lists, nl.bstart, nl.bflat, nl.bmap, False)
    bstart = nl.bstart
    total = int(bstart[-1])
    diff = int(count.sum()) - int(bstart[q1] - bstart[q0])
    if diff:
        tail = int(bstart[q1])
        if nl.bflat.size < total + diff:
            room = int((total + diff) * 1.25) + 16
            bflat, bmap = np.empty(room, np.int32), np.empty(room, np.int64)
            bflat[:total], bmap[:total] = nl.bflat[:total], nl.bmap[:total]
            nl.bflat, nl.bmap = bflat, bmap
        nl.bflat[tail + diff : total + diff] = nl.bflat[tail:total]  # (numpy copies overlaps safely)
        nl.bmap[tail + diff : total + diff] = nl.bmap[tail:total]
        bstart[q1 + 1 :] += diff
    bstart[q0 + 1 : q1 + 1] = bstart[q0] + np.cumsum(count)
    _backward_lists(blocks, sources, *lists, bstart, nl.bflat, nl.bmap, True)
