"""A grid of every vertex of a groom, kept across brush moves and updated where strands moved.

The brush-local engine (:mod:`hairtool.frozen.local`) asks it three things on each mouse move:
which strands have a vertex within a brush's radius, which vertices a change can reach through
the clump kernel's lists (other strands within h·(1 + MARGIN)) and nearest neighbours, walked
in one call (:meth:`VertexGrid.reach`), and the neighbour list of each vertex it redoes. Cells
are cubes one list radius wide, hashed into about 2V buckets, each a doubly linked list of
vertices, so that moving a vertex to another cell costs O(1) and the grid never has to be
rebuilt while the strands stay the same (a candidate counts only where its exact cell matches,
so hash collisions never count twice). Cell coordinates are clipped to ±2**20, which only makes
far-away cells share a list.

A vertex's list comes in the order a full build of :class:`hairtool.frozen.spatial.NeighbourList`
gives it (:func:`list_frame` names that build's grid): the neighbours after the vertex in the
build's sorted order, then those before it, each increasing. So the pulls are summed in the same
order, and a brush-local run gives a full run's bits. The ``*_reference`` functions are the
numpy twins.
"""

from __future__ import annotations

import numba
import numpy as np
from numba import njit, prange

from hairtool import serial_twins
from hairtool.bounds import box
from hairtool.kernel_arrays import readonly
from hairtool.serial_twins import twin_njit

_OFF = 1 << 20  # cell coordinates are clipped to [−_OFF, _OFF − 1]
_BITS = 21
_HASH = np.uint64(0x9E3779B97F4A7C15)
IDX_BITS = 24  # vertex index bits in a list sort key: grooms of up to 16.7M vertices
_IDX_MASK = (1 << IDX_BITS) - 1
_SNAP = 16  # as hairtool.frozen.spatial.SNAP (the list build's grid lattice)
_CELL_MASK = (1 << _BITS) - 1
BLOCK_COUNTERS = 1 << 22  # at most (16 MB): blocks of 4³ cells or coarser over the groom's box


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


@njit(cache=True, nogil=True, inline="always")
def _block_at(cx, cy, cz, origin, dims, shift):
    """The counter of the block that holds cell (cx, cy, cz): blocks of 2**shift cells a side
    from the cell ``origin``, ``dims`` of them; past them, the last counter (outside)."""
    bx = (cx - origin[0]) >> shift
    by = (cy - origin[1]) >> shift
    bz = (cz - origin[2]) >> shift
    if bx < 0 or by < 0 or bz < 0 or bx >= dims[0] or by >= dims[1] or bz >= dims[2]:
        return dims[0] * dims[1] * dims[2]
    return (bz * dims[1] + by) * dims[0] + bx


@njit(cache=True, nogil=True, inline="always")
def _block_of(key, origin, dims, shift):
    """:func:`_block_at` of a packed cell key."""
    cx = (key & _CELL_MASK) - _OFF
    cy = ((key >> _BITS) & _CELL_MASK) - _OFF
    cz = ((key >> (2 * _BITS)) & _CELL_MASK) - _OFF
    return _block_at(cx, cy, cz, origin, dims, shift)


@njit(cache=True, nogil=True)
def _count_blocks(key, origin, dims, shift, count):
    count[:] = 0
    for i in range(key.size):
        count[_block_of(key[i], origin, dims, shift)] += 1


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
def _move(points, vids, inv, shift, key, head, nxt, prv, blocks):
    """The vertices ``vids`` into the cells of their new ``points`` (and their blocks' counts);
    returns how many changed cell."""
    origin, dims, bshift, count = blocks
    moved = 0
    for n in range(vids.size):
        i = vids[n]
        k = _pack(_coord(points[i, 0], inv), _coord(points[i, 1], inv), _coord(points[i, 2], inv))
        if k == key[i]:
            continue
        moved += 1
        count[_block_of(key[i], origin, dims, bshift)] -= 1
        count[_block_of(k, origin, dims, bshift)] += 1
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


@njit(cache=True, nogil=True)
def _cell_groups(qx, qy, qz, inv):
    """The queries by grid cell: ``(order, starts)``, the queries of group g being
    ``order[starts[g] : starts[g + 1]]``. Queries of one cell share the cells around it, so a
    group walks those cells' linked lists once for all its queries."""
    n = qx.size
    keys = np.empty(n, np.int64)
    for q in range(n):
        keys[q] = _pack(_coord(qx[q], inv), _coord(qy[q], inv), _coord(qz[q], inv))
    order = np.argsort(keys)
    starts = np.empty(n + 1, np.int64)
    g = 0
    for k in range(n):
        if k == 0 or keys[order[k]] != keys[order[k - 1]]:
            starts[g] = k
            g += 1
    starts[g] = n
    return order, starts[: g + 1]


