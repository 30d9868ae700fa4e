"""Front faces only, by sight: which strands under a brush the head hides from the camera.

A strand is hidden from a sample when it has a vertex within the sample's radius and the head
mesh stands between each such vertex and the camera: the ray from the vertex toward the eye
(against the sample's ``view``) meets a face of the head first. That is what an artist sees
under the brush: hair on the crown seen from a camera level with the face is in sight even
though its roots tilt back from that camera, and the strands on the far side of the head never
are. (The rule before it, :func:`~hairtool.frozen.brushes.scalp.facing_away`, judged a strand
by the normal at its root; stroke logs written before ``BrushSample.visible`` replay with it.)
Why the head and not a band of depth behind the front-most hair under the cursor: the brush is
a ball around the hair the press found, already a band of its own radius; what reaches the far
side is a brush wider than the head is deep there, and only the head tells that apart. Judged
by the vertices under the brush, not the root, a strand whose root is hidden on the scalp
still takes part where its hair above it is in sight.

The head is given as a :class:`FaceGrid`: its faces binned into a uniform grid of cells (a
:class:`~hairtool.guides.surface.MeshSurface` builds one); a ray walks the cells it crosses
(Amanatides and Woo's traversal) and stops at the first face it meets past ``START`` of the
mesh's size, so a root lying on the scalp is not hidden by the face it lies on. A strand with
no vertex within the radius is not hidden (no brush touches it).

:func:`hidden_strands` judges a brush sample's strands, :func:`hidden_points` single points
(the vertex a press starts a stroke on); each has a numpy twin (``*_reference``) that tries
every face for every vertex (the same float operations, so the same verdicts wherever a ray
does not graze a cell's corner to the last bit).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numba import njit
from numpy.typing import ArrayLike

#: a ray starts counting faces this share of the mesh's size from its vertex
START = 1e-6


@dataclass(frozen=True)
class FaceGrid:
    """A head mesh's faces in a uniform grid: ``vertices`` ``(V, 3)`` float64, ``faces``
    ``(F, 3)`` int64 (non-degenerate), the grid's corner ``lo``, cell size ``cell`` and
    ``dims`` cells per axis, and per cell the faces its box overlaps (CSR: ``start``,
    ``items``)."""

    vertices: np.ndarray
    faces: np.ndarray
    lo: np.ndarray
    cell: float
    dims: np.ndarray
    start: np.ndarray
    items: np.ndarray

    @property
    def size(self) -> float:
        """The grid's longest side (a length the ray's start is measured against)."""
        return float(self.cell * self.dims.max())


@njit(cache=True, nogil=True, inline="always")
def _meets(px, py, pz, dx, dy, dz, vertices, faces, f, tmin):  # pragma: no cover - compiled
    """Whether the ray p + t·d meets face ``f`` at some t > tmin (Möller and Trumbore)."""
    a, b, c = faces[f, 0], faces[f, 1], faces[f, 2]
    ax, ay, az = vertices[a, 0], vertices[a, 1], vertices[a, 2]
    e1x, e1y, e1z = vertices[b, 0] - ax, vertices[b, 1] - ay, vertices[b, 2] - az
    e2x, e2y, e2z = vertices[c, 0] - ax, vertices[c, 1] - ay, vertices[c, 2] - az
    qx, qy, qz = dy * e2z - dz * e2y, dz * e2x - dx * e2z, dx * e2y - dy * e2x
    det = e1x * qx + e1y * qy + e1z * qz
    if det == 0.0:
        return False
    inv = 1.0 / det
    sx, sy, sz = px - ax, py - ay, pz - az
    u = (sx * qx + sy * qy + sz * qz) * inv
    if u < 0.0 or u > 1.0:
        return False
    rx, ry, rz = sy * e1z - sz * e1y, sz * e1x - sx * e1z, sx * e1y - sy * e1x
    v = (dx * rx + dy * ry + dz * rz) * inv
    if v < 0.0 or u + v > 1.0:
        return False
    return (e2x * rx + e2y * ry + e2z * rz) * inv > tmin


@njit(cache=True, nogil=True)
def _blocked(px, py, pz, d, vertices, faces, lo, cell, dims, start, items, tmin):  # pragma: no cover
    """Whether the ray from (px, py, pz) along ``d`` meets a face past ``tmin``: the cells it
    crosses inside the grid's box, in order, each face tried where it is met."""
    t0, t1 = 0.0, np.inf
    p = (px, py, pz)
    for a in range(3):
        hi = lo[a] + dims[a] * cell
        if d[a] == 0.0:
            if p[a] < lo[a] or p[a] > hi:
                return False
        else:
            ta, tb = (lo[a] - p[a]) / d[a], (hi - p[a]) / d[a]
            if ta > tb:
                ta, tb = tb, ta
            t0, t1 = max(t0, ta), min(t1, tb)
    if t0 > t1:
        return False
    ci = np.empty(3, np.int64)
    step = np.empty(3, np.int64)
    tmax = np.empty(3, np.float64)
    tdelta = np.empty(3, np.float64)
    for a in range(3):
        x = p[a] + t0 * d[a]
        ci[a] = min(max(int(np.floor((x - lo[a]) / cell)), 0), dims[a] - 1)
        if d[a] > 0.0:
            step[a], tdelta[a] = 1, cell / d[a]
            tmax[a] = (lo[a] + (ci[a] + 1) * cell - p[a]) / d[a]
        elif d[a] < 0.0:
            step[a], tdelta[a] = -1, -cell / d[a]
            tmax[a] = (lo[a] + ci[a] * cell - p[a]) / d[a]
        else:
            step[a], tdelta[a], tmax[a] = 0, np.inf, np.inf
    while True:
        c = (ci[0] * dims[1] + ci[1]) * dims[2] + ci[2]
        for k in range(start[c], start[c + 1]):
            if _meets(px, py, pz, d[0], d[1], d[2], vertices, faces, items[k], tmin):
                return True
        a = 0
        if tmax[1] < tmax[a]:
            a = 1
        if tmax[2] < tmax[a]:
            a = 2
        if tmax[a] > t1:
            return False
        ci[a] += step[a]
        if ci[a] < 0 or ci[a] >= dims[a]:
            return False
        tmax[a] += tdelta[a]


