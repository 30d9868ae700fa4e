"""Brush-local ClumpWithGaps: a move redoes the strands under the brush and those their clumps reach.

While a brush drags, a mouse move changes a few strands. :class:`LocalClump` keeps what the last
run left (a :class:`~hairtool.frozen.clump.ClumpRecord`: each iteration's points and forces,
every vertex's input and output) and a :class:`~hairtool.frozen.vertex_grid.VertexGrid` of the
input kept across moves. A move's *region* is the strands that changed (points or clump strength)
and every strand with a vertex within the list radius h·(1 + MARGIN), the clump kernel's reach,
of one of their vertices, before or after the move. The region is clumped again from its new
input; every other vertex is held where the last run had it at each iteration (its points and
forces), read-only, and its result stays bit for bit.

So a region vertex ends where a full run would put it if the full run's clump reached no further
than the region: where a move's effect stays inside it (strands farther than the reach from every
other strand, or a first run) the bytes are a full run's, because each list comes in a full
build's order (:mod:`hairtool.frozen.vertex_grid`) and the same kernels sum it. Beyond the region
a full run would move a vertex by the changed pulls of its region neighbours too (the effect
spreads two list steps per iteration); the local run leaves it be, which is what makes a move cost
the brush and not the groom. :func:`clump_region_reference` is the numpy twin (the same
definition, pairs summed in another order: equal to about 1e-6 of h).
"""

from __future__ import annotations

from contextlib import contextmanager

import numba
import numpy as np
from numba import prange

from hairtool.bounds import box, moved_box
from hairtool.frozen.clump import (
    _GAP_CODE,
    EPS,
    MARGIN,
    ClumpRecord,
    auto_step,
    gap_factors_reference,
    moved_vertex,
    vertex_force,
)
from hairtool.frozen.lengths import restore_lengths_reference
from hairtool.frozen.noise import CH_CLUMP, hash_head_nb, hash_tail_u01_nb, seed_u64
from hairtool.frozen.spatial import pairs_within_reference
from hairtool.frozen.vertex_grid import VertexGrid, list_frame
from hairtool.groom import Topology, vertex_ids_of
from hairtool.serial_twins import twin_njit

MAX_SEEDS = 0.1  # of the vertices: a move that changes more runs in full (cheaper then)
MAX_REGION = 0.25  # of the vertices: a region larger than this, too (measured on ratboy_mohawk: a
# local move at 15 % of the vertices cost 0.6× a full run, at 35 % 1.2×; break-even near 25 %)
SERIAL_BELOW = 4_000  # vertices: fewer run on one thread (waking the others costs more than the
# work). Measured on the 2-core VM (comb at the studio's brush on the bear, regions of 2-4 %:
# 8k vertices): per move 30.7 → 24.9 ms median, 56 → 44 p90 against the former 50,000; ratboy's
# drag (3k-vertex regions) 16.4 → 11.7 ms; smaller regions unchanged


@contextmanager
def threads_for(vertices: int):
    """numba threads for work on this many vertices: one below :data:`SERIAL_BELOW`, else all
    (the kernels' results do not depend on the count)."""
    threads = numba.get_num_threads()
    if vertices < SERIAL_BELOW:
        numba.set_num_threads(1)
    try:
        yield
    finally:
        numba.set_num_threads(threads)


@twin_njit(nogil=True, parallel=True)
def _local_force(P, flat, cap, cnt, vids, roots, h, ident, F, best):
    """f (15) and the nearest neighbour of each vertex ``vids[n]``, its list at
    ``flat[n·cap :][: cnt[n]]`` (original indices; ``P``, ``F`` in original order)."""
    inv_h = 1.0 / h
    for n in prange(vids.size):
        i = vids[n]
        a0 = n * cap
        a1 = a0 + cnt[n]
        fx, fy, fz, best[n], _, _ = vertex_force(
            P, flat, a0, a1, flat, a1, a1, P[i, 0], P[i, 1], P[i, 2], roots[i], h, inv_h, False, ident
        )
        F[i, 0], F[i, 1], F[i, 2] = fx, fy, fz


@twin_njit(nogil=True, parallel=True)
def _local_gap(P, F, S, step, best, vids, h, gap, it, seed, out):
    """The next iterate (or the float32 result) of each vertex ``vids[n]`` into ``out``."""
    for n in prange(vids.size):
        i = vids[n]
        j = best[n]
        zeta = 0.0
        if gap != 2 and j >= 0:
            zeta = hash_tail_u01_nb(hash_head_nb(seed, i, CH_CLUMP), it)
        moved_vertex(P, F, S, step, i, j, zeta, h, gap, out, i)


@twin_njit(nogil=True, parallel=True)
def _set_rows(dst, src, vids):
    for n in prange(vids.size):
        i = vids[n]
        for a in range(3):
            dst[i, a] = src[i, a]


