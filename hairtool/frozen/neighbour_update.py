"""A neighbour list brought up to date where vertices moved, instead of built again.

A brush stroke moves the strands under the brush; the full run on release wants the list of
the new points, and a build from scratch costs half of that run on a big groom. On the row grid
(:class:`~hairtool.frozen.spatial.NeighbourList`), a vertex's lists depend only on the rows
(y, z cells) around it, so an update:

1. re-sorts the rows that held or now hold a moved vertex (the others keep their order and
   only shift by their row's new start);
2. searches again from the vertices whose forward search reaches such a row, and gives every
   other vertex of the stretch its old entries with the shift applied;
3. transposes again the backward lists of the stretch of rows the change reaches.

Everything outside that stretch stays as it was. The result is the list a build from scratch
gives, entry for entry and in the same order (tests compare the two on real grooms), so a
clump run's bytes do not depend on how its list came about; the build is this module's oracle.
An update declines (returns False, and the caller builds) when the grid moved, when too much
moved for an update to pay, or when a chunk of the forward entries outgrew its room.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from hairtool.frozen.spatial import NeighbourList, _search_row, search_reach
from hairtool.serial_twins import twin_njit

UPDATE_SHARE = 0.25  # moved vertices, as a share of all, above which a build is cheaper
SPAN_SHARE = 0.8  # sorted positions between the first and last row that changed, as a share, above
# which likewise (2-core VM: an update over 0.8 of the mohawk cost 0.6 of a build, over 0.8 of a
# ponytail piece as much as one)


@twin_njit(nogil=True, parallel=True)
def _moved_mask(points, ref, mask):
    for i in prange(points.shape[0]):
        mask[i] = (points[i, 0] != ref[i, 0]) | (points[i, 1] != ref[i, 1]) | (points[i, 2] != ref[i, 2])


def moved_vertices(points: np.ndarray, ref: np.ndarray) -> np.ndarray:
    """Indices of the vertices whose point differs from ``ref``'s (NaN counts as moved)."""
    mask = np.empty(points.shape[0], np.bool_)
    _moved_mask(points, ref, mask)
    return np.flatnonzero(mask)


def moved_vertices_reference(points: np.ndarray, ref: np.ndarray) -> np.ndarray:
    """numpy twin of :func:`moved_vertices`."""
    return np.flatnonzero(np.any(points != ref, axis=1))


@twin_njit(nogil=True, parallel=True)
def _resort_rows(ra, rb, old_start, start, old_order, moved, arrivals, arr_start, qx, order):
    """The new order of rows [ra, rb]: a row without a moved vertex, old or new, is its old run
    moved to its new start; another merges its unmoved vertices (already in (quantised x, index)
    order) with the moved vertices that now lie in it, in the same order, as the build's stable
    counting sorts would."""
    p0 = old_start[0]
    for r in prange(ra, rb + 1):
        a, b = old_start[r - ra] - p0, old_start[r - ra + 1] - p0
        m, e = arr_start[r - ra], arr_start[r - ra + 1]
        w = start[r]
        while a < b or m < e:
            if a < b and moved[old_order[a]]:
                a += 1
                continue
            take_old = m == e
            if a < b and m < e:
                i, j = old_order[a], arrivals[m]
                take_old = qx[i] < qx[j] or (qx[i] == qx[j] and i < j)
            if a < b and take_old:
                order[w] = old_order[a]
                a += 1
            else:
                order[w] = arrivals[m]
                m += 1
            w += 1


@twin_njit(nogil=True, parallel=True)
def _gather_span(p0, p1, order, points, strand, skip, sx, sy, sz, sstrand, sskip):
    for k in prange(p0, p1):
        i = order[k]
        sx[k] = points[i, 0]
        sy[k] = points[i, 1]
        sz[k] = points[i, 2]
        sstrand[k] = strand[i]
        sskip[k] = skip[i]