@njit(cache=True, nogil=True)
def _gather_block(gx, gy, gz, shift, key, head, nxt, out):
    """The vertices of the 3 × 3 × 3 cells around cell (gx, gy, gz) into ``out`` (as many as
    fit); returns how many there are (more than ``out`` holds: call again with a larger one)."""
    m = 0
    for cz in range(max(gz - 1, -_OFF), min(gz + 1, _OFF - 1) + 1):
        for cy in range(max(gy - 1, -_OFF), min(gy + 1, _OFF - 1) + 1):
            for cx in range(max(gx - 1, -_OFF), min(gx + 1, _OFF - 1) + 1):
                k = _pack(cx, cy, cz)
                j = head[_bucket(k, shift)]
                while j >= 0:
                    if key[j] == k:
                        if m < out.size:
                            out[m] = j
                        m += 1
                    j = nxt[j]
    return m


@njit(cache=True, nogil=True)
def _block_in(gx, gy, gz, shift, key, head, nxt, scratch):
    """:func:`_gather_block` into ``scratch`` (a thread's, reused: allocating on the parallel
    threads cost more than the work), or into an array of its own where the block is crowded."""
    m = _gather_block(gx, gy, gz, shift, key, head, nxt, scratch)
    if m <= scratch.size:
        return scratch[:m]
    out = np.empty(m, np.int64)
    _gather_block(gx, gy, gz, shift, key, head, nxt, out)
    return out


_BLOCK_ROOM = 512  # vertices of a 3 × 3 × 3 block of cells a thread keeps room for (more: arrays of its own)


@twin_njit(nogil=True, parallel=True)
def _mark_near_grouped(points, strand, qx, qy, qz, r2, inv, shift, key, head, nxt, mark):
    """:func:`_mark_near` for a reach of at most one cell: the queries grouped by cell, each
    group testing the vertices of the 27 cells around its own (every vertex within the reach
    of a query lies there), read from the grid once per group rather than once per query."""
    order, starts = _cell_groups(qx, qy, qz, inv)
    scratch = np.empty((numba.config.NUMBA_NUM_THREADS, _BLOCK_ROOM), np.int64)  # each thread's block
    for g in prange(starts.size - 1):
        q0 = order[starts[g]]
        gx, gy, gz = _coord(qx[q0], inv), _coord(qy[q0], inv), _coord(qz[q0], inv)
        block = _block_in(gx, gy, gz, shift, key, head, nxt, scratch[numba.get_thread_id()])
        for c in range(block.size):
            j = block[c]
            if mark[strand[j]]:
                continue
            x, y, z = np.float64(points[j, 0]), np.float64(points[j, 1]), np.float64(points[j, 2])
            for k in range(starts[g], starts[g + 1]):
                q = order[k]
                ex = x - qx[q]
                ey = y - qy[q]
                ez = z - qz[q]
                if ex * ex + ey * ey + ez * ez < r2:
                    mark[strand[j]] = True
                    break


@twin_njit(nogil=True, parallel=True)
def _mark_near(points, strand, qx, qy, qz, r2, inv, shift, key, head, nxt, mark, bs):
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
            _mark_slab(points, strand, px, py, pz, r2, shift, key, head, nxt, mark, x0, x1, y0, y1, cz, bs)


@njit(cache=True, nogil=True)
def _mark_slab(points, strand, px, py, pz, r2, shift, key, head, nxt, mark, x0, x1, y0, y1, cz, bs):
    """The strands with a vertex closer than sqrt(r2) to p among the cells [x0, x1] × [y0, y1]
    of the slab cz. ``bs``: the grid's block counters (:attr:`VertexGrid.blocks`): the cells of
    a block that holds no vertex are passed over without a look at their buckets (a brush's
    box is mostly empty cells, and the buckets, 16 bytes a vertex, miss the cache)."""
    origin, dims, bshift, count = bs
    outside = dims[0] * dims[1] * dims[2]
    for cy in range(y0, y1 + 1):
        cx = x0
        while cx <= x1:
            b = _block_at(cx, cy, cz, origin, dims, bshift)
            if count[b] == 0:
                # on to the next block's first cell (past the counted box: the next cell)
                cx = cx + 1 if b == outside else ((((cx - origin[0]) >> bshift) + 1) << bshift) + origin[0]
                continue
            k = _pack(cx, cy, cz)
            cx += 1
            j = head[_bucket(k, shift)]
            while j >= 0:
                if key[j] == k and not mark[strand[j]]:
                    ex = np.float64(points[j, 0]) - px
                    ey = np.float64(points[j, 1]) - py
                    ez = np.float64(points[j, 2]) - pz
                    if ex * ex + ey * ey + ez * ez < r2:
                        mark[strand[j]] = True
                j = nxt[j]


