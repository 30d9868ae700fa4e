"""Brush-local ClumpWithGaps: a move redoes the vertices whose clumping it can change, and no others.

While a brush drags, a mouse move changes a few strands. :class:`LocalClump` keeps what the last
run left (a :class:`~hairtool.frozen.clump.ClumpRecord`: each iteration's points, forces and
nearest neighbours, every vertex's input and output) and a
:class:`~hairtool.frozen.vertex_grid.VertexGrid` of the input kept across moves. A move changes
the input of some vertices (their points, or their clump strength). In a full run that change
travels along the neighbour lists (other strands within the list radius h·(1 + MARGIN)): a
vertex's lists change where a changed vertex comes or goes within reach; its force reads the
points of its list; its next point reads its force and the force and point of its nearest
neighbour (the gap correction). So each iteration carries a change one list step (counted on the
lists before and after the move), and on to the vertices whose nearest neighbour is one of
those: a vertex with no changed point in its list has the last run's nearest neighbour, which
the record keeps (:meth:`LocalClump.reach`). The vertices so reached in k iterations are the
move's: they are clumped again from the new input; every other vertex is where the last run had
it at each iteration, and is read there.

So a move gives a full run's bytes, every vertex of them: each redone vertex's list comes in a
full build's order (:mod:`hairtool.frozen.vertex_grid`) and the same kernels sum it, and every
vertex outside the reach is, in a full run, where the last run had it. The record then holds a
full run of the new input, and the next move starts from it. Where that cannot hold or would
cost more, the move runs in full instead: a move that changes the frame of a full build's lists
(every list's order; a tip moved past the snapped box), or whose change or reach is a large
share of the groom (:data:`MAX_SEEDS`, :data:`MAX_REGION`: a full run costs less then). A comb
at a ponytail's tips costs its brush though every strand meets the others in the tie: the reach
follows the vertices that changed, not every vertex of their strands.
:func:`clump_region_reference` is the numpy twin (the same definition, pairs summed in another
order: equal to about 1e-6 of h).
"""

from __future__ import annotations

from contextlib import contextmanager

import numba
import numpy as np
from numba import prange

from hairtool import serial_twins
from hairtool.bounds import box, moved_box
from hairtool.frozen.clump import (
    _GAP_CODE,
    EPS,
    MARGIN,
    ClumpRecord,
    auto_step,
    gap_factors_reference,
    next_iterate,
    vertex_force,
)
from hairtool.frozen.lengths import restore_lengths_reference
from hairtool.frozen.noise import CH_CLUMP, hash_head_nb, hash_tail_u01_nb, seed_u64
from hairtool.frozen.spatial import pairs_within_reference
from hairtool.frozen.vertex_grid import VertexGrid, list_frame
from hairtool.groom import Topology
from hairtool.serial_twins import twin_njit
from hairtool.sorted_ids import distinct_sorted

MAX_SEEDS = 0.1  # of the vertices: a move that changes more runs in full (cheaper then)
MAX_REGION = 0.25  # of the vertices: a region larger than this, too (measured on ratboy_mohawk: a
# local move at 15 % of the vertices cost 0.6× a full run, at 35 % 1.2×; break-even near 25 %)
SERIAL_BELOW = 4_000  # vertices: fewer run on the serial twins (:mod:`hairtool.serial_twins`;
# waking the pool's threads costs more than the work). Measured on the 2-core VM (comb at the
# studio's brush on the bear, regions of 2-4 %: 8k vertices): per move 30.7 → 24.9 ms median, 56
# → 44 p90 against 50,000; ratboy's drag (3k-vertex regions) 16.4 → 11.7 ms. The studio's
# threads wait passively (``OMP_WAIT_POLICY``, :mod:`app`): with spinning ones, as in a script
# that leaves it unset, a loaded host's parallel launches cost ~8 ms each, whatever their work


