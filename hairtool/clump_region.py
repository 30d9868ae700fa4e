"""ClumpWithGaps again after an edit, redone only near the vertices whose input changed.

While a brush drags, a few percent of the vertices move per mouse move. After k Jacobi
iterations a vertex depends only on the vertices within k steps of the candidate graph (pairs
closer than R = h·(1 + MARGIN) at the start), so on nothing farther than k·R; and its
neighbour list keeps its order (a full build orders a list by sorted position, and the sort
keeps the relative order of the vertices that did not move). So a vertex farther than k·R
from every changed vertex, where it was and where it is, ends exactly where the last run left
it. :func:`clump_points_interactive` keeps a :class:`~hairtool.clump.ClumpRecord` of each run
(its input, output, and each iteration's points and forces) and redoes only the region of
grid cells (at least k·R wide) around the changed ones, reading the record for neighbours
outside it. The bytes are those of a full run (the tests hold it to that); where the
automatic step comes out different, too many vertices changed, or the parameters did, it
runs in full.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from hairtool.bounds import box
from hairtool.clump import (
    MARGIN,
    ClumpWorkspace,
    _first_stats,
    _lowest_of_nearest,
    _pull,
    clump_points,
    gap_lambda,
    record_key,
    step_from_stats,
)
from hairtool.freeze import CH_CLUMP, check_seed, hash_head_nb, hash_tail_u01_nb, seed_u64
from hairtool.groom import Groom

MAX_CHANGED = 0.25  # of the vertices: more changed, and the update runs in full
MAX_REGION = 0.5  # of the vertices: a larger region runs in full
MAX_SIDE = 128  # region grid cells per axis at most (the cells grow instead)
CELLS_PER_REACH = 1  # grid cells across k·R (3 follow the changes 12 % closer; their 250 offsets cost more)


@njit(cache=True, nogil=True, parallel=True)
def _changed(points, last, flags):
    """Vertices whose coordinates differ from the last input, bit for bit (−0.0 ≠ 0.0)."""
    a, b = points.view(np.uint32), last.view(np.uint32)
    for i in prange(points.shape[0]):
        flags[i] = a[i, 0] != b[i, 0] or a[i, 1] != b[i, 1] or a[i, 2] != b[i, 2]


@njit(cache=True, nogil=True, inline="always")
def _cell(x, y, z, lo, inv, dims):
    """The grid cell (clamped into the grid) of (x, y, z), as one index. Scalars and tuples only:
    an array passed to an inlined helper in a loop is reference-counted at every call."""
    cx = min(max(np.int64(np.floor((x - lo[0]) * inv)), 0), dims[0] - 1)
    cy = min(max(np.int64(np.floor((y - lo[1]) * inv)), 0), dims[1] - 1)
    cz = min(max(np.int64(np.floor((z - lo[2]) * inv)), 0), dims[2] - 1)
    return (cz * dims[1] + cy) * dims[0] + cx


@njit(cache=True, nogil=True)
def _mark_changed_cells(points, last, changed, lo, inv, dims, cells, marked):
    """The cells that hold a changed vertex, where it is or where it was, once each (into
    ``cells``, flagged in ``marked``, which is left all False). Returns how many."""
    n = 0
    for k in range(changed.size):
        i = changed[k]
        for c in (
            _cell(points[i, 0], points[i, 1], points[i, 2], lo, inv, dims),
            _cell(last[i, 0], last[i, 1], last[i, 2], lo, inv, dims),
        ):
            if not marked[c]:
                marked[c] = True
                cells[n] = c
                n += 1
    for k in range(n):
        marked[cells[k]] = False
    return n


@njit(cache=True, nogil=True, parallel=True)
def _region(points, lo3, inv, dims3, cells, offsets, near, mask):
    """``mask``: the vertices of the cells within the ``offsets`` of ``cells``. Returns how many."""
    lo = (lo3[0], lo3[1], lo3[2])
    dims = (dims3[0], dims3[1], dims3[2])
    sx, sxy = dims[0], dims[0] * dims[1]
    near[: sxy * dims[2]] = False
    for k in range(cells.size):
        c = cells[k]
        cz, cy, cx = c // sxy, (c // sx) % dims[1], c % sx
        for o in range(offsets.shape[0]):
            x, y, z = cx + offsets[o, 0], cy + offsets[o, 1], cz + offsets[o, 2]
            if 0 <= x < dims[0] and 0 <= y < dims[1] and 0 <= z < dims[2]:
                near[z * sxy + y * sx + x] = True
    n = 0
    for i in prange(points.shape[0]):
        inside = near[_cell(points[i, 0], points[i, 1], points[i, 2], lo, inv, dims)]
        mask[i] = inside
        n += inside
    return n


def region_offsets(m: int) -> np.ndarray:
    """Cell offsets (d, 3) whose cells may hold points nearer than m cells to a point of the cell
    at 0: the nearest points of cells d apart are cell·√Σ max(|d| − 1, 0)² apart."""
    d = np.arange(-m, m + 1)
    grid = np.stack(np.meshgrid(d, d, d, indexing="ij"), -1).reshape(-1, 3)
    gap = np.maximum(np.abs(grid) - 1, 0)
    return np.ascontiguousarray(grid[(gap * gap).sum(axis=1) < m * m], np.int64)


@njit(cache=True, nogil=True, parallel=True)
def _region_force(P, flat, cap, list_count, region, roots, h, stats, F, best, count, weight, ident):
    """:func:`hairtool.clump._force_kernel` for the vertices ``region`` (original indices) with
    vertex i's list at ``flat[i·cap :][: list_count[i]]``: the same pulls in the same order, so
    the same numbers. ``P``, ``F``, ``count``, ``weight`` in original order; ``best`` per
    region vertex."""
    inv_h = 1.0 / h
    for n in prange(region.size):
        i = region[n]
        acc = (0.0, 0.0, 0.0, h, np.int64(-1), False, np.int64(0), 0.0)
        px, py, pz = P[i, 0], P[i, 1], P[i, 2]
        a0, a1 = i * cap, i * cap + list_count[i]
        if not roots[i]:
            acc = _pull(P, flat, a0, a1, px, py, pz, h, inv_h, stats, acc)
        fx, fy, fz, br, bj, tie, c, wsum = acc
        if tie and bj >= 0:
            bj, _ = _lowest_of_nearest(P, flat, a0, a1, px, py, pz, br, ident, bj, bj)
        F[i, 0], F[i, 1], F[i, 2] = fx, fy, fz
        best[n] = bj
        if stats:
            count[i] = c
            weight[i] = wsum


@njit(cache=True, nogil=True, parallel=True)
def _region_gap(P, F, step, best, region, h, gap, it, seed, out):
    """:func:`hairtool.clump._gap_kernel` for the vertices ``region``, into ``out`` (the next
    iterate, or the float32 result after the last iteration)."""
    for n in prange(region.size):
        i = region[n]
        lam = 1.0
        j = best[n]
        if gap != 2 and j >= 0:
            zeta = hash_tail_u01_nb(hash_head_nb(seed, i, CH_CLUMP), it)
            lam = gap_lambda(
                P[j, 0] - P[i, 0], P[j, 1] - P[i, 1], P[j, 2] - P[i, 2],
                F[j, 0] - F[i, 0], F[j, 1] - F[i, 1], F[j, 2] - F[i, 2], step, zeta, h, gap,
            )  # fmt: skip
        for a in range(3):
            out[i, a] = P[i, a] + lam * (step * F[i, a])


@njit(cache=True, nogil=True, parallel=True)
def _store_lists(lists, list_count, rows, nbr, cnt):
    """Region lists (rows of ``nbr``) into the record's rows ``rows``."""
    for n in prange(rows.size):
        i = rows[n]
        list_count[i] = cnt[n]
        for m in range(cnt[n]):
            lists[i, m] = nbr[n, m]


