"""Where a ray first meets the head: the point a brush on the head works around under the mouse
(a perspective camera's line from its eye through the cursor).

Trying every face at each brush sample cost 3-4 ms on Sintel's head and grew with its faces.
:func:`first_hit` walks the head's :class:`~hairtool.frozen.brushes.sight.FaceGrid` cell by
cell along the ray, as the sight test does (Amanatides and Woo, the cells beyond a side, edge or
corner the ray passes within ``SIDE`` of, the same watertight face test), keeps the nearest
face met so far, and stops at the first cell the ray leaves after that face's point (less the
side tolerance): no face of a later cell can be met before it.

A face is met at ``t`` (the point ``origin + t · direction``) where the watertight test of
:mod:`~hairtool.frozen.brushes.sight` says so with ``t > tmin``; ``t`` is the test's own
``(t · det) / det``. :func:`first_hit_reference` tries every face with the same float operations
(numpy), so both give the same nearest ``t`` bit for bit (a face's ``t`` does not depend on the
order the faces are tried in) and a face met there.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from hairtool.frozen.brushes.sight import (
    SIDE,
    FaceGrid,
    _edge_numpy,
    _sides,
    face_det_t,
    next_side,
    ray_frame,
    walk_start,
)


@njit(cache=True, nogil=True, inline="always")
def _face_t(o, kx, ky, kz, sx, sy, sz, vertices, faces, f, tmin):  # pragma: no cover - compiled
    """``t`` where the ray from ``o`` meets face ``f`` past ``tmin``, or inf: the sight test's
    watertight verdict (:func:`~hairtool.frozen.brushes.sight._meets`, no far end)."""
    det, t = face_det_t(o, kx, ky, kz, sx, sy, sz, vertices, faces, f)
    if det == 0.0:
        return np.inf
    if (det > 0.0 and t > tmin * det) or (det < 0.0 and t < tmin * det):
        return t / det
    return np.inf


@njit(cache=True, nogil=True, inline="always")
def _in_cell(c, frame, o, vertices, faces, start, items, tmin, best, face):  # pragma: no cover
    """The nearest of ``best`` (at ``face``) and the faces of cell ``c``."""
    kx, ky, kz, sx, sy, sz = frame
    for n in range(start[c], start[c + 1]):
        t = _face_t(o, kx, ky, kz, sx, sy, sz, vertices, faces, items[n], tmin)
        if t < best:
            best, face = t, items[n]
    return best, face


@njit(cache=True, nogil=True)
def _beside(
    s0, s1, s2, ci, frame, o, vertices, faces, dims, start, items, tmin, best, face
):  # pragma: no cover
    """The nearest of ``best`` and the faces of the cells beyond cell ``ci`` across the sides
    ``s0, s1, s2`` its point lies on (as :func:`~hairtool.frozen.brushes.sight._beside`)."""
    for m0 in range(2 if s0 else 1):
        for m1 in range(2 if s1 else 1):
            for m2 in range(2 if s2 else 1):
                if m0 or m1 or m2:
                    c = ((ci[0] + m0 * s0) * dims[1] + ci[1] + m1 * s1) * dims[2] + ci[2] + m2 * s2
                    best, face = _in_cell(c, frame, o, vertices, faces, start, items, tmin, best, face)
    return best, face


@njit(cache=True, nogil=True)
def _first_hit_kernel(o, d, vertices, faces, lo, cell, dims, start, items, tmin):  # pragma: no cover
    """``(t, face)`` of the nearest face the ray from ``o`` along ``d`` (not zero) meets past
    ``tmin`` inside the grid's box, or ``(inf, -1)``: the cells in order, each with the cells
    beyond the sides its entry and exit points lie within ``SIDE`` of, until the nearest ``t``
    found lies before the exit of the cell just searched by more than the side tolerance."""
    best, face = np.inf, -1
    ci = np.empty(3, np.int64)
    step = np.empty(3, np.int64)
    tmax = np.empty(3, np.float64)
    tdelta = np.empty(3, np.float64)
    t0, t1 = walk_start(o, d, lo, cell, dims, ci, step, tmax, tdelta)
    if t0 > t1:
        return best, face
    frame = ray_frame(d)
    tol = SIDE * cell
    # the side tolerance in t, and the walk's own rounding where the origin is far from the box
    slack = tol / np.sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]) + 1e-12 * t1
    s0, s1, s2 = _sides(o, d, t0, ci, -1, lo, cell, dims, tol)  # where the walk starts
    while True:
        c = (ci[0] * dims[1] + ci[1]) * dims[2] + ci[2]
        best, face = _in_cell(c, frame, o, vertices, faces, start, items, tmin, best, face)
        if s0 != 0 or s1 != 0 or s2 != 0:  # the point the walk entered by
            best, face = _beside(
                s0, s1, s2, ci, frame, o, vertices, faces, dims, start, items, tmin, best, face
            )
        a, leaves = next_side(tmax, t1)
        exit_t = t1 if leaves else tmax[a]
        s0, s1, s2 = _sides(o, d, exit_t, ci, -1 if leaves else a, lo, cell, dims, tol)
        if s0 != 0 or s1 != 0 or s2 != 0:  # the point it leaves by (the next cell's entry)
            best, face = _beside(
                s0, s1, s2, ci, frame, o, vertices, faces, dims, start, items, tmin, best, face
            )
        if leaves or best < exit_t - slack:
            return best, face
        ci[a] += step[a]
        if ci[a] < 0 or ci[a] >= dims[a]:
            return best, face
        tmax[a] += tdelta[a]


def _ray(origin, direction) -> tuple[np.ndarray, np.ndarray] | None:
    """The ray as float64 ``(3,)`` arrays, or None where it has no direction (zero or not finite)."""
    o = np.ascontiguousarray(np.asarray(origin, np.float64).reshape(3))
    d = np.ascontiguousarray(np.asarray(direction, np.float64).reshape(3))
    if not (np.isfinite(o).all() and np.isfinite(d).all()) or not d.any():
        return None
    return o, d


def first_hit(grid: FaceGrid, origin, direction, tmin: float = 0.0) -> tuple[float, int]:
    """Where the ray from ``origin`` along ``direction`` first meets a face of ``grid``.

    Parameters
    ----------
    grid : FaceGrid
        The head.
    origin : array_like
        ``(3,)`` the ray's start.
    direction : array_like
        ``(3,)`` its direction, any length (``t`` counts it).
    tmin : float, default 0
        Faces are met only at ``t > tmin``.

    Returns
    -------
    tuple of (float, int)
        ``t`` (the point is ``origin + t · direction``) and the face (a row of ``grid.faces``),
        or ``(inf, -1)`` for a miss (and for a direction zero or not finite).
    """
    ray = _ray(origin, direction)
    if ray is None:
        return np.inf, -1
    t, f = _first_hit_kernel(
        ray[0], ray[1], grid.vertices, grid.faces, grid.lo, grid.cell, grid.dims, grid.start, grid.items,
        float(tmin),
    )  # fmt: skip
    return float(t), int(f)


def face_ts_reference(corners: tuple, origin, direction, tmin: float = 0.0) -> np.ndarray:
    """``(F,)`` each face's ``t`` (:func:`_face_t` on arrays; inf where the ray does not meet it),
    the faces given by their ``corners``: three ``(F, 3)`` float64 arrays, the faces' first,
    second and third vertices (a surface keeps them, so each call gathers nothing)."""
    ray = _ray(origin, direction)
    if ray is None:
        return np.full(len(corners[0]), np.inf)
    o, d = ray
    kx, ky, kz, sx, sy, sz = ray_frame(d)
    z = [p[:, kz] - o[kz] for p in corners]
    x = [p[:, kx] - o[kx] - sx * z[j] for j, p in enumerate(corners)]
    y = [p[:, ky] - o[ky] - sy * z[j] for j, p in enumerate(corners)]
    u = _edge_numpy(x[2], y[2], x[1], y[1])
    v = _edge_numpy(x[0], y[0], x[2], y[2])
    w = _edge_numpy(x[1], y[1], x[0], y[0])
    det = u + v + w
    t = sz * (u * z[0] + v * z[1] + w * z[2])
    mixed = ((u < 0.0) | (v < 0.0) | (w < 0.0)) & ((u > 0.0) | (v > 0.0) | (w > 0.0))
    ahead = ((det > 0.0) & (t > tmin * det)) | ((det < 0.0) & (t < tmin * det))
    met = ~mixed & ahead
    out = np.full(len(det), np.inf)
    out[met] = t[met] / det[met]
    return out


def first_hit_reference(grid: FaceGrid, origin, direction, tmin: float = 0.0) -> tuple[float, int]:
    """Numpy twin of :func:`first_hit`: every face tried (the lowest such face where several
    are met at the nearest ``t``)."""
    f = grid.faces
    corners = tuple(grid.vertices[f[:, j]] for j in range(3))
    ts = face_ts_reference(corners, origin, direction, tmin)
    if len(ts) == 0 or not np.isfinite(ts.min()):
        return np.inf, -1
    i = int(np.argmin(ts))
    return float(ts[i]), i
