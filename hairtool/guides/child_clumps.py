"""ClumpWithGaps among render-hair children, one guide clump at a time.

A child belongs to the clump of its nearest guide (the binding's first guide). Children adhere
(Kim 2026, eqs. 14–19, :mod:`hairtool.frozen.clump`) to the other children of their own clump
only, the way render hair clumps to its guides, so each clump is a small run of its own: a grid
over that clump's vertices alone (not over every child vertex), k Jacobi iterations with the
gap correction, the lengths kept, all in cache. Clumps run in parallel and nothing is shared
between them, so the bytes do not depend on the thread count, and a release after a stroke
redoes only the clumps whose children follow a moved guide (:class:`ChildClumps`).

Each clump's run is the whole-groom run of :func:`hairtool.frozen.clump.clump_points` on that
clump's children alone: its own automatic step (from its own mean Σg), ζ from a seed of its own
(:func:`clump_seeds`, drawn from the seed and the guide, so clumps do not repeat each other's
noise), roots fixed. The forces are summed pair by pair here rather than list by list (float64
sums in another order), so the contract is that run to within rounding: the tests hold the two
to 1e-6 of the clump radius (on Sintel's children they agree byte for byte).
:func:`clump_children_reference` is that run, clump by clump, with the numpy twin
:func:`~hairtool.frozen.clump.clump_reference` or the numba path: the oracle.

How far this is from one run over all children at once (what the studio did before): pairs of
children of different guides no longer pull. On Sintel's 30,000 children about half of the
within-h neighbours of a vertex are another guide's children, so clumps part along the lines
between guides, as clumps do around their guides in production render hair.
"""

from __future__ import annotations

import numba
import numpy as np
from numba import njit, prange

from hairtool.frozen.clump import (
    MARGIN,
    check_clump_params,
    clump_points,
    clump_reference,
    gap_lambda,
    step_from_stats,
)
from hairtool.frozen.lengths import restore_lengths
from hairtool.frozen.noise import CH_CLUMP, EPS, check_seed, hash_head_nb, hash_tail_u01_nb, hash_u01
from hairtool.groom import Groom
from hairtool.kernel_arrays import readonly

CH_CHILD_CLUMP = 6  # noise channel of the clumps' seeds (hairtool.frozen.noise uses 1-5)
_GAP_CODE = {"printed": 0, "text": 1, "off": 2}
_CELLS_PER_VERTEX = 4  # a clump's grid has at most this many cells per vertex (coarser if needed)


def clump_of_children(guide_ids: np.ndarray, guide_count: int) -> tuple[np.ndarray, np.ndarray]:
    """Children grouped by nearest guide: ``start`` (G+1,) into ``children`` (N,), each clump's
    children in increasing order.

    Parameters
    ----------
    guide_ids : ndarray
        ``(N,)`` each child's nearest guide.
    guide_count : int
        G.

    Returns
    -------
    tuple of (ndarray, ndarray)
        ``start`` and ``children``, int64.
    """
    nearest = np.asarray(guide_ids)[:, 0]
    children = np.argsort(nearest, kind="stable").astype(np.int64)
    start = np.zeros(guide_count + 1, np.int64)
    np.cumsum(np.bincount(nearest, minlength=guide_count), out=start[1:])
    return start, children


def clump_seeds(seed: int, guide_count: int) -> np.ndarray:
    """``(G,)`` the seed of each guide's clump (whole numbers below 2**53): ζ of different
    clumps is drawn independently.

    Parameters
    ----------
    seed : int
        The user's seed.
    guide_count : int
        G.

    Returns
    -------
    ndarray
        ``(G,)`` int64.
    """
    u = hash_u01(seed, np.arange(guide_count), 0, CH_CHILD_CLUMP)
    return (u * 2.0**53).astype(np.int64)