def parallel_for(vertices: int) -> bool:
    """Whether work on this many vertices runs the parallel kernels (from :data:`SERIAL_BELOW`
    on, and while the process runs parallel at all); else their serial twins, which give the
    same bytes."""
    return vertices >= SERIAL_BELOW and serial_twins.parallel_in_use()


@contextmanager
def parallel_from(vertices: int):
    """Brush-local work on ``vertices`` or more runs the parallel kernels while inside: the
    studio's warm-up compiles the kernels a dense groom's moves take (regions of
    :data:`SERIAL_BELOW` vertices and more, the bear's) with a small groom's moves."""
    global SERIAL_BELOW
    saved, SERIAL_BELOW = SERIAL_BELOW, int(vertices)
    try:
        yield
    finally:
        SERIAL_BELOW = saved


@contextmanager
def threads_for(vertices: int):
    """numba threads for kernels without a serial twin (a brush's) on this many vertices: one
    below :data:`SERIAL_BELOW`, else all (the kernels' results do not depend on the count)."""
    threads = numba.get_num_threads()
    if not parallel_for(vertices):
        numba.set_num_threads(1)
    try:
        yield
    finally:
        numba.set_num_threads(threads)


@twin_njit(nogil=True, parallel=True)
def _local_run(new, sv, flat, cap, cnt, vids, roots, h, ident, step, gap, seed, iterations, rec, near):
    """Every iteration of the vertices ``vids`` (lists at ``flat[n·cap :][: cnt[n]]``, original
    indices) from their new input (points ``new``, clump strength ``sv``), written into the
    record ``rec`` = (points, strength, iterates, forces, best, result); the other vertices are
    read where the record has them. One call for the move: the input copied in, then per
    iteration f (15) and the nearest neighbour of each vertex, then its next iterate (or the
    float32 result) with the gap correction: two parallel loops an iteration.
    ``near``: (vids.size,) scratch for the nearest neighbours."""
    points, strength, iterates, forces, best, result = rec
    inv_h = 1.0 / h
    for n in range(vids.size):  # (serial: a copy costs less than waking the threads for it)
        i = vids[n]
        for a in range(3):
            points[i, a] = new[i, a]
            iterates[0, i, a] = points[i, a]
        strength[i] = sv[i]
    for it in range(iterations):
        P, F = iterates[it], forces[it]
        for n in prange(vids.size):
            i = vids[n]
            a0 = n * cap
            a1 = a0 + cnt[n]
            fx, fy, fz, near[n], _, _ = vertex_force(
                P, flat, a0, a1, flat, a1, a1, P[i, 0], P[i, 1], P[i, 2], roots[i], h, inv_h, False, ident
            )
            F[i, 0], F[i, 1], F[i, 2] = fx, fy, fz
            best[it, i] = near[n]
        if it + 1 < iterations:
            _gap_rows(P, F, strength, step, near, vids, h, gap, it, seed, iterates[it + 1])
        else:
            _gap_rows(P, F, strength, step, near, vids, h, gap, it, seed, result)


@twin_njit(nogil=True, parallel=True)
def _gap_rows(P, F, S, step, near, vids, h, gap, it, seed, out):
    """The next iterate (or the float32 result) of each vertex ``vids[n]`` into ``out``, as the
    full run's gap pass: its arrays read here and the scalar
    :func:`~hairtool.frozen.clump.next_iterate` called (numba counted references to arrays
    handed to an inlined helper at every vertex)."""
    for n in prange(vids.size):
        i = vids[n]
        j = near[n]
        si = S[i]
        close = gap != 2 and j >= 0 and si != 0.0
        zeta = 0.0
        ex = ey = ez = gx = gy = gz = 0.0
        if close:
            zeta = hash_tail_u01_nb(hash_head_nb(seed, i, CH_CLUMP), it)
            sj = S[j]
            ex, ey, ez = P[j, 0] - P[i, 0], P[j, 1] - P[i, 1], P[j, 2] - P[i, 2]
            gx, gy, gz = sj * F[j, 0] - si * F[i, 0], sj * F[j, 1] - si * F[i, 1], sj * F[j, 2] - si * F[i, 2]
        out[i, 0], out[i, 1], out[i, 2] = next_iterate(
            P[i, 0], P[i, 1], P[i, 2], F[i, 0], F[i, 1], F[i, 2], si,
            ex, ey, ez, gx, gy, gz, close, step, zeta, h, gap,
        )  # fmt: skip


