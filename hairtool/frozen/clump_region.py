"""ClumpWithGaps again after an edit, redone only near the vertices whose input changed.

While a brush drags, a few percent of the vertices move per mouse move. An iteration moves a
vertex by the pulls of its list (the other-strand vertices closer than h·(1 + MARGIN) at the
start) and, for the gap correction, by the force on its nearest neighbour, which comes from
that one's list: after k iterations a vertex depends only on the vertices within 2k steps of
the lists (k without the gap correction). A list keeps its order while its vertices stay: a
full build orders it by sorted position on a grid that small edits leave as it is
(:data:`hairtool.frozen.spatial.SNAP`), and the sort keeps the relative order of the vertices that
did not move. So a vertex more than 2k steps from every changed vertex, along the lists of the
last run and of this one, ends exactly where the last run left it. :func:`clump_points_interactive`
keeps a :class:`~hairtool.frozen.clump.ClumpRecord` of each run (its input, output, each iteration's
points and forces, every vertex's list), makes new lists for the changed vertices and those
whose lists held or now hold one, and redoes the vertices within 2k steps, reading the record
for their neighbours outside. A strand whose clump strength changed (the clump brush) moves
differently from the first step on while its points and lists stay: its vertices join the
changed ones as the region's seeds, without new lists. The bytes are those of a full run (the
tests hold it to that);
where the automatic step comes out different, too many vertices changed, or the parameters
did, it runs in full.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from hairtool.frozen.clump import (
    _GAP_CODE,
    MARGIN,
    ClumpWorkspace,
    _first_stats,
    clump_points,
    keep_still,
    moved_vertex,
    record_key,
    step_from_stats,
    vertex_force,
    vertex_strength,
)
from hairtool.frozen.lengths import restore_lengths
from hairtool.frozen.noise import CH_CLUMP, check_seed, hash_head_nb, hash_tail_u01_nb, seed_u64
from hairtool.groom import Groom

MAX_CHANGED = 0.25  # of the vertices: more changed, and the update runs in full
MAX_REGION = 0.5  # of the vertices: a larger region runs in full


@njit(cache=True, nogil=True, parallel=True)
def _changed(points, last, flags):
    """Vertices whose coordinates differ from the last input, bit for bit (−0.0 ≠ 0.0)."""
    a, b = points.view(np.uint32), last.view(np.uint32)
    for i in prange(points.shape[0]):
        flags[i] = a[i, 0] != b[i, 0] or a[i, 1] != b[i, 1] or a[i, 2] != b[i, 2]


@njit(cache=True, nogil=True)
def _relist(changed, nbr, cnt, lists, list_count, mark):
    """Flag in ``mark`` the changed vertices and those in their new lists (rows of ``nbr``) or
    their old ones (``lists``): the vertices whose lists may differ from the last run's.
    Returns how many."""
    n = 0
    for k in range(changed.size):
        i = changed[k]
        n += not mark[i]
        mark[i] = True
        for m in range(cnt[k]):
            n += not mark[nbr[k, m]]
            mark[nbr[k, m]] = True
        for m in range(list_count[i]):
            n += not mark[lists[i, m]]
            mark[lists[i, m]] = True
    return n


@njit(cache=True, nogil=True)
def _within_steps(k, seeds, lists, list_count, new_row, nbr_a, cnt_a, nbr_b, cnt_b, limit, mask, queue):
    """``mask`` (all False before): the vertices within k steps of ``seeds`` along the last
    run's lists (``lists``) and this run's: the same, but for the vertices with ``new_row`` r ≥ 0,
    whose new list is row r of ``nbr_a``, or r − len(nbr_a) of ``nbr_b``. Returns how many, or
    stops once there are more than ``limit``. (The visits are written out: an inlined helper
    given the arrays would count references at every call.)"""
    n = 0
    for s in seeds:
        if not mask[s]:
            mask[s] = True
            queue[n] = s
            n += 1
    na = cnt_a.size
    a = 0
    for _ in range(k):
        if n > limit:
            break
        b = n
        for q in range(a, b):
            u = queue[q]
            for m in range(list_count[u]):
                w = lists[u, m]
                if not mask[w]:
                    mask[w] = True
                    queue[n] = w
                    n += 1
            r = new_row[u]
            if r >= 0:
                row, cnt = (nbr_a[r], cnt_a[r]) if r < na else (nbr_b[r - na], cnt_b[r - na])
                for m in range(cnt):
                    w = row[m]
                    if not mask[w]:
                        mask[w] = True
                        queue[n] = w
                        n += 1
        a = b
    return n


@njit(cache=True, nogil=True, parallel=True)
def _region_force(P, flat, cap, list_count, region, roots, h, stats, F, best, count, weight, ident):
    """:func:`hairtool.frozen.clump._force_kernel` for the vertices ``region`` (original indices) with
    vertex i's list at ``flat[i·cap :][: list_count[i]]``: the same pulls in the same order, so
    the same numbers. ``P``, ``F``, ``count``, ``weight`` in original order; ``best`` per
    region vertex."""
    inv_h = 1.0 / h
    for n in prange(region.size):
        i = region[n]
        a0, a1 = i * cap, i * cap + list_count[i]
        fx, fy, fz, best[n], c, wsum = vertex_force(
            P, flat, a0, a1, flat, a1, a1, P[i, 0], P[i, 1], P[i, 2], roots[i], h, inv_h, stats, ident
        )
        F[i, 0], F[i, 1], F[i, 2] = fx, fy, fz
        if stats:
            count[i] = c
            weight[i] = wsum


@njit(cache=True, nogil=True, parallel=True)
def _region_gap(P, F, S, step, best, region, h, gap, it, seed, out):
    """:func:`hairtool.frozen.clump._gap_kernel` for the vertices ``region``, into ``out`` (the next
    iterate, or the float32 result after the last iteration); ``S`` clump strengths, original order."""
    for n in prange(region.size):
        i = region[n]
        j = best[n]
        zeta = 0.0
        if gap != 2 and j >= 0:
            zeta = hash_tail_u01_nb(hash_head_nb(seed, i, CH_CLUMP), it)
        moved_vertex(P, F, S, step, i, j, zeta, h, gap, out, i)


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


class RegionScratch:
    """Buffers of the region updates, kept between them, and what the last one did."""

    def __init__(self) -> None:
        self.flags = np.zeros(0, np.bool_)
        self.mask = np.zeros(0, np.bool_)
        self.ident = np.zeros(0, np.int64)
        self.capacity = 32  # list slots per region vertex (grows to the longest list + 1)
        self.updates = 0  # region updates so far
        self.too_many = np.inf  # changed vertices of a try whose region was too large (grows)
        self.skipping = False  # the last update did not try
        self.fraction = 1.0  # share of the vertices the last update redid (1: a full run)
        self.region = np.zeros(0, np.int64)  # the vertices the last region update redid
        self.kept: np.ndarray | None = None  # the last result with lengths kept (keep_lengths)

    def sized(self, v: int) -> None:
        if self.flags.size != v:
            self.flags = np.empty(v, np.bool_)
            self.mask = np.zeros(v, np.bool_)
            self.relist = np.zeros(v, np.bool_)
            self.new_row = np.full(v, -1, np.int64)
            self.queue = np.empty(v, np.int64)
            self.ident = np.arange(v, dtype=np.int64)


def _update_region(
    groom: Groom,
    h: float,
    iterations: int,
    step: float | None,
    gap_mode: str,
    seed: int,
    ws: ClumpWorkspace,
    sv: np.ndarray,
) -> np.ndarray | None:
    """The result redone near the changed vertices, or None where only a full run will do (the
    record is then marked not valid, as this may have begun to rewrite it)."""
    rec = ws.recorded
    if rec is None or not rec.valid or rec.key != record_key(groom, h, iterations, step, gap_mode, seed):
        return None
    sc = ws.region
    v = groom.vertex_count
    sc.sized(v)
    points = groom.points
    _changed(points, rec.points, sc.flags)
    changed = np.flatnonzero(sc.flags)
    restrength = np.flatnonzero(sv != rec.strength)  # moved or not, they step differently
    seeds = np.union1d(changed, restrength) if restrength.size else changed
    if seeds.size == 0:
        ws.step, ws.mean_neighbours = rec.step, rec.mean_neighbours
        sc.fraction = 0.0
        sc.region = changed
        return rec.result.copy()
    if seeds.size > MAX_CHANGED * v or not rec.dense:
        sc.skipping = seeds.size > MAX_CHANGED * v  # (a record would not serve the next move either)
        return None
    if seeds.size >= 0.5 * sc.too_many:  # about as many as made the last try too large:
        sc.too_many *= 1.25  # try again in a few moves
        sc.skipping = True  # and meanwhile, run in full without recording
        return None
    if not rec.lists_ready:  # the lists of the recorded full run, still in the workspace
        if not ws.holds_list_of(rec.points):
            return None
        while ws.neighbours.padded_lists(rec.lists, rec.list_count) > rec.lists.shape[1]:
            rec.lists = np.empty((v, 2 * rec.lists.shape[1]), np.int32)
        rec.lists_ready = True
    top = groom.topology
    roots = ws.roots_mask(top)
    nl = ws.neighbours
    if changed.size:
        ws.invalidate()  # the sort below replaces the kept list's order
        radius = h * (1.0 + MARGIN)
        sorted_ = nl.sort(points, top.strand_index, roots, radius)
        if not sorted_ or (tuple(nl.lo), tuple(nl.dims)) != rec.frame:
            return None  # another grid: every list may come in another order
        # New lists: the changed vertices', then those of the vertices their lists held or hold.
        pos_c = np.flatnonzero(sc.flags[nl.order])
        ids_c = nl.order[pos_c]
        nbr_c, cnt_c = _lists(nl, pos_c, sc)
        sc.relist[:] = False
        if _relist(changed, nbr_c, cnt_c, rec.lists, rec.list_count, sc.relist) > MAX_REGION * v:
            sc.too_many = seeds.size
            return None  # the region holds these and more
        sc.relist[changed] = False
        pos_r = np.flatnonzero(sc.relist[nl.order])
        ids_r = nl.order[pos_r]
        nbr_r, cnt_r = _lists(nl, pos_r, sc)
    else:  # strengths alone: the points, hence the lists and the step, are the last run's
        ids_c = ids_r = np.zeros(0, np.int64)
        nbr_c = nbr_r = np.zeros((0, sc.capacity), np.int32)
        cnt_c = cnt_r = np.zeros(0, np.int64)
    # The region: within 2k steps of a changed vertex (k without gaps), along both runs' lists.
    sc.new_row[ids_c] = np.arange(ids_c.size)
    sc.new_row[ids_r] = np.arange(ids_c.size, ids_c.size + ids_r.size)
    sc.mask[:] = False
    n = _within_steps(
        iterations * (1 if gap_mode == "off" else 2), seeds, rec.lists, rec.list_count, sc.new_row,
        nbr_c, cnt_c, nbr_r, cnt_r, int(MAX_REGION * v), sc.mask, sc.queue,
    )  # fmt: skip
    sc.new_row[ids_c] = -1
    sc.new_row[ids_r] = -1
    if n > MAX_REGION * v:
        sc.too_many = seeds.size
        return None
    rec.valid = False  # rewritten from here on
    longest = max(int(cnt_c.max(initial=0)), int(cnt_r.max(initial=0)))
    if longest > rec.lists.shape[1]:
        wider = np.empty((v, sc.capacity), np.int32)
        wider[:, : rec.lists.shape[1]] = rec.lists
        rec.lists = wider
    _store_lists(rec.lists, rec.list_count, ids_c, nbr_c, cnt_c)
    _store_lists(rec.lists, rec.list_count, ids_r, nbr_r, cnt_r)
    region = np.flatnonzero(sc.mask)  # in original order: strand by strand, near in memory
    _set_rows(rec.iterates[0], points, region)  # the first iterate: the points
    best = np.empty(region.size, np.int64)
    flat = rec.lists.reshape(-1)
    k_step = 0.0 if step is None else float(step)
    gap, seed64 = _GAP_CODE[gap_mode], seed_u64(seed)
    for it in range(iterations):
        p, f = rec.iterates[it], rec.forces[it]
        _region_force(
            p, flat, rec.lists.shape[1], rec.list_count, region, roots, h, it == 0, f, best, rec.count,
            rec.weight, sc.ident,
        )  # fmt: skip
        if it == 0:
            if step is None and changed.size == 0:
                k_step = rec.step  # Σg depends on the points alone: the recorded run's step
            elif step is None:  # Σg as a full run sums it, in its (sorted) order: the same bits
                sorted_count, sorted_weight = np.empty(v, np.int64), np.empty(v)
                _sorted_stats(nl.order, rec.count, rec.weight, sorted_count, sorted_weight)
                _, _, w_sum, w_count = _first_stats(sorted_count, sorted_weight, nl.skip)
                k_step = step_from_stats(h, w_sum, w_count)
                if k_step != rec.step:
                    return None  # the record's forces and counts are rewritten: dropped
            mean_nb = int(rec.count.sum()) / max(v - top.strand_count, 1)  # pairs per moving vertex
        out = rec.iterates[it + 1] if it + 1 < iterations else rec.result
        _region_gap(p, f, sv, k_step, best, region, h, gap, it, seed64, out)
    sc.too_many = np.inf
    rec.points[:] = points
    rec.strength[:] = sv
    rec.mean_neighbours = mean_nb
    rec.valid = True
    ws.step, ws.mean_neighbours = k_step, mean_nb
    sc.updates += 1
    sc.fraction = region.size / v
    sc.region = region
    return rec.result.copy()


def _lists(nl, positions: np.ndarray, sc: RegionScratch) -> tuple[np.ndarray, np.ndarray]:
    """:meth:`~hairtool.frozen.spatial.NeighbourList.region_lists`, wide enough (the width adapts)."""
    while True:
        nbr, cnt = nl.region_lists(positions, sc.capacity)
        if cnt.size == 0 or int(cnt.max()) < sc.capacity:
            return nbr, cnt
        sc.capacity = (int(cnt.max()) + 16) // 16 * 16


def clump_points_interactive(
    groom: Groom,
    radius: float,
    iterations: int = 3,
    step: float | None = None,
    gap_mode: str = "printed",
    seed: int = 0,
    workspace: ClumpWorkspace | None = None,
    keep_lengths: bool = False,
    strength: np.ndarray | None = None,
) -> np.ndarray:
    """:func:`~hairtool.frozen.clump.clump_points`, the same bytes, for a workspace that sees one
    edit after another: redone only near what changed (points or clump ``strength``) since its
    last run when it can. With ``keep_lengths`` the length pass follows the iterations' result
    in either path (the record keeps the result before it)."""
    ws = workspace or ClumpWorkspace()
    if ws.region is None:
        ws.region = RegionScratch()
    ws.region.skipping = False
    out = None
    sv = vertex_strength(groom, strength)
    if iterations > 0 and groom.strand_count >= 2:
        seed = check_seed(seed)
        out = _update_region(groom, float(radius), int(iterations), step, gap_mode, seed, ws, sv)
    if out is None:
        ws.region.fraction = 1.0
        ws.record = not ws.region.skipping
        out = clump_points(groom, radius, iterations, step, gap_mode, seed, ws, False, strength)
    sc = ws.region
    if not (keep_lengths and iterations > 0 and groom.strand_count >= 2):
        sc.kept = None
        return out
    top = groom.topology
    if sc.fraction < 1.0 and sc.kept is not None and sc.kept.shape == out.shape:
        # Outside the region the input and the result are the last run's: so is their pass.
        restore_lengths(groom.points, out, top, np.unique(top.strand_index[sc.region]), sc.kept)
    else:
        sc.kept = restore_lengths(groom.points, out, top)
    keep_still(groom.points, sv, sc.kept)
    return sc.kept.copy()