@twin_njit(nogil=True, parallel=True)
def _mark_near_wide(points, strand, px, py, pz, r2, inv, shift, key, head, nxt, mark, bs):
    """:func:`_mark_near` for one query over many cells (a brush): its slabs of cells in parallel."""
    reach = np.sqrt(r2)
    x0, x1 = _coord(px - reach, inv), _coord(px + reach, inv)
    y0, y1 = _coord(py - reach, inv), _coord(py + reach, inv)
    z0, z1 = _coord(pz - reach, inv), _coord(pz + reach, inv)
    for cz in prange(z0, z1 + 1):
        _mark_slab(points, strand, px, py, pz, r2, shift, key, head, nxt, mark, x0, x1, y0, y1, cz, bs)


@njit(cache=True, nogil=True)
def _vertices_near(points, strand, qx, qy, qz, qs, r2, inv, shift, key, head, nxt, skip, out):
    """The vertices not flagged in ``skip`` of a strand other than ``qs[q]`` closer than
    sqrt(r2) to a query q, for a reach of at most one cell (the 27 cells around a query hold
    them), each written once into ``out`` and flagged; returns how many. The queries go by grid
    cell (:func:`_cell_groups`): a group reads the 27 cells around its own from the grid once for
    all its queries (a region's queries are a few per cell on dense hair). Serial: they find each
    vertex dozens of times, and flagging it at once lets the later finds pass it by (in
    parallel, their duplicates cost more to sort out than the walk)."""
    order, starts = _cell_groups(qx, qy, qz, inv)
    scratch = np.empty(_BLOCK_ROOM, np.int64)
    m = 0
    for g in range(starts.size - 1):
        q0 = order[starts[g]]
        gx, gy, gz = _coord(qx[q0], inv), _coord(qy[q0], inv), _coord(qz[q0], inv)
        block = _block_in(gx, gy, gz, shift, key, head, nxt, scratch)
        for c in range(block.size):
            j = block[c]
            if skip[j]:
                continue
            x, y, z = np.float64(points[j, 0]), np.float64(points[j, 1]), np.float64(points[j, 2])
            sj = strand[j]
            for e in range(starts[g], starts[g + 1]):
                q = order[e]
                if qs[q] == sj:
                    continue
                ex = x - qx[q]
                ey = y - qy[q]
                ez = z - qz[q]
                if ex * ex + ey * ey + ez * ez < r2:
                    skip[j] = True
                    out[m] = j
                    m += 1
                    break
    return m


@njit(cache=True, nogil=True)
def _near_ids(points, strand, ids, r2, inv, shift, key, head, nxt, skip, out):
    """:func:`_vertices_near` with the vertices ``ids`` (their points and strands) as queries."""
    n = ids.size
    qx, qy, qz, qs = np.empty(n), np.empty(n), np.empty(n), np.empty(n, np.int64)
    for q in range(n):
        i = ids[q]
        qx[q], qy[q], qz[q] = points[i, 0], points[i, 1], points[i, 2]
        qs[q] = strand[i]
    return _vertices_near(points, strand, qx, qy, qz, qs, r2, inv, shift, key, head, nxt, skip, out)