@njit(cache=True, nogil=True, parallel=True)
def _set_rows(dst, src, rows):
    for n in prange(rows.size):
        for a in range(3):
            dst[rows[n], a] = src[rows[n], a]


@njit(cache=True, nogil=True, parallel=True)
def _sorted_stats(order, count, weight, sorted_count, sorted_weight):
    for k in prange(order.size):
        sorted_count[k] = count[order[k]]
        sorted_weight[k] = weight[order[k]]


def _within(points, last, changed, lo, hi, reach, sc, mask) -> int:
    """``mask``: a superset of the vertices within ``reach`` of a changed vertex, where it is or
    where it was (the cells around the ones that hold them, cells at least ``reach`` wide).
    Returns how many."""
    cell = max(reach / CELLS_PER_REACH, float((hi - lo).max()) / (MAX_SIDE - 1))
    dims = np.floor((hi - lo) / cell).astype(np.int64) + 1
    cells = int(np.prod(dims))
    if sc.near.size < cells:
        sc.near, sc.marked = np.empty(cells, np.bool_), np.zeros(cells, np.bool_)
    marked = np.empty(2 * changed.size, np.int64)
    marked = marked[: _mark_changed_cells(points, last, changed, lo, 1.0 / cell, dims, marked, sc.marked)]
    return _region(points, lo, 1.0 / cell, dims, marked, sc.offsets, sc.near, mask)


class RegionScratch:
    """Buffers of the region updates, kept between them, and what the last one did."""

    def __init__(self) -> None:
        self.flags = np.zeros(0, np.bool_)
        self.mask = np.zeros(0, np.bool_)
        self.near = np.zeros(0, np.bool_)
        self.marked = np.zeros(0, np.bool_)
        self.offsets = region_offsets(CELLS_PER_REACH)
        self.ident = np.zeros(0, np.int64)
        self.capacity = 32  # list slots per region vertex (grows to the longest list + 1)
        self.updates = 0  # region updates so far
        self.fraction = 1.0  # share of the vertices the last update redid (1: a full run)

    def sized(self, v: int) -> None:
        if self.flags.size != v:
            self.flags = np.empty(v, np.bool_)
            self.mask = np.empty(v, np.bool_)
            self.relist = np.empty(v, np.bool_)
            self.ident = np.arange(v, dtype=np.int64)


