"""Surface collision: after a brush sample no vertex of a strand it moved stays inside the head.

The strands a sample changed are checked against the head's signed distance (< 0 inside: behind
the surface normal at the closest point). In a strand with a vertex inside, from the first such
vertex to the tip, each vertex in turn is put back at its segment's length from the (already
solved) one before, toward where the brush left it; if it is then inside, it is pushed out to
the closest surface point plus a margin along the normal there and put back at its length
toward that point, up to PUSHES times, each time lifted 4× further out (at most a segment's
length): the length pulls it back part of the way. A vertex the strand cannot get outside (in
a fold of the mesh) stays as close as it gets. Roots never move, and every segment keeps the
length the brush gave it.

The surface is anything with ``signed_distance(points) -> (distances, closest points,
normals)`` (:class:`CollisionSurface`), e.g. :class:`hairtool.guides.surface.MeshSurface`.
The loop runs along the strands' vertex indices with all the strands being solved at once
(numpy); its numba kernel is the surface's own (a grid of faces, tested against brute force).
"""

from __future__ import annotations

from typing import Protocol

import numpy as np

from hairtool.groom import Groom, vertex_ids_of

PUSHES = 10
MARGIN = 1e-5  # of the groom's size: how far outside a pushed vertex lands
EPS = 1e-12


class CollisionSurface(Protocol):
    def signed_distance(self, points: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]: ...


def _unit_toward(prev: np.ndarray, x: np.ndarray, length: np.ndarray, fallback: np.ndarray) -> np.ndarray:
    d = x - prev
    n = np.sqrt(np.einsum("ij,ij->i", d, d))
    small = n < EPS
    d[small], n[small] = fallback[small], np.sqrt(np.einsum("ij,ij->i", fallback[small], fallback[small]))
    return prev + d * (length / np.maximum(n, EPS))[:, None]


def collide(before: Groom, after: Groom, surface: CollisionSurface, margin: float) -> Groom:
    """``after`` (one sample's result on ``before``, same strands) with the strands it moved
    pushed out of the head, lengths kept (module docstring)."""
    top = after.topology
    o = top.offsets
    moved_v = np.any(after.points != before.points, axis=1)
    moved = np.logical_or.reduceat(moved_v, o[:-1]) if len(moved_v) else np.zeros(0, bool)
    ids = np.flatnonzero(moved & (top.counts > 1))
    if ids.size == 0:
        return after
    starts, counts = o[ids], top.counts[ids]
    vids = vertex_ids_of(top, ids)
    sd, _, _ = surface.signed_distance(after.points[vids].astype(np.float64))
    inside = (sd < 0) & (top.index_in_strand[vids] > 0)
    if not inside.any():
        return after
    strand_of = np.repeat(np.arange(ids.size), counts)
    first = np.full(ids.size, np.iinfo(np.int64).max)
    np.minimum.at(first, strand_of[inside], top.index_in_strand[vids[inside]])
    fix = first < np.iinfo(np.int64).max
    s0, n_s, first = starts[fix], counts[fix], first[fix]
    p = after.points.astype(np.float64)
    given = p.copy()  # where the brush left each vertex, and the lengths it gave
    for i in range(int(first.min()), int(n_s.max())):
        act = (n_s > i) & (first <= i)
        if not act.any():
            continue
        v = s0[act] + i
        seg = given[v] - given[v - 1]
        length = np.sqrt(np.einsum("ij,ij->i", seg, seg))
        x = _unit_toward(p[v - 1], given[v], length, seg)
        for t in range(PUSHES):
            d, q, nrm = surface.signed_distance(x)
            out = ~(d < 0)
            if out.all():
                break
            lift = np.minimum(margin * 4.0**t, np.maximum(length[~out], margin))  # further out each time
            pushed = q[~out] + lift[:, None] * nrm[~out]
            x[~out] = _unit_toward(p[v - 1][~out], pushed, length[~out], seg[~out])
        p[v] = x
    return after.with_points(p.astype(np.float32))