@njit(cache=True, nogil=True)
def _local(points, offsets, kids):
    """A clump's vertices, its children one after another: float64 points, each vertex's child
    (0, 1, …), root flag and global vertex."""
    n = 0
    for c in kids:
        n += offsets[c + 1] - offsets[c]
    P = np.empty((n, 3))
    strand = np.empty(n, np.int64)
    root = np.zeros(n, np.bool_)
    vid = np.empty(n, np.int64)
    m = 0
    for s in range(kids.size):
        a, b = offsets[kids[s]], offsets[kids[s] + 1]
        for v in range(a, b):
            for ax in range(3):
                P[m, ax] = points[v, ax]
            strand[m] = s
            root[m] = v == a
            vid[m] = v
            m += 1
    return P, strand, root, vid


@njit(cache=True, nogil=True)
def _pairs(P, strand, radius):
    """Every pair (i, j) of vertices of different children closer than ``radius`` (each once,
    i < j). Cells ``radius`` wide (wider if the clump's box holds too many rows): the vertices
    sorted by row (y, z), within a row by cell along x, two counting sorts; each vertex then
    tests its own row's cells x−1 … x+1 after it and those of the four rows ahead, (y+1, z) and
    (y−1 … y+1, z+1), through pointers that only move forward while x grows along a row."""
    n = P.shape[0]
    lo = np.empty(3)
    hi = np.empty(3)
    for ax in range(3):
        lo[ax] = P[:, ax].min()
        hi[ax] = P[:, ax].max()
    cell = radius
    while True:
        ny = np.int64((hi[1] - lo[1]) / cell) + 1
        nz = np.int64((hi[2] - lo[2]) / cell) + 1
        if ny * nz <= _CELLS_PER_VERTEX * n + 64:
            break
        cell *= 1.25
    nx = np.int64((hi[0] - lo[0]) / cell) + 1
    inv = 1.0 / cell
    rows = ny * nz
    cx = np.empty(n, np.int64)
    row = np.empty(n, np.int64)
    for i in range(n):
        cx[i] = min(np.int64((P[i, 0] - lo[0]) * inv), nx - 1)
        y = min(np.int64((P[i, 1] - lo[1]) * inv), ny - 1)
        z = min(np.int64((P[i, 2] - lo[2]) * inv), nz - 1)
        row[i] = z * ny + y
    # Counting sort by cell along x, then (stable) by row.
    count = np.zeros(nx + 1, np.int64)
    for i in range(n):
        count[cx[i] + 1] += 1
    for k in range(nx):
        count[k + 1] += count[k]
    by_x = np.empty(n, np.int64)
    for i in range(n):
        by_x[count[cx[i]]] = i
        count[cx[i]] += 1
    start = np.zeros(rows + 1, np.int64)
    for i in range(n):
        start[row[i] + 1] += 1
    for k in range(rows):
        start[k + 1] += start[k]
    fill = start[:-1].copy()
    order = np.empty(n, np.int64)
    sx = np.empty(n, np.int64)  # the sorted vertices' cells along x, points and children
    sp = np.empty((n, 3))
    ss = np.empty(n, np.int64)
    for k in range(n):
        i = by_x[k]
        q = fill[row[i]]
        order[q] = i
        sx[q] = cx[i]
        sp[q, 0], sp[q, 1], sp[q, 2] = P[i, 0], P[i, 1], P[i, 2]
        ss[q] = strand[i]
        fill[row[i]] += 1
    r2 = radius * radius
    cap = 8 * n + 16
    pa = np.empty(cap, np.int32)
    pb = np.empty(cap, np.int32)
    m = 0
    first = np.zeros(5, np.int64)  # per row ahead: the first entry at cell x−1 or beyond …
    last = np.zeros(5, np.int64)  # … and past the last at cell x+1
    end = np.zeros(5, np.int64)
    ahead = np.array([[0, 0], [1, 0], [-1, 1], [0, 1], [1, 1]], np.int64)  # rows (dy, dz)
    current = -1
    for p in range(n):
        i = order[p]
        r = row[i]
        x = sx[p]
        px, py, pz, si = sp[p, 0], sp[p, 1], sp[p, 2], ss[p]
        if r != current:  # a new row: the pointers of the rows ahead afresh
            current = r
            y, z = r % ny, r // ny
            for d in range(5):
                dy = ahead[d, 0]
                dz = ahead[d, 1]
                first[d] = last[d] = end[d] = 0
                if 0 <= y + dy < ny and z + dz < nz:
                    rr = (z + dz) * ny + y + dy
                    first[d] = last[d] = start[rr]
                    end[d] = start[rr + 1]
        room = 0
        for d in range(5):
            while first[d] < end[d] and sx[first[d]] < x - 1:
                first[d] += 1
            if last[d] < first[d]:
                last[d] = first[d]
            while last[d] < end[d] and sx[last[d]] <= x + 1:
                last[d] += 1
            room += last[d] - first[d]
        if m + room >= cap:  # room for every candidate: the writes below need no test
            cap = 2 * (m + room) + 16
            na = np.empty(cap, np.int32)
            nb = np.empty(cap, np.int32)
            na[:m] = pa[:m]
            nb[:m] = pb[:m]
            pa, pb = na, nb
        for d in range(5):
            q0 = max(first[d], p + 1) if d == 0 else first[d]
            # Branch-free (the outcome is unpredictable): always write, count the hits.
            for q in range(q0, last[d]):
                ex = sp[q, 0] - px
                ey = sp[q, 1] - py
                ez = sp[q, 2] - pz
                j = order[q]
                pa[m] = min(i, j)
                pb[m] = max(i, j)
                m += np.int64((ex * ex + ey * ey + ez * ez < r2) & (ss[q] != si))
    return pa[:m], pb[:m]