@njit(cache=True, nogil=True)
def _search_rows_marked(changed, ny, nz, rw0, rb, search):
    """``search[r − rw0]``: whether row r's forward search reaches a changed row (the search's
    own rows: r, (y+1, z), (y−1..y+1, z+1))."""
    n_rows = changed.size
    for r in range(rw0, rb + 1):
        cy, cz = r % ny, r // ny
        s = changed[r]
        if cy + 1 < ny:
            s |= changed[r + 1]
        if cz + 1 < nz:
            s |= changed[r + ny]
            if cy >= 1:
                s |= changed[r + ny - 1]
            if cy + 1 < ny and r + ny + 1 < n_rows:
                s |= changed[r + ny + 1]
        search[r - rw0] = s


@twin_njit(nogil=True, parallel=True)
def _rewrite_forward(
    c0, c1, chunks, base, limit, rw0, rb, search, row_shift, p_lo, pos_shift,
    old_aflat, old_aoff, old_acnt, a0,
    sx, sy, sz, sstrand, start, ny, nz, reach, r2, aflat, aoff, acnt, over,
):  # fmt: skip
    """Chunks c0..c1 of the forward entries again, each from its base: rows before ``rw0`` as
    they were; rows [rw0, rb] searched again (``search``) or with their old entries; later rows
    with their old entries, every old sorted position in them shifted (``pos_shift`` over the
    old positions from ``p_lo``). ``old_*``: the chunks' entries and each vertex's offset and
    count before (vertices from ``a0`` on); ``over[c − c0]``: the chunk outgrew its room."""
    p_hi = p_lo + pos_shift.size
    for c in prange(c0, c1 + 1):
        pos = base[c]
        lim = limit[c]
        for r in range(chunks[c], chunks[c + 1]):
            if r < rw0:  # untouched (positions before the re-sorted rows do not move)
                for p in range(start[r], start[r + 1]):
                    pos += old_acnt[p - a0]
                continue
            if r <= rb and search[r - rw0]:
                q = pos
                pos = _search_row(sx, sy, sz, sstrand, start, ny, nz, r, reach, r2, aflat, pos, lim, acnt)
                for p in range(start[r], start[r + 1]):
                    aoff[p] = q
                    q += acnt[p]
                continue
            d = row_shift[r - rw0] if r <= rb else 0
            for p in range(start[r], start[r + 1]):
                po = p - d  # the vertex's old position (its row kept its order)
                o, n = old_aoff[po - a0] - base[c0], old_acnt[po - a0]
                aoff[p] = pos
                acnt[p] = n
                for k in range(o, o + n):
                    j = old_aflat[k]
                    if p_lo <= j < p_hi:
                        j += pos_shift[j - p_lo]
                    aflat[min(pos, lim)] = j
                    pos += 1
        over[c - c0] = pos > lim


@njit(cache=True, nogil=True)
def _backward_counts(s0, q0, q1, aflat, aoff, acnt, count):
    """How many forward entries of the vertices [s0, q1) point at each vertex of [q0, q1)."""
    count[:] = 0
    for i in range(s0, q1):
        for n in range(aoff[i], aoff[i] + acnt[i]):
            j = aflat[n]
            if q0 <= j < q1:
                count[j - q0] += 1


@njit(cache=True, nogil=True)
def _backward_fill(s0, q0, q1, aflat, aoff, acnt, bstart, bflat, bmap, fill):
    """The backward lists of [q0, q1) from the forward entries of [s0, q1): each j's finders
    in increasing i, ``bmap`` each entry's forward one, as the build's transpose writes them."""
    fill[:] = 0
    for i in range(s0, q1):
        for n in range(aoff[i], aoff[i] + acnt[i]):
            j = aflat[n]
            if q0 <= j < q1:
                e = bstart[j] + fill[j - q0]
                bflat[e] = i
                bmap[e] = n
                fill[j - q0] += 1