@njit(cache=True, nogil=True)
def _reach_walks(new, was, new_bits, was_bits, strand, changed, best, gap, iterations, most, r2, inv, shift,
                 key, head, nxt, skip, out, known):  # fmt: skip
    """:meth:`hairtool.frozen.local.LocalClump.reach` in one call, on flags instead of sets:
    the reached vertices, unsorted, into ``out`` (V,); returns how many, or −1 past ``most``.
    ``skip`` (V,) is all False on entry and on return (only what a call flags is cleared: no
    pass over V); ``known`` (V,) is scratch. Each layer is a set, so the order the walks find
    its vertices in changes nothing the caller sorts."""
    nc = changed.size
    for c in range(nc):
        skip[changed[c]] = True
        out[c] = changed[c]
    nw = 0  # lists then and now: the changed points where they are, and where they were
    for c in range(nc):
        for a in range(3):
            if was_bits[c, a] != new_bits[changed[c], a]:
                nw += 1
                break
    m = nc + nw
    qx, qy, qz, qs = np.empty(m), np.empty(m), np.empty(m), np.empty(m, np.int64)
    w = nc
    for c in range(nc):
        i = changed[c]
        qx[c], qy[c], qz[c], qs[c] = new[i, 0], new[i, 1], new[i, 2], strand[i]
        for a in range(3):
            if was_bits[c, a] != new_bits[i, a]:
                qx[w], qy[w], qz[w], qs[w] = was[c, 0], was[c, 1], was[c, 2], strand[i]
                w += 1
                break
    pos = nc  # out[:pos]: the layers so far
    count = nc
    nk = 0  # known[:nk]: next forces the gap search already found (flagged)
    pulled0 = pulled1 = 0
    over = False
    grid = (r2, inv, shift, key, head, nxt, skip)
    for it in range(iterations):
        if it == 0:
            found = _vertices_near(new, strand, qx, qy, qz, qs, *grid, out[pos:])
        else:  # the pulled of the last iteration (or its fresh without the gap), searched
            found = _near_ids(new, strand, out[pulled0:pulled1], *grid, out[pos:])
        for k in range(nk):
            out[pos + found + k] = known[k]
        nf = found + nk
        forces = out[pos : pos + nf]
        nk = 0
        npull = 0
        if gap and nf > 0:
            near = known  # scratch until the known are picked from it
            nn = _near_ids(new, strand, forces, *grid, near)
            for k in range(nn):
                skip[near[k]] = False
            pull = np.empty(nn, np.bool_)
            for k in range(nn):  # their nearest's force can change (read before any is flagged)
                b = best[it, near[k]]
                pull[k] = b >= 0 and skip[b]
            for k in range(nn):
                j = near[k]
                skip[j] = True  # pulled, or known (the next forces): flagged either way
                if pull[k]:
                    out[pos + nf + npull] = j
                    npull += 1
            for k in range(nn):  # the known, kept in order in the scratch's front
                if not pull[k]:
                    known[nk] = near[k]
                    nk += 1
        fresh = nf + npull
        count += fresh
        if fresh == 0 or count > most:
            over = count > most
            pos += fresh  # (flagged: cleared below)
            break
        if gap:
            pulled0, pulled1 = pos + nf, pos + fresh
        else:
            pulled0, pulled1 = pos, pos + fresh
        pos += fresh
    for k in range(pos):
        skip[out[k]] = False
    for k in range(nk):
        skip[known[k]] = False
    return -1 if over else pos


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
    wider). The vertices go by grid cell: a cell's vertices test the block of 27 cells around
    it, read from the grid once (coordinates, strands and, on the row grid, build-order keys)."""
    nv = vids.size
    qx, qy, qz = np.empty(nv), np.empty(nv), np.empty(nv)
    for n in range(nv):
        qx[n], qy[n], qz[n] = points[vids[n], 0], points[vids[n], 1], points[vids[n], 2]
    order, starts = _cell_groups(qx, qy, qz, inv)
    threads = numba.config.NUMBA_NUM_THREADS
    scratch_j = np.empty((threads, _BLOCK_ROOM), np.int64)  # each thread's block, reused
    scratch_xyz = np.empty((threads, _BLOCK_ROOM, 3))
    scratch_sk = np.empty((threads, _BLOCK_ROOM, 2), np.int64)
    for g in prange(starts.size - 1):
        n0 = order[starts[g]]
        gx, gy, gz = _coord(qx[n0], inv), _coord(qy[n0], inv), _coord(qz[n0], inv)
        t = numba.get_thread_id()
        block = _block_in(gx, gy, gz, shift, key, head, nxt, scratch_j[t])
        nb = block.size
        bxyz, bsk = scratch_xyz[t], scratch_sk[t]  # strand, build-order key (row grid)
        if nb > _BLOCK_ROOM:  # a crowded block: arrays of its own
            bxyz, bsk = np.empty((nb, 3)), np.empty((nb, 2), np.int64)
        for c in range(nb):
            j = block[c]
            x, y, z = np.float64(points[j, 0]), np.float64(points[j, 1]), np.float64(points[j, 2])
            bxyz[c, 0], bxyz[c, 1], bxyz[c, 2] = x, y, z
            bsk[c, 0] = strand[j]
            if dense:
                bsk[c, 1] = _order_key(x, y, z, j, dense, lo, inv_cell, ny, nz, inv_q, nq, 0, 0, 0)
        for e in range(starts[g], starts[g + 1]):
            n = order[e]
            i = vids[n]
            px, py, pz = qx[n], qy[n], qz[n]
            si = strand[i]
            ox = np.int64(np.floor((px - lo[0]) * inv_cell))
            oy = np.int64(np.floor((py - lo[1]) * inv_cell))
            oz = np.int64(np.floor((pz - lo[2]) * inv_cell))
            base = n * cap
            m = 0
            if dense:  # branch-free (a hit is unpredictable): write always, count hits
                last = cap - 1  # the slot past a full list is scratch
                for c in range(nb):
                    ex, ey, ez = bxyz[c, 0] - px, bxyz[c, 1] - py, bxyz[c, 2] - pz
                    hit = (ex * ex + ey * ey + ez * ez < r2) & (bsk[c, 0] != si)
                    flat[base + min(m, last)] = bsk[c, 1]
                    m += np.int64(hit)
            else:  # the hashed grid's keys depend on the query's cell: made for the hits only
                for c in range(nb):
                    if bsk[c, 0] == si:
                        continue
                    ex, ey, ez = bxyz[c, 0] - px, bxyz[c, 1] - py, bxyz[c, 2] - pz
                    if ex * ex + ey * ey + ez * ez < r2:
                        if m < cap - 1:
                            flat[base + m] = _order_key(
                                bxyz[c, 0], bxyz[c, 1], bxyz[c, 2], block[c], dense, lo, inv_cell, ny, nz,
                                inv_q, nq, ox, oy, oz,
                            )  # fmt: skip
                        m += 1
            cnt[n] = m
            if m >= cap - 1:
                continue
            _sort_short(flat, base, base + m)
            row = flat[base : base + m]
            split = 0  # the row grid's list: those after i in sorted order, then those before
            if dense:
                own = _order_key(px, py, pz, i, dense, lo, inv_cell, ny, nz, inv_q, nq, ox, oy, oz)
                while split < m and row[split] < own:
                    split += 1
            # rotate by split in place: reverse the two parts, then the whole
            _reverse(flat, base, base + split)
            _reverse(flat, base + split, base + m)
            _reverse(flat, base, base + m)
            for e2 in range(base, base + m):
                flat[e2] = flat[e2] & _IDX_MASK


@njit(cache=True, nogil=True)
def _sort_short(a, b, e):
    """``a[b:e]`` sorted in place: by insertion where short (a vertex's hits come nearly in
    order, the 27 cells walked row by row as the list build orders them), else numpy's sort."""
    if e - b > 64:
        a[b:e].sort()
        return
    for k in range(b + 1, e):
        x = a[k]
        m = k
        while m > b and a[m - 1] > x:
            a[m] = a[m - 1]
            m -= 1
        a[m] = x