@njit(cache=True, nogil=True, inline="always")
def _nearer(r, j, br, bj, i):
    """Whether j at r beats vertex i's nearest so far (within h; exact ties: the lower index)."""
    return r < br[i] or (r == br[i] and bj[i] >= 0 and j < bj[i])


@njit(cache=True, nogil=True)
def _clump_run(P, root, pa, pb, h, iterations, step, gap, seed):
    """The k iterations on one clump (as :func:`hairtool.frozen.clump.clump_points` defines
    them); ``step`` < 0: automatic. Returns (the points, within-h pairs of its moving vertices,
    moving vertices, the step used)."""
    n = P.shape[0]
    inv_h = 1.0 / h
    f = np.empty((n, 3))
    br = np.empty(n)
    bj = np.empty(n, np.int64)
    count = np.zeros(n, np.int64)
    weight = np.zeros(n)
    heads = np.empty(n, np.uint64)
    for i in range(n):
        heads[i] = hash_head_nb(seed, i, CH_CLUMP)
    Pn = np.empty_like(P)
    k_step = step
    pairs = 0
    moving = 0
    for it in range(iterations):
        f[:] = 0.0
        br[:] = h
        bj[:] = -1
        for m in range(pa.size):
            a, b = pa[m], pb[m]
            ex = P[b, 0] - P[a, 0]
            ey = P[b, 1] - P[a, 1]
            ez = P[b, 2] - P[a, 2]
            r = np.sqrt(ex * ex + ey * ey + ez * ez)
            t = max(1.0 - r * inv_h, 0.0)
            g = t * t  # (14)
            s = g / (r + EPS)  # (15); the pair's pull on b is exactly the negation
            if not root[a]:
                f[a, 0] += s * ex
                f[a, 1] += s * ey
                f[a, 2] += s * ez
                if _nearer(r, b, br, bj, a):
                    br[a], bj[a] = r, b
                if it == 0:
                    count[a] += np.int64(r < h)
                    weight[a] += g
            if not root[b]:
                f[b, 0] -= s * ex
                f[b, 1] -= s * ey
                f[b, 2] -= s * ez
                if _nearer(r, a, br, bj, b):
                    br[b], bj[b] = r, a
                if it == 0:
                    count[b] += np.int64(r < h)
                    weight[b] += g
        if it == 0:
            w_sum = 0.0
            w_count = 0
            for i in range(n):
                pairs += count[i]
                moving += np.int64(not root[i])
                if count[i] > 0:
                    w_sum += weight[i]
                    w_count += 1
            if step < 0.0:
                k_step = step_from_stats(h, w_sum, w_count)
        for i in range(n):
            j = bj[i]
            lam = 1.0
            if gap != 2 and j >= 0:
                zeta = hash_tail_u01_nb(heads[i], it)
                lam = gap_lambda(
                    P[j, 0] - P[i, 0], P[j, 1] - P[i, 1], P[j, 2] - P[i, 2],
                    f[j, 0] - f[i, 0], f[j, 1] - f[i, 1], f[j, 2] - f[i, 2],
                    k_step, zeta, h, gap,
                )  # fmt: skip
            for ax in range(3):
                Pn[i, ax] = P[i, ax] + lam * (k_step * f[i, ax])  # (16), (19)
        P, Pn = Pn, P
    return P, pairs, moving, k_step