def update_list(
    nl: NeighbourList, points: np.ndarray, strand: np.ndarray, skip: np.ndarray, moved: np.ndarray
) -> bool:
    """Bring ``nl``, a row-grid list built for the same vertices (``strand``, ``skip`` as then)
    at its radius, up to date for ``points``, where only the vertices ``moved`` (indices,
    increasing) differ from its last points. False: not updated, and ``nl`` is left for a
    build only."""
    v = len(nl.order)
    if not nl.dense or nl.chunks is None or points.shape[0] != v:
        return False
    if moved.size == 0:
        return True
    if moved.size > UPDATE_SHARE * v:
        return False
    lo, hi, dims = nl._grid(points, nl.radius, True)
    if dims != nl.dims or not (np.array_equal(lo, nl.lo) and np.array_equal(hi, nl.hi)):
        return False
    ny, nz = dims[1], dims[2]
    start = nl.start
    p = points[moved].astype(np.float64)
    inv_cell = 1.0 / nl.radius
    new_key = np.minimum(np.floor((p[:, 1] - lo[1]) * inv_cell).astype(np.int64), ny - 1)
    new_key += ny * np.minimum(np.floor((p[:, 2] - lo[2]) * inv_cell).astype(np.int64), nz - 1)
    new_qx = np.minimum(np.floor((p[:, 0] - lo[0]) * nl.inv_q).astype(np.int64), nl.nq - 1)
    old_key = nl.keys[moved]
    ra = int(min(old_key.min(), new_key.min()))
    rb = int(max(old_key.max(), new_key.max()))
    p0, p1 = int(start[ra]), int(start[rb + 1])
    if p1 - p0 > SPAN_SHARE * v:
        return False

    # 1. Rows [ra, rb] sorted again; the vertices between p0 and p1 gathered again.
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
    _resort_rows(ra, rb, old_start, start, old_order, is_moved, arrivals, arr_start, nl._qx, nl.order)
    _gather_span(p0, p1, nl.order, points, strand, skip, nl.x, nl.y, nl.z, nl.strand, nl.skip)

    # 2. The forward entries of the chunks that hold rows [rw0, rb], rw0 the first row whose
    # search reaches row ra.
    changed = np.zeros(ny * nz, np.bool_)
    changed[old_key] = True
    changed[new_key] = True
    rw0 = max(0, ra - ny - 1)
    search = np.empty(rb - rw0 + 1, np.bool_)
    _search_rows_marked(changed, ny, nz, rw0, rb, search)
    row_shift = np.zeros(rb - rw0 + 1, np.int64)
    row_shift[ra - rw0 :] = start[ra : rb + 1] - old_start[:-1]
    pos_shift = np.repeat(row_shift[ra - rw0 :], np.diff(old_start))  # of each old position in [p0, p1)
    chunks, base, limit = nl.chunks, nl.base, nl.limit
    c0 = int(np.searchsorted(chunks, rw0, side="right") - 1)
    c1 = int(np.searchsorted(chunks, rb, side="right") - 1)
    a0, a1 = int(start[chunks[c0]]), int(start[chunks[c1 + 1]])
    old_aoff = nl.aoff[a0:a1].copy()
    old_acnt = nl.acnt[a0:a1].copy()
    old_aflat = nl.aflat[base[c0] : limit[c1] + 1].copy()
    over = np.zeros(c1 - c0 + 1, np.bool_)
    r2 = nl.radius**2
    _rewrite_forward(
        c0, c1, chunks, base, limit, rw0, rb, search, row_shift, p0, pos_shift,
        old_aflat, old_aoff, old_acnt, a0,
        nl.x, nl.y, nl.z, nl.strand, start, ny, nz, search_reach(r2, nl.slack, nl.radius), r2,
        nl.aflat, nl.aoff, nl.acnt, over,
    )  # fmt: skip
    if over.any():
        nl.chunks = None  # half rewritten: only a build can follow
        return False
    nl.forward_entries += int(nl.acnt[a0:a1].sum() - old_acnt.sum())

    # 3. The backward lists of the rows those entries point into: from rw0 to the rows the
    # last rewritten chunk's search reaches.
    qb = min(ny * nz - 1, int(chunks[c1 + 1]) - 1 + ny + 1)
    q0, q1 = int(start[rw0]), int(start[qb + 1])
    s0 = int(start[max(0, rw0 - ny - 1)])
    count = np.empty(q1 - q0, np.int64)
    _backward_counts(s0, q0, q1, nl.aflat, nl.aoff, nl.acnt, count)
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
    _backward_fill(s0, q0, q1, nl.aflat, nl.aoff, nl.acnt, bstart, nl.bflat, nl.bmap, count)
    return True
