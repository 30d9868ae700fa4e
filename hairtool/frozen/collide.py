"""Surface collision: after a brush sample no vertex of a strand it moved stays inside the head.

The strands a sample changed are checked against the head's signed distance (< 0 inside: behind
the normal of the face, edge or corner the closest point lies on, which reads folds and ridges
the right way round). In a strand with a vertex inside, from the first such vertex to the tip,
each vertex in turn is put back at its segment's length from the (already solved) one before,
toward where the brush left it; if it is then inside, it is pushed out to the closest surface
point plus a margin along the normal there and put back at its length toward that point, up to
PUSHES times, each time lifted 4× further out (at most a segment's length): the length pulls
it back part of the way.

In a harsh fold those pushes can bounce between the fold's two walls and end inside (the
length pulls the vertex back through the wall it was pushed off). A vertex still inside then
*escapes*: on the sphere of its segment's length around the vertex before, directions are
tried from the one the brush wanted toward the way out there (the normal at that vertex's
closest point) and over the whole sphere (a fixed spiral of directions); of those that land
at least the margin outside, the one closest to the wanted direction is taken, then moved back
toward the wanted one by bisection while it stays outside, so the vertex rests against the
surface. Only where no direction of the sphere is outside (the vertex before is sealed in)
does a vertex stay inside, as far out as it got. Every tried point is rounded to float32 first,
as the groom stores it, so a vertex found outside stays outside. Roots never move, and every
segment keeps the length the brush gave it.

Clumping comes after the strokes and pulls strands toward their clumps, which on a curved head
can cut back through it: :func:`keep_out` (run by the pipeline after ClumpWithGaps wherever its
strokes collide) lets a strand that was outside before clumping clump only as far as it stays
outside, its segments at their clumped lengths.

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
TOWARD_OUT = 8  # directions tried from the wanted one to the way out
BISECTIONS = 12  # steps back toward the wanted direction


def _spiral(n: int) -> np.ndarray:
    """``(n, 3)`` unit directions spread evenly over the sphere (a golden-angle spiral)."""
    k = np.arange(n) + 0.5
    z = 1.0 - 2.0 * k / n
    t = np.pi * (3.0 - np.sqrt(5.0)) * k
    r = np.sqrt(1.0 - z * z)
    return np.column_stack([r * np.cos(t), r * np.sin(t), z])


SPHERE = _spiral(96)


class CollisionSurface(Protocol):
    def signed_distance(self, points: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]: ...


def _unit_toward(prev: np.ndarray, x: np.ndarray, length: np.ndarray, fallback: np.ndarray) -> np.ndarray:
    d = x - prev
    n = np.sqrt(np.einsum("ij,ij->i", d, d))
    small = n < EPS
    d[small], n[small] = fallback[small], np.sqrt(np.einsum("ij,ij->i", fallback[small], fallback[small]))
    return prev + d * (length / np.maximum(n, EPS))[:, None]


def _f32(x: np.ndarray) -> np.ndarray:
    return x.astype(np.float32).astype(np.float64)


def _unit(x: np.ndarray) -> np.ndarray:
    return x / np.maximum(np.sqrt(np.einsum("...i,...i->...", x, x)), EPS)[..., None]


def escape(
    prev: np.ndarray, want: np.ndarray, length: np.ndarray, surface: CollisionSurface, margin: float
) -> np.ndarray:
    """``(M, 3)`` points at ``length`` from ``prev`` (float32-exact), each outside the surface
    by at least ``margin`` and as near the direction toward ``want`` as found (module
    docstring); where no tried direction is outside, the one farthest out.

    Parameters
    ----------
    prev : ndarray
        ``(M, 3)`` the points before, each already outside.
    want : ndarray
        ``(M, 3)`` where each point would go.
    length : ndarray
        ``(M,)`` each segment's length.
    surface : CollisionSurface
        The head.
    margin : float
        How far outside, in the groom's units.

    Returns
    -------
    ndarray
        ``(M, 3)`` float32 points.
    """
    m = len(prev)
    d0 = _unit(want - prev)
    _, _, n_p = surface.signed_distance(prev)
    out_dir = np.where(np.isfinite(n_p), n_p, d0)
    t = (np.arange(1, TOWARD_OUT + 1) / TOWARD_OUT)[None, :, None]
    dirs = np.concatenate(
        [_unit((1.0 - t) * d0[:, None] + t * out_dir[:, None]), np.broadcast_to(SPHERE, (m, *SPHERE.shape))],
        axis=1,
    )  # (M, C, 3)
    cand = _f32(prev[:, None] + length[:, None, None] * dirs)
    sd = surface.signed_distance(cand.reshape(-1, 3))[0].reshape(m, -1)
    clear = sd >= margin
    score = np.where(clear, np.einsum("mci,mi->mc", dirs, d0), -np.inf)
    best = np.where(clear.any(axis=1), np.argmax(score, axis=1), np.argmax(sd, axis=1))
    rows = np.arange(m)
    hi, lo = dirs[rows, best], d0.copy()
    ok = clear[rows, best]
    for _ in range(BISECTIONS):  # toward the wanted direction while outside
        mid = lo + hi
        fine = ok & (np.einsum("ij,ij->i", mid, mid) > EPS)
        mid = np.where(fine[:, None], _unit(mid), hi)
        inside = surface.signed_distance(_f32(prev + length[:, None] * mid))[0] < margin
        hi = np.where((fine & ~inside)[:, None], mid, hi)
        lo = np.where((fine & inside)[:, None], mid, lo)
    return _f32(prev + length[:, None] * hi)


#: How far a strand may clump before it enters the head is searched on a grid of SPLIT shares
#: of its clumping move, then of the best cell, ROUNDS times (a share within 1/64): all the
#: shares of a round go to the head in one query, each query being a kernel launch.
SPLIT, ROUNDS = 8, 2


def _with_lengths(x: np.ndarray, like: np.ndarray, n: int) -> np.ndarray:
    """``(S, n, 3)`` strands ``x`` with each segment back to its length in ``like``, directions
    kept, root to tip."""
    seg = np.linalg.norm(np.diff(like, axis=1), axis=2)
    out = x.copy()
    for i in range(1, n):
        d = x[:, i] - x[:, i - 1]
        norm = np.sqrt(np.einsum("ij,ij->i", d, d))
        fallback = like[:, i] - like[:, i - 1]
        d = np.where((norm > EPS)[:, None], d, fallback)
        norm = np.where(norm > EPS, norm, np.maximum(seg[:, i - 1], EPS))
        out[:, i] = out[:, i - 1] + d * (seg[:, i - 1] / norm)[:, None]
    return out


def _any_inside(surface: CollisionSurface, x: np.ndarray) -> np.ndarray:
    """``(S,)`` whether a point of each strand ``x`` ``(S, n, 3)`` but its root is inside."""
    d = surface.signed_distance(x.reshape(-1, 3))[0].reshape(x.shape[:2])
    return (d[:, 1:] < 0).any(axis=1)


def keep_out(
    before: Groom,
    after: Groom,
    surface: CollisionSurface,
    margin: float,
    sd_before: np.ndarray | None = None,
    sd_after: np.ndarray | None = None,
) -> Groom:
    """``after`` (the clumped ``before``, same strands) where clumping pulled a strand into the
    head: a strand wholly outside in ``before`` (roots aside) and not in ``after`` clumps only as
    far as it stays outside, the largest share t of its clumping move (``before`` + t·(``after`` −
    ``before``), t the largest outside on a grid of :data:`SPLIT` shares refined :data:`ROUNDS`
    times, over the strands at once, each tried shape rounded to float32 first) with its
    segments back at their clumped lengths; where that put it inside again, it keeps its shape
    from before clumping. On a curved head a clump's pull can cut through it. A strand already
    inside before (a stroke with collision off put it there) is left as it is. ``margin`` is
    unused (kept for :func:`collide`'s signature). ``sd_before`` / ``sd_after``: the points'
    signed distances where known (:class:`KeepOut`).

    Parameters
    ----------
    before : Groom
        The strands before clumping.
    after : Groom
        The same strands clumped.
    surface : CollisionSurface
        The head.
    margin : float
        How far outside, in the groom's units.
    sd_before, sd_after : ndarray, optional
        Signed distances of their points, where the caller has them.

    Returns
    -------
    Groom
        ``after`` with the strands clumping pulled in clumped less.
    """
    del margin
    top = before.topology
    if before.vertex_count == 0:
        return after
    if sd_before is None:
        sd_before = surface.signed_distance(before.points.astype(np.float64))[0]
    if sd_after is None:
        sd_after = surface.signed_distance(after.points.astype(np.float64))[0]
    deep = top.index_in_strand > 0
    starts = top.offsets[:-1]
    was_in = np.logical_or.reduceat((sd_before < 0) & deep, starts)
    now_in = np.logical_or.reduceat((sd_after < 0) & deep, starts)
    fix = np.flatnonzero(now_in & ~was_in)
    if fix.size == 0:
        return after
    out = after.points.copy()
    for n in np.unique(top.counts[fix]):  # strands of one vertex count at a time, as arrays
        ids = fix[top.counts[fix] == n]
        vids = vertex_ids_of(top, ids)
        b = before.points[vids].astype(np.float64).reshape(len(ids), n, 3)
        a = after.points[vids].astype(np.float64).reshape(len(ids), n, 3)
        # The signed distance changes no faster than a point moves: a vertex farther out before
        # clumping than its whole clumping move stays outside at every share (the tolerance
        # covers float32 rounding), so only the others are asked about.
        tol = 1e-4 * (1.0 + float(np.abs(b).max()))
        near = sd_before[vids].reshape(len(ids), n) <= np.linalg.norm(a - b, axis=2) + tol
        near[:, 0] = False  # (roots never count)
        lo, step = np.zeros(len(ids)), 1.0  # outside at lo (before clumping: it was outside)
        for _ in range(ROUNDS):
            step /= SPLIT
            t = lo[:, None] + step * np.arange(1, SPLIT)[None, :]  # (S, SPLIT − 1) shares to try
            ask = np.broadcast_to(near[:, None, :], (*t.shape, n))
            x = _f32(b[:, None] + t[..., None, None] * (a - b)[:, None])
            d = np.full(ask.shape, np.inf)
            d[ask] = surface.signed_distance(x[ask])[0] if ask.any() else 0.0
            clear = ~(d < 0).any(axis=2)
            last = np.where(clear.any(axis=1), SPLIT - 2 - np.argmax(clear[:, ::-1], axis=1), -1)
            lo = np.where(last >= 0, t[np.arange(len(ids)), np.maximum(last, 0)], lo)  # the largest outside
        x = _f32(_with_lengths(b + lo[:, None, None] * (a - b), a, n))
        x = np.where(_any_inside(surface, x)[:, None, None], b, x)  # (before clumping it was outside)
        out[vids] = x.reshape(-1, 3).astype(np.float32)
    return after.with_points(out)


class KeepOut:
    """:func:`keep_out` with a memory: the signed distances of the points it saw at its last
    call are reused for those that did not change (a brush moves a few strands per update and
    clumping redoes only the region around them), so an update asks the head about those alone,
    before and after clumping in one query. The same bytes as :func:`keep_out` without it."""

    def __init__(self) -> None:
        self._last: dict[str, tuple] = {}

    def remember(self, before: Groom, after: Groom, surface: CollisionSurface) -> None:
        """Ask the head about ``before`` and ``after`` now, so that the next call asks only about
        the points that differ from them (the first stroke after an open would otherwise ask
        about every point twice).

        Parameters
        ----------
        before, after : Groom
            The strands before and after clumping.
        surface : CollisionSurface
            The head.
        """
        for key, points in (("before", before.points), ("after", after.points)):
            sd = surface.signed_distance(points.astype(np.float64))[0]
            self._last[key] = (surface, points.copy(), sd)

    def __call__(self, before: Groom, after: Groom, surface: CollisionSurface, margin: float) -> Groom:
        parts = []  # per groom: its points, which changed since last time, the distances known
        for key, points in (("before", before.points), ("after", after.points)):
            last = self._last.get(key)
            if last is None or last[0] is not surface or last[1].shape != points.shape:
                parts.append((key, points, np.ones(len(points), bool), np.empty(len(points))))
            else:
                parts.append((key, points, np.any(points != last[1], axis=1), last[2].copy()))
        ask = np.concatenate([p[changed] for _, p, changed, _ in parts]).astype(np.float64)
        found = surface.signed_distance(ask)[0] if len(ask) else np.zeros(0)
        at = 0
        for key, points, changed, sd in parts:
            k = int(changed.sum())
            sd[changed] = found[at : at + k]
            at += k
            self._last[key] = (surface, points.copy(), sd)
        return keep_out(before, after, surface, margin, parts[0][3], parts[1][3])


def collide(before: Groom, after: Groom, surface: CollisionSurface, margin: float) -> Groom:
    """``after`` (one sample's result on ``before``, same strands) with the strands it moved
    pushed out of the head, lengths kept (module docstring).

    Parameters
    ----------
    before : Groom
        The strands before the sample.
    after : Groom
        The same strands after it.
    surface : CollisionSurface
        The head.
    margin : float
        How far outside, in the groom's units.

    Returns
    -------
    Groom
        ``after``, the strands it moved kept out of the head.
    """
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
        x = _f32(_unit_toward(p[v - 1], given[v], length, seg))
        out = np.zeros(len(v), bool)
        for t in range(PUSHES):
            d, q, nrm = surface.signed_distance(x)
            out = ~(d < 0)
            if out.all():
                break
            lift = np.minimum(margin * 4.0**t, np.maximum(length[~out], margin))  # further out each time
            pushed = q[~out] + lift[:, None] * nrm[~out]
            x[~out] = _f32(_unit_toward(p[v - 1][~out], pushed, length[~out], seg[~out]))
        else:
            out = ~(surface.signed_distance(x)[0] < 0)
        if not out.all():  # bounced in a fold: escape along the sphere of the segment's length
            x[~out] = escape(p[v - 1][~out], given[v][~out], length[~out], surface, margin)
        p[v] = x
    return after.with_points(p.astype(np.float32))