@njit(cache=True, nogil=True)
def _write(P, vid, out):
    """A clump's result (float32) to its children's rows of ``out``."""
    for i in range(vid.size):
        for ax in range(3):
            out[vid[i], ax] = P[i, ax]


@njit(cache=True, nogil=True)
def _one_clump(points, offsets, kids, seed, h, iterations, step, gap, raw, out, stats, g):
    """Clump g's run: its children's rows of ``raw`` (clumped, before the length pass); a clump
    of one child, which has nothing to clump with, is written as built to ``out`` too.
    ``stats[g]`` = (within-h pairs, moving vertices, step) of its run."""
    P, strand, root, vid = _local(points, offsets, kids)
    stats[g, 0] = 0.0
    stats[g, 1] = 0.0
    stats[g, 2] = 0.0
    if kids.size < 2:
        _write(P, vid, raw)
        _write(P, vid, out)
        return
    pa, pb = _pairs(P, strand, h * (1.0 + MARGIN))
    Q, pairs, moving, used = _clump_run(P, root, pa, pb, h, iterations, step, gap, seed)
    _write(Q, vid, raw)
    stats[g, 0] = pairs
    stats[g, 1] = moving
    stats[g, 2] = used


@njit(cache=True, nogil=True, parallel=True)
def _clumps_kernel(
    points, offsets, start, children, seeds, jobs, job_start, h, iterations, step, gap, raw, out, stats
):
    """The clumps ``jobs[job_start[j]:job_start[j + 1]]`` of each job j (one job a thread, see
    :func:`clump_jobs`), each by :func:`_one_clump`."""
    for j in prange(job_start.size - 1):
        for k in range(job_start[j], job_start[j + 1]):
            g = jobs[k]
            kids = children[start[g] : start[g + 1]]
            _one_clump(points, offsets, kids, seeds[g], h, iterations, step, gap, raw, out, stats, g)


def clump_jobs(work: np.ndarray, clumps: np.ndarray, n: int) -> tuple[np.ndarray, np.ndarray]:
    """``clumps`` dealt into ``n`` jobs of about equal ``work`` (per clump; heaviest first, each to
    the lightest job so far), as a CSR ``(clump ids, job starts)``. prange hands each thread one
    block of consecutive iterations: over all clumps, with only a stroke's to redo (neighbours,
    so next to each other in the guides' order) one thread had nearly all of them. Each clump's
    bytes are its own whatever job runs it.

    Parameters
    ----------
    work : ndarray
        ``(G,)`` each clump's work.
    clumps : ndarray
        The clumps to run.
    n : int
        Jobs.

    Returns
    -------
    tuple of (ndarray, ndarray)
        The clump ids by job and the jobs' starts.
    """
    clumps = np.asarray(clumps, np.int64)
    n = max(1, min(int(n), clumps.size))
    job = np.zeros(clumps.size, np.int64)
    load = np.zeros(n)
    for k in np.argsort(-work[clumps], kind="stable"):
        j = int(np.argmin(load))
        job[k] = j
        load[j] += work[clumps[k]] + 64.0  # a clump's fixed cost: its grid and arrays
    order = np.lexsort((clumps, job))
    return clumps[order], np.searchsorted(job[order], np.arange(n + 1)).astype(np.int64)