def _same_frame(a: tuple, b: tuple) -> bool:
    """Whether two :func:`~hairtool.frozen.vertex_grid.list_frame` results are the same grid."""
    return all(np.array_equal(x, y) for x, y in zip(a, b, strict=True))


class LocalClump:
    """What a brush-local update keeps between moves: the grid of the input and the last run's
    record (see the module doc). Made after a full, recorded run of ``points``."""

    def __init__(
        self, points: np.ndarray, topology: Topology, h: float, record: ClumpRecord, longest: int = 0
    ) -> None:
        """``longest``: the longest neighbour list of the full run (the region lists get room
        for it from the first move on, instead of running again wider on the move that meets it)."""
        self.topology = topology
        self.h = float(h)
        self.radius = self.h * (1.0 + MARGIN)
        self.record = record
        self.grid = VertexGrid(points, topology.strand_index, self.radius)
        self.grid.reserve(longest)
        self.roots = np.zeros(topology.vertex_count, bool)
        self.roots[topology.root_indices] = True
        self.ident = np.arange(topology.vertex_count, dtype=np.int64)
        self.region = np.zeros(0, np.int64)  # the strands the last update redid
        self.vertices = np.zeros(0, np.int64)  # and its vertices
        self.lists_ms = 0.0  # of the last update: grid moves and neighbour lists
        self._box: tuple | None = None  # the grid's points' box (float64), None: not known
        self._frame = self.frame(points)  # the full build's grid the record's lists were in
        self._nearest = np.empty(0, np.int64)  # scratch of :func:`_local_run`, kept across moves

    def _near(self, n: int) -> np.ndarray:
        """Room for ``n`` nearest neighbours (grown, never shrunk)."""
        if self._nearest.size < n:
            self._nearest = np.empty(max(n, int(1.5 * self._nearest.size)), np.int64)
        return self._nearest[:n]

    def resync(self, points: np.ndarray, old: np.ndarray) -> None:
        """After another full run: the grid follows the vertices that moved since ``old``."""
        moved = np.flatnonzero(np.any(points.view(np.uint32) != old.view(np.uint32), axis=1))
        self.grid.move(points, moved)
        self._follow(old[moved], points[moved])
        self._frame = self.frame(points)

    def _follow(self, old: np.ndarray, new: np.ndarray) -> None:
        """The box after the grid's points ``old`` moved to ``new`` (unknown where one held an
        extreme: :meth:`frame` then looks at every point once)."""
        if self._box is not None:
            self._box = moved_box(self._box, old, new)

    def frame(self, points: np.ndarray) -> tuple:
        """:func:`~hairtool.frozen.vertex_grid.list_frame` of the grid's ``points``, from the box
        kept across moves (a pass over millions of points costs more than a move)."""
        if self._box is None:
            self._box = tuple(b.astype(np.float64) for b in box(points))
        return list_frame(points, self.radius, self._box)

    def near(self, points: np.ndarray, queries: np.ndarray, radius: float) -> np.ndarray:
        """Sorted ids of the strands with a vertex of ``points`` (as the grid holds them) closer
        than ``radius`` to one of ``queries`` (on the serial kernels where the queries' boxes
        span fewer than :data:`SERIAL_BELOW` cells: the walk's work)."""
        mark = np.zeros(self.topology.strand_count, bool)
        if len(queries):
            cells = len(queries) * (2.0 * radius / self.grid.cell + 1.0) ** 3
            self.grid.strands_near(points, queries, radius, mark, parallel_for(int(min(cells, 2**62))))
        return np.flatnonzero(mark)

    def update(
        self,
        was: np.ndarray,
        new: np.ndarray,
        changed: np.ndarray,
        sv: np.ndarray,
        iterations: int,
        step: float,
        gap_mode: str,
        seed: int,
    ) -> tuple[np.ndarray, np.ndarray] | None:
        """The input changed on the vertices ``changed`` (sorted ids: their points, at ``was``
        before, or their clump strength ``sv`` (V,)) and is now ``new``. Returns the region (the
        strands with a vertex redone) and the vertices redone (:func:`reach`), after writing
        their rows of the record; None where a full run must run instead: the change or its
        reach is most of the groom (:data:`MAX_SEEDS`, :data:`MAX_REGION`: a full run costs
        less), or the move changed the frame of a full build's lists (every list's order then
        changes). The grid holds ``new`` either way."""
        import time

        t0 = time.perf_counter()
        top, rec = self.topology, self.record
        v = top.vertex_count
        self.grid.move(new, changed)
        self._follow(was, new[changed])
        if changed.size > MAX_SEEDS * v:
            return None
        frame = self.frame(new)
        if not _same_frame(frame, self._frame):
            return None
        vids = self.reach(was, new, changed, iterations, gap_mode, int(MAX_REGION * v))
        if vids is None:
            return None
        parallel = parallel_for(vids.size)
        flat, cnt, cap = self.grid.lists(new, vids, self.radius, frame, parallel)
        self.lists_ms = (time.perf_counter() - t0) * 1e3
        run = _local_run if parallel else serial_twins.serial(_local_run)
        fields = (rec.points, rec.strength, rec.iterates, rec.forces, rec.best, rec.result)
        gap, seed64 = _GAP_CODE[gap_mode], seed_u64(seed)
        run(new, sv, flat, cap, cnt, vids, self.roots, self.h, self.ident, float(step), gap, seed64,
            iterations, fields, self._near(vids.size))  # fmt: skip
        self.region = distinct_sorted(top.strand_index[vids])  # (vids ascending: their strands too)
        self.vertices = vids
        return self.region, vids

    def reach(
        self, was: np.ndarray, new: np.ndarray, changed: np.ndarray, iterations: int, gap_mode: str, most: int
    ) -> np.ndarray | None:
        """Sorted ids of every vertex whose clumping a change of the input on ``changed`` can
        change (see the module doc), from the grid holding ``new`` and the record's nearest
        neighbours; None past ``most`` of them.

        In iteration it, the forces that can change are those of the vertices whose points can,
        and of those with one of them in their lists (the lists that changed are those of the
        vertices near a changed vertex, before or after). The points of the next iterate that can
        change are those, and the points of the vertices whose nearest neighbour's force can (the
        gap correction; not with gap mode "off"): a vertex whose list holds no changed point has
        the record's nearest neighbour. The grid walks it all in one compiled call
        (:meth:`~hairtool.frozen.vertex_grid.VertexGrid.reach`: flags, not numpy's set
        operations between six calls)."""
        return self.grid.reach(
            new, was, changed, self.record.best, gap_mode != "off", iterations, self.radius, most
        )