def strands_differing(
    before: np.ndarray, after: np.ndarray, counts: np.ndarray, strands: np.ndarray
) -> np.ndarray:
    """Of ``strands`` (``counts`` vertices each), those with a vertex whose bytes differ between
    ``before`` and ``after``, their vertices' rows one strand after another."""
    if strands.size == 0:
        return strands
    diff = np.any(before.view(np.uint32) != after.view(np.uint32), axis=1)
    starts = np.concatenate([[0], np.cumsum(counts)[:-1]])
    return strands[np.logical_or.reduceat(diff, starts)]


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
        self.lists_ms = 0.0  # of the last update: grid moves and neighbour lists
        self._box: tuple | None = None  # the grid's points' box (float64), None: not known

    def resync(self, points: np.ndarray, old: np.ndarray) -> None:
        """After another full run: the grid follows the vertices that moved since ``old``."""
        moved = np.flatnonzero(np.any(points.view(np.uint32) != old.view(np.uint32), axis=1))
        self.grid.move(points, moved)
        self._follow(old[moved], points[moved])

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
        than ``radius`` to one of ``queries``."""
        mark = np.zeros(self.topology.strand_count, bool)
        if len(queries):
            self.grid.strands_near(points, queries, radius, mark)
        return np.flatnonzero(mark)

    def update(
        self,
        was: np.ndarray,
        new: np.ndarray,
        seeds: np.ndarray,
        sv: np.ndarray,
        iterations: int,
        step: float,
        gap_mode: str,
        seed: int,
    ) -> tuple[np.ndarray, np.ndarray] | None:
        """The input went to ``new`` on the strands ``seeds`` (those whose points or clump
        strength ``sv`` (V,) changed), whose vertices were at ``was`` before. Returns the
        region's strands and vertices, after writing their result rows into the record's
        ``result``; None where the region would be most of the groom (:data:`MAX_SEEDS`,
        :data:`MAX_REGION`: the caller runs in full; the grid holds ``new`` either way)."""
        import time

        t0 = time.perf_counter()
        top, rec = self.topology, self.record
        seed_v = vertex_ids_of(top, seeds)
        v = top.vertex_count
        self.grid.move(new, seed_v)
        self._follow(was, new[seed_v])
        if seed_v.size > MAX_SEEDS * v:
            return None
        # The strands whose lists held the seeds' vertices and those whose lists hold them now, in
        # one query on the grid as it is now: a vertex within reach of a seed's old place that
        # moved is a seed's own (in the region anyway); the others are where they were.
        both = np.concatenate([was, new[seed_v]])
        region = np.union1d(self.near(new, both, self.radius), seeds)
        vids = vertex_ids_of(top, region)
        if vids.size > MAX_REGION * v:
            return None
        with threads_for(vids.size):
            flat, cnt, cap = self.grid.lists(new, vids, self.radius, self.frame(new))
            self.lists_ms = (time.perf_counter() - t0) * 1e3
            rec.points[vids] = new[vids]
            rec.strength[vids] = sv[vids]
            _set_rows(rec.iterates[0], rec.points, vids)
            best = np.empty(vids.size, np.int64)
            gap, seed64 = _GAP_CODE[gap_mode], seed_u64(seed)
            for it in range(iterations):
                p, f = rec.iterates[it], rec.forces[it]
                _local_force(p, flat, cap, cnt, vids, self.roots, self.h, self.ident, f, best)
                out = rec.iterates[it + 1] if it + 1 < iterations else rec.result
                _local_gap(p, f, rec.strength, float(step), best, vids, self.h, gap, it, seed64, out)
        self.region = region
        return region, vids


def clump_region_reference(
    points: np.ndarray,
    topology: Topology,
    region: np.ndarray,
    iterates: np.ndarray,
    forces: np.ndarray,
    sv: np.ndarray,
    h: float,
    iterations: int,
    step: float | None,
    gap_mode: str,
    seed: int,
    keep_lengths: bool = False,
) -> np.ndarray:
    """Numpy twin of a :class:`LocalClump` update: ``(V, 3)`` float64, the region strands'
    vertices clumped from ``points`` with every other vertex at ``iterates[it]`` and pulling
    with ``forces[it]`` in iteration it (a previous run's); the rows outside the region are the
    last iterate's. ``step`` None: :func:`~hairtool.frozen.clump.auto_step` of ``points``."""
    strand = topology.strand_index
    v = topology.vertex_count
    inside = np.zeros(v, bool)
    inside[vertex_ids_of(topology, np.asarray(region, np.int64))] = True
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
    if keep_lengths and iterations > 0:
        kept = restore_lengths_reference(points, P.astype(np.float32), topology).astype(np.float64)
        kept = np.where((sv == 0.0)[:, None], points, kept)
        P = np.where(inside[:, None], kept, P)
    return P