class ChildClumps:
    """ClumpWithGaps among the children of each guide, kept between runs so that a run after a
    stroke redoes only the clumps it names. ``guide_ids`` (N, k) as the binding holds them (the
    first, nearest guide names a child's clump); ``radius`` h, ``iterations``, ``step`` (None:
    each clump's automatic one), ``gap_mode`` and ``seed`` as for
    :func:`~hairtool.frozen.clump.clump_points`; ``keep_lengths``: each child's segments back to
    their lengths afterwards (:func:`~hairtool.frozen.lengths.restore_lengths`)."""

    def __init__(
        self,
        guide_ids: np.ndarray,
        guide_count: int,
        radius: float,
        iterations: int = 3,
        step: float | None = None,
        gap_mode: str = "printed",
        seed: int = 0,
        keep_lengths: bool = True,
    ) -> None:
        """ClumpWithGaps among the children of each guide, ready to run on their points.

        Parameters
        ----------
        guide_ids : ndarray
            ``(N,)`` each child's nearest guide.
        guide_count : int
            G.
        radius : float
            The clump radius h.
        iterations : int, default 3
            Clump passes k.
        step : float, optional
            The pass's step (None: from the radius).
        gap_mode : str, default "printed"
            ClumpWithGaps' gap rule.
        seed : int, default 0
            The clumps' seed.
        keep_lengths : bool, default True
            Give each segment back its length after clumping.
        """
        check_clump_params(radius, iterations, step, gap_mode)
        self.guide_ids = np.asarray(guide_ids, np.int64)
        self.guide_count = int(guide_count)
        self.radius, self.iterations, self.step = float(radius), int(iterations), step
        self.gap_mode, self.keep_lengths = gap_mode, bool(keep_lengths)
        self.seeds = clump_seeds(check_seed(seed), self.guide_count).astype(np.uint64)
        self.start, self.children = clump_of_children(self.guide_ids, self.guide_count)
        sizes = np.diff(self.start)
        self._work: np.ndarray | None = None  # per clump: its vertices (its run's cost, about)
        self._clumped_kids = self.children[np.repeat(sizes >= 2, sizes)]  # those the length pass redoes
        self.stats = np.zeros((self.guide_count, 3))  # per clump: within-h pairs, moving vertices, step
        self.raw: np.ndarray | None = None
        self.out: np.ndarray | None = None
        self.clumps_run = 0  # in the last run

    @property
    def mean_neighbours(self) -> float:
        """Children's vertices within h per moving vertex (first iteration), over all clumps."""
        return float(self.stats[:, 0].sum() / max(self.stats[:, 1].sum(), 1.0))

    def redo_for(self, moved_guides: np.ndarray) -> np.ndarray:
        """``(G,)`` the clumps holding a child that follows one of ``moved_guides`` (G flags).

        Parameters
        ----------
        moved_guides : ndarray
            ``(G,)`` bool.

        Returns
        -------
        ndarray
            ``(G,)`` bool.
        """
        follows = np.asarray(moved_guides, np.bool_)[self.guide_ids].any(axis=1)
        redo = np.zeros(self.guide_count, np.bool_)
        redo[self.guide_ids[follows, 0]] = True
        return redo

    def run(self, points: np.ndarray, topology, redo: np.ndarray | None = None) -> np.ndarray:
        """float32 ``(V, 3)``: the children at ``points`` clumped, in an array this object keeps
        and the next run rewrites (copy it to keep it). ``redo``: per guide, whether its clump is
        run again; the others keep what the last run wrote (None, or a first run: all).

        Parameters
        ----------
        points : ndarray
            ``(V, 3)`` the children's points.
        topology : Topology
            Their strands.
        redo : ndarray, optional
            ``(G,)`` bool, the clumps to run again (None: all).

        Returns
        -------
        ndarray
            ``(V, 3)`` float32, this object's buffer.
        """
        v = topology.vertex_count
        if self._work is None:
            total = np.zeros(self.children.size + 1)
            np.cumsum(topology.counts[self.children], out=total[1:])
            self._work = total[self.start[1:]] - total[self.start[:-1]]
        if self.out is None or self.out.shape != (v, 3):
            self.out = np.empty((v, 3), np.float32)
            self.raw = np.empty((v, 3), np.float32) if self.keep_lengths else self.out
            redo = None
        if redo is None:
            flags = np.zeros(0, np.bool_)
            self.clumps_run = self.guide_count
        else:
            flags = np.ascontiguousarray(redo, np.bool_)
            self.clumps_run = int(np.count_nonzero(flags))
            if self.clumps_run == 0:
                return self.out
        if self.iterations == 0:
            self.out[:] = points
            return self.out
        todo = np.flatnonzero(flags) if flags.size else np.arange(self.guide_count)
        todo = todo[np.diff(self.start)[todo] > 0]
        jobs, job_start = clump_jobs(self._work, todo, numba.get_num_threads())
        _clumps_kernel(
            readonly(points), readonly(topology.offsets), self.start, self.children, self.seeds, jobs,
            job_start, self.radius, self.iterations, -1.0 if self.step is None else float(self.step),
            _GAP_CODE[self.gap_mode], self.raw, self.out, self.stats,
        )  # fmt: skip
        if self.keep_lengths:
            kids = self._clumped_kids
            if flags.size:
                kids = kids[flags[self.guide_ids[kids, 0]]]
            restore_lengths(points, self.raw, topology, kids, out=self.out)
        return self.out