def clump_region_reference(
    points: np.ndarray,
    topology: Topology,
    vertices: np.ndarray,
    iterates: np.ndarray,
    forces: np.ndarray,
    result: np.ndarray,
    sv: np.ndarray,
    h: float,
    iterations: int,
    step: float | None,
    gap_mode: str,
    seed: int,
    keep_lengths: bool = False,
) -> np.ndarray:
    """Numpy twin of a :class:`LocalClump` update: ``(V, 3)`` float64, the ``vertices`` (ids)
    clumped from ``points`` with every other vertex at ``iterates[it]`` and pulling with
    ``forces[it]`` in iteration it (a previous run's); the other rows are that run's ``result``
    (with ``keep_lengths``, the lengths given back on every strand with a vertex redone).
    ``step`` None: :func:`~hairtool.frozen.clump.auto_step` of ``points``."""
    strand = topology.strand_index
    v = topology.vertex_count
    inside = np.zeros(v, bool)
    inside[np.asarray(vertices, np.int64)] = True
    moving = np.ones(v, bool)
    moving[topology.root_indices] = False
    ci, cj = pairs_within_reference(points, strand, h * (1.0 + MARGIN))
    keep = inside[ci] & moving[ci]
    ci, cj = ci[keep], cj[keep]
    P = np.asarray(iterates[0], np.float64).copy()
    P[inside] = points[inside]
    for it in range(iterations):
        if it > 0:
            Q = np.asarray(iterates[it], np.float64).copy()
            Q[inside] = P[inside]
            P = Q
        d = P[cj] - P[ci]
        r = np.sqrt(d[:, 0] * d[:, 0] + d[:, 1] * d[:, 1] + d[:, 2] * d[:, 2])
        near = r < h
        i, j, d, r = ci[near], cj[near], d[near], r[near]
        g = (1.0 - r / h) ** 2  # (14)
        f = np.asarray(forces[it], np.float64).copy()
        f[inside] = 0.0
        for a in range(3):
            f[:, a] += np.bincount(i, weights=g / (r + EPS) * d[:, a], minlength=v)  # (15)
        if it == 0 and step is None:
            step = auto_step(h, np.bincount(i, weights=g, minlength=v), np.bincount(i, minlength=v))
        dp = sv[:, None] * (float(step) * f)
        lam = gap_factors_reference(i, j, r, P, dp, h, seed, it, gap_mode)
        step_all = np.where(inside[:, None] & moving[:, None], lam[:, None] * dp, 0.0)
        P = P + step_all
    P = np.where(inside[:, None], P, np.asarray(result, np.float64))
    if keep_lengths and iterations > 0:
        kept = restore_lengths_reference(points, P.astype(np.float32), topology).astype(np.float64)
        kept = np.where((sv == 0.0)[:, None], points, kept)
        whole = np.zeros(topology.strand_count, bool)
        whole[strand[inside]] = True
        P = np.where(whole[strand][:, None], kept, P)
    return P