@njit(cache=True, nogil=True)
def _hidden_kernel(  # pragma: no cover - compiled
    points, offsets, cursor, r2, d, vertices, faces, lo, cell, dims, start, items, tmin, out
):
    """One thread: the bear's 192,452 vertices against a 3,968-face occluder in 0.74-1.3 ms a
    move (``benchmarks/front_by_sight.py``; in parallel 12 ms on the loaded 2-core host, waking
    its threads)."""
    for s in range(offsets.size - 1):
        near, seen = False, False
        for i in range(offsets[s], offsets[s + 1]):
            px, py, pz = np.float64(points[i, 0]), np.float64(points[i, 1]), np.float64(points[i, 2])
            ex, ey, ez = px - cursor[0], py - cursor[1], pz - cursor[2]
            if ex * ex + ey * ey + ez * ez > r2:
                continue
            near = True
            if not _blocked(px, py, pz, d, vertices, faces, lo, cell, dims, start, items, tmin):
                seen = True
                break
        out[s] = near and not seen


def _toward_eye(view: ArrayLike) -> np.ndarray:
    v = np.asarray(view, np.float64)
    return -v / np.linalg.norm(v)


def hidden_strands(
    points: np.ndarray, offsets: np.ndarray, cursor: ArrayLike, radius: float, view: ArrayLike, grid: FaceGrid
) -> np.ndarray:
    """``(S,)`` the strands the head hides from a camera looking along ``view`` under a brush
    at ``cursor`` of ``radius`` (module docstring): a front-facing brush leaves them as if
    locked.

    Parameters
    ----------
    points : numpy.ndarray
        ``(V, 3)`` the groom's vertices (float32 or float64; compared in float64).
    offsets : numpy.ndarray
        ``(S + 1,)`` where each strand's vertices start.
    cursor : array_like
        ``(3,)`` the brush's centre.
    radius : float
        The brush's radius.
    view : array_like
        ``(3,)`` the camera's viewing direction (from the eye into the scene), not zero.
    grid : FaceGrid
        The head.

    Returns
    -------
    numpy.ndarray
        ``(S,)`` bool.
    """
    out = np.empty(len(offsets) - 1, np.bool_)
    _hidden_kernel(
        points, np.asarray(offsets, np.int64), np.asarray(cursor, np.float64), float(radius) ** 2,
        _toward_eye(view), grid.vertices, grid.faces, grid.lo, grid.cell, grid.dims, grid.start,
        grid.items, START * grid.size, out,
    )  # fmt: skip
    return out