def clump_children(
    children: Groom,
    guide_ids: np.ndarray,
    guide_count: int,
    radius: float,
    iterations: int = 3,
    step: float | None = None,
    gap_mode: str = "printed",
    seed: int = 0,
    keep_lengths: bool = True,
) -> np.ndarray:
    """float32 ``(V, 3)``: ClumpWithGaps among the children of each guide, once (see
    :class:`ChildClumps`).

    Parameters
    ----------
    children : Groom
        The children.
    guide_ids : ndarray
        ``(N,)`` each child's nearest guide.
    guide_count : int
        G.
    radius, iterations, step, gap_mode, seed, keep_lengths
        As :class:`ChildClumps` takes them.

    Returns
    -------
    ndarray
        ``(V, 3)`` float32.
    """
    run = ChildClumps(guide_ids, guide_count, radius, iterations, step, gap_mode, seed, keep_lengths)
    return run.run(children.points, children.topology)


def clump_children_reference(
    children: Groom,
    guide_ids: np.ndarray,
    guide_count: int,
    radius: float,
    iterations: int = 3,
    step: float | None = None,
    gap_mode: str = "printed",
    seed: int = 0,
    keep_lengths: bool = True,
    numpy: bool = True,
) -> np.ndarray:
    """The oracle of :func:`clump_children`: the whole-groom ClumpWithGaps run on each clump's
    children alone (``numpy``: its numpy twin :func:`~hairtool.frozen.clump.clump_reference`,
    else the studio's numba path :func:`~hairtool.frozen.clump.clump_points`).

    Parameters
    ----------
    children, guide_ids, guide_count, radius, iterations, step, gap_mode, seed, keep_lengths
        As :func:`clump_children` takes them.
    numpy : bool, default True
        Use the whole-groom clump's numpy twin (else its numba path).

    Returns
    -------
    ndarray
        ``(V, 3)`` float32.
    """
    start, kids = clump_of_children(guide_ids, guide_count)
    seeds = clump_seeds(seed, guide_count)
    out = children.points.astype(np.float32)
    for g in range(guide_count):
        ids = kids[start[g] : start[g + 1]]
        if ids.size == 0:
            continue
        sub = children.subset(ids)
        args = (sub, radius, iterations, step, gap_mode, int(seeds[g]))
        if numpy:
            pts = clump_reference(*args, keep_lengths=keep_lengths).points
        else:
            pts = clump_points(*args, keep_lengths=keep_lengths)
        rows = np.concatenate([np.arange(children.offsets[c], children.offsets[c + 1]) for c in ids])
        out[rows] = pts
    return out