@njit(cache=True, nogil=True, inline="always")
def _reverse(a, b, e):
    e -= 1
    while b < e:
        a[b], a[e] = a[e], a[b]
        b += 1
        e -= 1


def list_frame(points: np.ndarray, radius: float, raw_box: tuple | None = None) -> tuple:
    """The grid a full :meth:`~hairtool.frozen.spatial.NeighbourList.build` of ``points`` at
    ``radius`` lays out (its corner, rows, x quantisation, row or hashed), which decides the
    order of its lists: ``(dense, lo, inv_cell, ny, nz, inv_q, nq)``, computed as the build does.
    ``raw_box``: the points' box in float64, where the caller keeps it (no pass over them).

    Parameters
    ----------
    points : ndarray
        ``(V, 3)``.
    radius : float
        The list's radius.
    raw_box : tuple, optional
        The points' box, where known.

    Returns
    -------
    tuple
        The frame.
    """
    v = points.shape[0]
    lo, hi = (b.astype(np.float64) for b in (box(points) if raw_box is None else raw_box))
    radius = float(radius)
    snap = _SNAP * radius
    lo, hi = np.floor(lo / snap) * snap, (np.floor(hi / snap) + 1.0) * snap
    dims = (np.floor((hi - lo) / radius).astype(np.int64) + 1).tolist()
    dense = dims[1] * dims[2] <= max(8 * v, 1 << 16)
    nq = int(min(1 << 16, max(64 * dims[0], 1)))
    width = max(float(hi[0] - lo[0]), 1e-300)
    return dense, lo, 1.0 / radius, int(dims[1]), int(dims[2]), nq / width, nq


def _blocks_over(points: np.ndarray, inv: float) -> tuple:
    """Vertex counters for blocks of cells over the box of ``points`` (``(origin, dims, shift,
    count)``, the last counter for the vertices that move out of the box): blocks of 4³ cells,
    or 8³ and coarser where the box would need more than :data:`BLOCK_COUNTERS`."""
    cells = (np.floor(b.astype(np.float64) * inv) for b in box(points))  # (as _coord computes them)
    lo, hi = (np.clip(c, -_OFF, _OFF - 1).astype(np.int64) for c in cells)
    span = hi - lo + 1
    shift = 2
    while int(np.prod(-(-span >> shift))) > BLOCK_COUNTERS:
        shift += 1
    dims = -(-span >> shift)
    return lo, dims, np.int64(shift), np.empty(int(np.prod(dims)) + 1, np.int32)