def reach_reference(
    was: np.ndarray,
    points: np.ndarray,
    strand: np.ndarray,
    changed: np.ndarray,
    radius: float,
    best: np.ndarray,
    gap_mode: str,
) -> np.ndarray:
    """Numpy twin of :meth:`LocalClump.reach` (without its limit): sorted ids of the vertices
    whose clumping can change when the input changes on ``changed`` (the only vertices that
    differ between ``was``, before the move, and ``points``), on the lists (other strands within
    ``radius``) of both, with ``best`` ``(k, V)`` the last run's nearest neighbours."""
    changed = np.asarray(changed, np.int64)
    ci, cj = pairs_within_reference(was, strand, radius)  # the lists before
    p = np.asarray(points, np.float64)
    ni, nj = [ci], [cj]
    for c in np.array_split(changed, max(1, changed.size // 64)):  # their lists after
        d = p[c][:, None, :] - p[None, :, :]
        near = (np.einsum("ijk,ijk->ij", d, d) < radius * radius) & (strand[c][:, None] != strand)
        a, b = np.nonzero(near)
        ni.append(c[a])
        nj.append(b)
    i, j = np.concatenate(ni + nj), np.concatenate(nj + ni)
    points_change = np.zeros(p.shape[0], bool)
    points_change[changed] = True
    for it in range(best.shape[0]):
        forces_change = points_change.copy()
        forces_change[i[points_change[j]]] = True  # (15): a changed point in the list
        points_change = forces_change.copy()
        if gap_mode != "off":  # (17)-(19): the nearest neighbour's force
            b = best[it]
            points_change |= (b >= 0) & forces_change[np.maximum(b, 0)]
    return np.flatnonzero(points_change)