def _update_region(
    groom: Groom, h: float, iterations: int, step: float | None, gap_mode: str, seed: int, ws: ClumpWorkspace
) -> np.ndarray | None:
    """The result redone near the changed vertices, or None where only a full run will do (the
    record is then dropped, as this may have begun to rewrite it)."""
    rec = ws.recorded
    if rec is None or rec.key != record_key(groom, h, iterations, step, gap_mode, seed):
        return None
    sc = ws.region
    v = groom.vertex_count
    sc.sized(v)
    points = groom.points
    _changed(points, rec.points, sc.flags)
    changed = np.flatnonzero(sc.flags)
    if changed.size == 0:
        ws.step, ws.mean_neighbours = rec.step, rec.mean_neighbours
        sc.fraction = 0.0
        return rec.result.copy()
    if changed.size > MAX_CHANGED * v:
        return None
    radius = h * (1.0 + MARGIN)
    lo, hi = (b.astype(np.float64) for b in box(points))
    if (
        not rec.dense
        or _within(points, rec.points, changed, lo, hi, iterations * radius, sc, sc.mask) > MAX_REGION * v
    ):
        return None
    top = groom.topology
    roots = ws.roots_mask(top)
    ws.invalidate()  # the sort below replaces the kept list's order
    nl = ws.neighbours
    if not nl.sort(points, top.strand_index, roots, radius, (lo, hi)):
        return None
    ws.recorded = None  # rewritten from here on
    # New lists for the vertices within R of a changed one (the others' are those recorded).
    _within(points, rec.points, changed, lo, hi, radius, sc, sc.relist)
    positions = np.flatnonzero(sc.relist[nl.order])
    while True:
        nbr, cnt = nl.region_lists(positions, sc.capacity)
        longest = int(cnt.max()) if cnt.size else 0
        if longest < sc.capacity:
            break
        sc.capacity = (longest + 16) // 16 * 16
    if longest > rec.lists.shape[1]:
        wider = np.empty((v, sc.capacity), np.int32)
        wider[:, : rec.lists.shape[1]] = rec.lists
        rec.lists = wider
    _store_lists(rec.lists, rec.list_count, nl.order[positions], nbr, cnt)
    region = np.flatnonzero(sc.mask)  # in original order: strand by strand, near in memory
    _set_rows(rec.iterates[0], points, region)  # the first iterate: the points
    best = np.empty(region.size, np.int64)
    flat = rec.lists.reshape(-1)
    k_step = 0.0 if step is None else float(step)
    gap, seed64 = {"printed": 0, "text": 1, "off": 2}[gap_mode], seed_u64(seed)
    for it in range(iterations):
        p, f = rec.iterates[it], rec.forces[it]
        _region_force(
            p, flat, rec.lists.shape[1], rec.list_count, region, roots, h, it == 0, f, best, rec.count,
            rec.weight, sc.ident,
        )  # fmt: skip
        if it == 0:
            if step is None:  # Σg as a full run sums it, in its (sorted) order: the same bits
                sorted_count, sorted_weight = np.empty(v, np.int64), np.empty(v)
                _sorted_stats(nl.order, rec.count, rec.weight, sorted_count, sorted_weight)
                _, _, w_sum, w_count = _first_stats(sorted_count, sorted_weight, nl.skip)
                k_step = step_from_stats(h, w_sum, w_count)
                if k_step != rec.step:
                    return None  # the record's forces and counts are rewritten: dropped
            mean_nb = int(rec.count.sum()) / max(v - top.strand_count, 1)  # pairs per moving vertex
        out = rec.iterates[it + 1] if it + 1 < iterations else rec.result
        _region_gap(p, f, k_step, best, region, h, gap, it, seed64, out)
    rec.points[:] = points
    rec.mean_neighbours = mean_nb
    ws.recorded = rec
    ws.step, ws.mean_neighbours = k_step, mean_nb
    sc.updates += 1
    sc.fraction = region.size / v
    return rec.result.copy()


def clump_points_interactive(
    groom: Groom,
    radius: float,
    iterations: int = 3,
    step: float | None = None,
    gap_mode: str = "printed",
    seed: int = 0,
    workspace: ClumpWorkspace | None = None,
) -> np.ndarray:
    """:func:`~hairtool.clump.clump_points`, the same bytes, for a workspace that sees one
    edit after another: redone only near what changed since its last run when it can."""
    ws = workspace or ClumpWorkspace()
    ws.record = True
    if ws.region is None:
        ws.region = RegionScratch()
    out = None
    if iterations > 0 and groom.strand_count >= 2:
        seed = check_seed(seed)
        out = _update_region(groom, float(radius), int(iterations), step, gap_mode, seed, ws)
    if out is None:
        ws.region.fraction = 1.0
        out = clump_points(groom, radius, iterations, step, gap_mode, seed, ws)
    return out