class VertexGrid:
    """Every vertex of one topology in hashed cells ``cell`` wide (see the module doc)."""

    def __init__(self, points: np.ndarray, strand: np.ndarray, cell: float) -> None:
        """A hashed grid of cell size ``cell`` over ``points``, kept up to date as vertices move.

        Parameters
        ----------
        points : ndarray
            ``(V, 3)``.
        strand : ndarray
            ``(V,)`` each vertex's strand.
        cell : float
            The cell size, > 0.
        """
        v = points.shape[0]
        self.cell = float(cell)
        self.inv = 1.0 / self.cell
        bits = max(6, int(np.ceil(np.log2(max(2 * v, 2)))))
        self.shift = np.uint64(64 - bits)
        self.key = np.empty(v, np.int64)
        self.head = np.empty(1 << bits, np.int64)
        self.nxt = np.empty(v, np.int64)
        self.prv = np.empty(v, np.int64)
        self.strand = readonly(np.asarray(strand, np.int64))  # as a topology holds it: one signature
        self.capacity = 64  # list slots per vertex (grows to the longest list + 1)
        self._flat = np.empty(0, np.int64)  # the lists' buffer (:meth:`prepare`)
        self._flags = np.zeros(0, np.bool_)  # :meth:`reach`'s, kept all False between calls
        self._found = self._known = np.empty(0, np.int64)  # and its scratch
        _build(readonly(points), self.inv, self.shift, self.key, self.head, self.nxt, self.prv)
        self.blocks = _blocks_over(points, self.inv)  # vertices per block of cells (_mark_slab skips)
        _count_blocks(self.key, *self.blocks)

    @property
    def vertex_count(self) -> int:
        return self.key.size

    def reserve(self, longest: int) -> None:
        """Room in :meth:`lists` for lists of ``longest`` neighbours (it grows by itself too).

        Parameters
        ----------
        longest : int
            Neighbours.
        """
        if longest + 1 >= self.capacity:
            self.capacity = (longest + 1 + 32) // 32 * 32

    def prepare(self, vertices: int) -> None:
        """Room in :meth:`lists` for the lists of this many vertices, its memory touched now: a
        buffer kept from move to move (a fresh one per move cost a move its page faults, ~13 ms
        for the bear's first region of 6,000 vertices). The lists :meth:`lists` returns live in it
        until the next call.

        Parameters
        ----------
        vertices : int
            Vertices.
        """
        need = vertices * self.capacity
        if self._flat.size < need:
            self._flat = np.empty(max(need, int(1.5 * self._flat.size)), np.int64)
            self._flat.fill(0)

    def move(self, points: np.ndarray, vids: np.ndarray) -> int:
        """The vertices ``vids`` now at ``points[vids]``; returns how many changed cell.

        Parameters
        ----------
        points : ndarray
            ``(V, 3)`` the points now.
        vids : ndarray
            The vertices that moved.

        Returns
        -------
        int
            The count that changed cell.
        """
        ids = np.ascontiguousarray(vids, np.int64)
        grid = (self.inv, self.shift, self.key, self.head, self.nxt, self.prv)
        return int(_move(readonly(points), ids, *grid, self.blocks))

    def strands_near(
        self, points: np.ndarray, queries: np.ndarray, radius: float, mark: np.ndarray, parallel: bool = True
    ) -> None:
        """Flag in ``mark`` ((S,) bool) the strands with a vertex of ``points`` (where the grid
        holds them) closer than ``radius`` to one of ``queries`` ((n, 3)).

        Parameters
        ----------
        points : ndarray
            ``(V, 3)``.
        queries : ndarray
            ``(n, 3)``.
        radius : float
            The distance.
        mark : ndarray
            ``(S,)`` bool, written.
        parallel : bool, default True
            Run the parallel kernels (False: their serial twins; the same flags).
        """
        q = np.asarray(queries, np.float64).reshape(-1, 3)
        points = readonly(points)  # the kernels' one signature, whoever holds the points
        radius = _within_reach(points, q, float(radius), self.cell)
        r2 = radius**2
        grid = (self.inv, self.shift, self.key, self.head, self.nxt, mark)
        if len(q) == 1 and _cells_within(q[0], float(radius), self.cell) <= self.vertex_count:
            x, y, z = float(q[0, 0]), float(q[0, 1]), float(q[0, 2])
            wide = _mark_near_wide if parallel else serial_twins.serial(_mark_near_wide)
            wide(points, self.strand, x, y, z, r2, *grid, self.blocks)
            return
        xyz = np.ascontiguousarray(q[:, 0]), np.ascontiguousarray(q[:, 1]), np.ascontiguousarray(q[:, 2])
        if float(radius) <= self.cell:
            grouped = _mark_near_grouped if parallel else serial_twins.serial(_mark_near_grouped)
            grouped(points, self.strand, *xyz, r2, *grid)
        else:
            each = _mark_near if parallel else serial_twins.serial(_mark_near)
            each(points, self.strand, *xyz, r2, *grid, self.blocks)

    def vertices_near(
        self, points: np.ndarray, queries: np.ndarray, strands: np.ndarray, radius: float, skip: np.ndarray
    ) -> np.ndarray:
        """Sorted ids of the vertices of ``points`` (where the grid holds them), not flagged in
        ``skip``, closer than ``radius`` (at most the cell) to one of ``queries`` and of a strand
        other than that query's: the vertices whose neighbour lists hold a point at a query's
        place. They are flagged in ``skip`` too (no pass over all V vertices).

        Parameters
        ----------
        points : ndarray
            ``(V, 3)``.
        queries : ndarray
            ``(n, 3)``.
        strands : ndarray
            ``(n,)`` each query's strand.
        radius : float
            The distance, at most :attr:`cell`.
        skip : ndarray
            ``(V,)`` bool: the vertices left out; written.

        Returns
        -------
        ndarray
            int64 vertex ids.
        """
        if float(radius) > self.cell:
            raise ValueError(f"radius {radius} beyond the grid's cell {self.cell}")
        q = np.asarray(queries, np.float64).reshape(-1, 3)
        xyz = np.ascontiguousarray(q[:, 0]), np.ascontiguousarray(q[:, 1]), np.ascontiguousarray(q[:, 2])
        qs = np.ascontiguousarray(strands, np.int64)
        out = np.empty(self.vertex_count, np.int64)  # (untouched past what is found)
        grid = (float(radius) ** 2, self.inv, self.shift, self.key, self.head, self.nxt, skip, out)
        found = _vertices_near(points, self.strand, *xyz, qs, *grid)
        return np.sort(out[:found])

    def reach(
        self,
        points: np.ndarray,
        was: np.ndarray,
        changed: np.ndarray,
        best: np.ndarray,
        gap: bool,
        iterations: int,
        radius: float,
        most: int,
    ) -> np.ndarray | None:
        """Sorted ids of the vertices a change on ``changed`` (now at ``points``, before at
        ``was``) can reach in ``iterations`` list steps and, with ``gap``, through the nearest
        neighbours ``best`` ``(k, V)``: :meth:`hairtool.frozen.local.LocalClump.reach`, walked
        in one compiled call on flags kept between calls (None past ``most`` of them).

        Parameters
        ----------
        points : ndarray
            ``(V, 3)`` float32, where the grid holds them.
        was : ndarray
            ``(len(changed), 3)`` float32: the changed vertices before.
        changed : ndarray
            Sorted int64 ids.
        best : ndarray
            ``(k, V)`` int64, each iteration's nearest neighbours (−1: none).
        gap : bool
            Whether the gap correction reads the nearest neighbour's force.
        iterations : int
            List steps.
        radius : float
            The list radius, at most :attr:`cell`.
        most : int
            The largest answer wanted.

        Returns
        -------
        ndarray or None
            int64 ids.
        """
        if float(radius) > self.cell:
            raise ValueError(f"radius {radius} beyond the grid's cell {self.cell}")
        v = self.vertex_count
        if self._flags.size != v:
            self._flags = np.zeros(v, np.bool_)  # all False between calls
            self._found = np.empty(v, np.int64)
            self._known = np.empty(v, np.int64)
        new = readonly(np.asarray(points, np.float32))  # (one compiled signature, whoever holds them)
        was = readonly(np.asarray(was, np.float32))
        changed, best = readonly(np.asarray(changed, np.int64)), readonly(np.asarray(best, np.int64))
        grid = (float(radius) ** 2, self.inv, self.shift, self.key, self.head, self.nxt)
        n = _reach_walks(
            new, was, new.view(np.uint32), was.view(np.uint32), self.strand, changed, best, bool(gap),
            int(iterations), int(most), *grid, self._flags, self._found, self._known,
        )  # fmt: skip
        return None if n < 0 else np.sort(self._found[:n])

    def lists(
        self, points: np.ndarray, vids: np.ndarray, radius: float, frame: tuple, parallel: bool = True
    ) -> tuple:
        """``(flat, cnt, cap)``: the list of each vertex ``vids[n]`` (other strands within
        ``radius``, original indices) at ``flat[n·cap :][: cnt[n]]``, in the order of a full build
        whose grid is ``frame`` (:func:`list_frame`); ``radius`` must not exceed the cell.
        ``flat`` is the grid's buffer: read it before the next call.

        Parameters
        ----------
        points : ndarray
            ``(V, 3)``.
        vids : ndarray
            The vertices whose lists are wanted.
        radius : float
            The distance.
        frame : tuple
            The full build's grid (:func:`list_frame`).
        parallel : bool, default True
            Run the parallel kernel (False: its serial twin; the same lists).

        Returns
        -------
        tuple
            ``(flat, cnt, cap)``.
        """
        dense, lo, inv_cell, ny, nz, inv_q, nq = frame
        ids = np.ascontiguousarray(vids, np.int64)
        r2 = float(radius) ** 2
        kernel = _region_lists if parallel else serial_twins.serial(_region_lists)
        while True:
            cap = self.capacity
            self.prepare(ids.size)
            flat = self._flat[: ids.size * cap]
            cnt = np.empty(ids.size, np.int64)
            kernel(
                points, self.strand, ids, r2, self.inv, self.shift, self.key, self.head, self.nxt, dense, lo,
                inv_cell, ny, nz, inv_q, nq, cap, flat, cnt,
            )  # fmt: skip
            most = int(cnt.max(initial=0))
            if most < cap - 1:
                return flat, cnt, cap
            self.reserve(most)