def hidden_strands_reference(
    points: ArrayLike, offsets: np.ndarray, cursor: ArrayLike, radius: float, view: ArrayLike, grid: FaceGrid
) -> np.ndarray:
    """Numpy twin of :func:`hidden_strands`: every face tried for every vertex within reach."""
    p = np.asarray(points).astype(np.float64)
    e = p - np.asarray(cursor, np.float64)
    near = e[:, 0] * e[:, 0] + e[:, 1] * e[:, 1] + e[:, 2] * e[:, 2] <= float(radius) ** 2
    blocked = np.zeros(len(p), bool)
    blocked[near] = hidden_points_reference(p[near], view, grid)
    starts, filled = np.asarray(offsets[:-1], np.int64), np.diff(offsets) > 0
    if len(p) == 0:
        return np.zeros(len(starts), bool)
    any_near = np.logical_or.reduceat(near, starts) & filled
    any_seen = np.logical_or.reduceat(near & ~blocked, starts) & filled
    return any_near & ~any_seen


@njit(cache=True, nogil=True)
def _points_kernel(points, d, vertices, faces, lo, cell, dims, start, items, tmin, out):  # pragma: no cover
    for i in range(points.shape[0]):
        px, py, pz = np.float64(points[i, 0]), np.float64(points[i, 1]), np.float64(points[i, 2])
        out[i] = _blocked(px, py, pz, d, vertices, faces, lo, cell, dims, start, items, tmin)


def hidden_points(points: np.ndarray, view: ArrayLike, grid: FaceGrid) -> np.ndarray:
    """``(P,)`` the points ``(P, 3)`` the head hides from a camera looking along ``view``: the
    ray from each toward the eye meets a face of ``grid`` (the vertex a press starts a stroke
    on is one in sight)."""
    out = np.empty(len(points), np.bool_)
    _points_kernel(
        points, _toward_eye(view), grid.vertices, grid.faces, grid.lo, grid.cell, grid.dims,
        grid.start, grid.items, START * grid.size, out,
    )  # fmt: skip
    return out


def hidden_points_reference(points: ArrayLike, view: ArrayLike, grid: FaceGrid) -> np.ndarray:
    """Numpy twin of :func:`hidden_points`: every face tried for every point."""
    p = np.asarray(points).astype(np.float64)
    d = _toward_eye(view)
    v, f = grid.vertices, grid.faces
    a = v[f[:, 0]]
    e1, e2 = v[f[:, 1]] - a, v[f[:, 2]] - a
    q = np.stack([d[1] * e2[:, 2] - d[2] * e2[:, 1], d[2] * e2[:, 0] - d[0] * e2[:, 2],
                  d[0] * e2[:, 1] - d[1] * e2[:, 0]], axis=1)  # fmt: skip
    det = e1[:, 0] * q[:, 0] + e1[:, 1] * q[:, 1] + e1[:, 2] * q[:, 2]
    inv = np.divide(1.0, det, out=np.zeros_like(det), where=det != 0.0)
    tmin = START * grid.size
    out = np.zeros(len(p), bool)
    for i in range(len(p)):
        s = p[i] - a
        u = (s[:, 0] * q[:, 0] + s[:, 1] * q[:, 1] + s[:, 2] * q[:, 2]) * inv
        r = np.stack([s[:, 1] * e1[:, 2] - s[:, 2] * e1[:, 1], s[:, 2] * e1[:, 0] - s[:, 0] * e1[:, 2],
                      s[:, 0] * e1[:, 1] - s[:, 1] * e1[:, 0]], axis=1)  # fmt: skip
        w = (d[0] * r[:, 0] + d[1] * r[:, 1] + d[2] * r[:, 2]) * inv
        t = (e2[:, 0] * r[:, 0] + e2[:, 1] * r[:, 1] + e2[:, 2] * r[:, 2]) * inv
        inside = (u >= 0.0) & (u <= 1.0) & (w >= 0.0) & (u + w <= 1.0)
        out[i] = bool((inside & (det != 0.0) & (t > tmin)).any())
    return out