#: Radii beyond this many cells are cut to the points' reach (:func:`_within_reach`).
_FAR_CELLS = 1024.0


def _within_reach(points: np.ndarray, queries: np.ndarray, radius: float, cell: float) -> float:
    """``radius``, or where it reaches far beyond the grid (1e6 walked empty cells for 20 s,
    1e200 overflowed its square) the same answer's radius: twice the diagonal of the box
    around the points and the queries, which every distance between them is within."""
    if radius <= _FAR_CELLS * cell:
        return radius
    with np.errstate(all="ignore"):
        lo = np.minimum(points.min(axis=0, initial=np.inf), queries.min(axis=0))
        hi = np.maximum(points.max(axis=0, initial=-np.inf), queries.max(axis=0))
        reach = 2.0 * float(np.linalg.norm((hi - lo).astype(np.float64))) + cell
    return min(radius, reach) if np.isfinite(reach) else radius


def _cells_within(q: np.ndarray, radius: float, cell: float) -> int:
    """How many grid cells the box of half-side ``radius`` around ``q`` spans (as _mark_near counts)."""
    lo = np.floor((q - radius) / cell)
    hi = np.floor((q + radius) / cell)
    return int(np.prod(np.clip(hi, -_OFF, _OFF - 1) - np.clip(lo, -_OFF, _OFF - 1) + 1))


def strands_near_reference(
    points: np.ndarray, strand: np.ndarray, queries: np.ndarray, radius: float, strand_count: int
) -> np.ndarray:
    """Numpy twin of :meth:`VertexGrid.strands_near`: every vertex against every query.

    Parameters
    ----------
    points : ndarray
        ``(V, 3)``.
    strand : ndarray
        ``(V,)`` each vertex's strand.
    queries : ndarray
        ``(n, 3)``.
    radius : float
        The distance.
    strand_count : int
        S.

    Returns
    -------
    ndarray
        ``(S,)`` bool.
    """
    p = np.asarray(points, np.float64)
    mark = np.zeros(strand_count, bool)
    for q in np.asarray(queries, np.float64).reshape(-1, 3):
        e = p - q
        d2 = e[:, 0] * e[:, 0] + e[:, 1] * e[:, 1] + e[:, 2] * e[:, 2]
        mark[strand[d2 < float(radius) ** 2]] = True
    return mark


def vertices_near_reference(
    points: np.ndarray,
    strand: np.ndarray,
    queries: np.ndarray,
    strands: np.ndarray,
    radius: float,
    skip: np.ndarray,
) -> np.ndarray:
    """Numpy twin of :meth:`VertexGrid.vertices_near`: every vertex against every query.

    Parameters
    ----------
    points : ndarray
        ``(V, 3)``.
    strand : ndarray
        ``(V,)`` each vertex's strand.
    queries : ndarray
        ``(n, 3)``.
    strands : ndarray
        ``(n,)`` each query's strand.
    radius : float
        The distance.
    skip : ndarray
        ``(V,)`` bool: the vertices left out.

    Returns
    -------
    ndarray
        Sorted int64 vertex ids.
    """
    p = np.asarray(points, np.float64)
    mark = np.zeros(p.shape[0], bool)
    for q, s in zip(np.asarray(queries, np.float64).reshape(-1, 3), np.asarray(strands), strict=True):
        e = p - q
        d2 = e[:, 0] * e[:, 0] + e[:, 1] * e[:, 1] + e[:, 2] * e[:, 2]
        mark |= (d2 < float(radius) ** 2) & (strand != s)
    return np.flatnonzero(mark & ~np.asarray(skip, bool)).astype(np.int64)


def lists_reference(
    points: np.ndarray, strand: np.ndarray, vids: np.ndarray, radius: float
) -> list[np.ndarray]:
    """Numpy twin of :meth:`VertexGrid.lists`: each vertex's list read off a full
    :class:`~hairtool.frozen.spatial.NeighbourList` build (forward run, then backward, original indices).

    Parameters
    ----------
    points : ndarray
        ``(V, 3)``.
    strand : ndarray
        ``(V,)`` each vertex's strand.
    vids : ndarray
        The vertices whose lists are wanted.
    radius : float
        The distance.

    Returns
    -------
    list of ndarray
        One list per vertex.
    """
    from hairtool.frozen.spatial import neighbour_list

    nl = neighbour_list(points, strand, radius)
    pos = np.empty(points.shape[0], np.int64)
    pos[nl.order] = np.arange(points.shape[0])
    return [nl.order[nl.of(int(pos[i]))] for i in np.asarray(vids, np.int64)]
