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

Rays never slip between faces: the test of a ray against a face is watertight (Woop, Benthin
and Wald's: every corner moved once into the ray's sheared frame, each edge's side from the
same products whichever face asks, its sign made exact where it rounds to 0, and a ray on an
edge or a corner counted as meeting every face there), and where the walk passes within
``SIDE`` of a cell's side, edge or corner it also tries the cells beyond, which it would
otherwise step past at a corner. So a point inside or behind a closed head is always hidden,
even from a view whose ray runs exactly through the head's vertices.

Rays go against the sample's ``view`` (an orthographic camera), or, given a perspective
camera's ``eye`` (a sample's ``eye``, which the studio records in its 3-D view), from each
vertex to the eye (and only faces before it hide).

:func:`hidden_strands` judges a brush sample's strands, :func:`hidden_points` single points
(the vertex a press starts a stroke on); each has a numpy twin (``*_reference``) that tries
every face for every vertex with the same float operations, so the same verdicts.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numba import njit
from numpy.typing import ArrayLike

from hairtool.kernel_arrays import readonly

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


#: a ray this share of a cell from a cell's side also tries the faces of the cells beyond it
SIDE = 1e-9

#: Veltkamp's splitter for float64 (2**27 + 1): a double into two halves whose products are exact
_SPLIT = 134217729.0


@njit(cache=True, nogil=True, inline="always")
def _product_error(a, b):  # pragma: no cover - compiled
    """a·b − fl(a·b) exactly (Dekker's two-product, without fused multiply-add)."""
    p = a * b
    c = _SPLIT * a
    ah = c - (c - a)
    al = a - ah
    c = _SPLIT * b
    bh = c - (c - b)
    bl = b - bh
    return ((ah * bh - p) + ah * bl + al * bh) + al * bl


@njit(cache=True, nogil=True, inline="always")
def _edge(ax, ay, bx, by):  # pragma: no cover - compiled
    """ax·by − ay·bx with its exact sign: rounding keeps the order of two products, so a
    nonzero float difference has the right sign, and where it is exactly 0 (the rounded
    products equal) the sign comes from their rounding errors (exact wherever neither product
    underflows: a head's coordinates are far from 1e-150). Swapping the two points negates
    it exactly, so two faces sharing an edge always judge the ray on opposite sides of it or
    both on it."""
    e = ax * by - ay * bx
    if e == 0.0:
        e = _product_error(ax, by) - _product_error(ay, bx)
    return e


@njit(cache=True, nogil=True, inline="always")
def face_det_t(o, kx, ky, kz, sx, sy, sz, vertices, faces, f):  # pragma: no cover - compiled
    """``(det, t · det)`` of the ray from ``o`` (in its frame, :func:`ray_frame`) against face
    ``f``, with ``det`` 0 where the ray passes outside the face or the face is edge-on: the
    watertight test's one computation, which :func:`_meets` and the first hit's walk judge."""
    a, b, c = faces[f, 0], faces[f, 1], faces[f, 2]
    az, bz, cz = vertices[a, kz] - o[kz], vertices[b, kz] - o[kz], vertices[c, kz] - o[kz]
    ax, ay = vertices[a, kx] - o[kx] - sx * az, vertices[a, ky] - o[ky] - sy * az
    bx, by = vertices[b, kx] - o[kx] - sx * bz, vertices[b, ky] - o[ky] - sy * bz
    cx, cy = vertices[c, kx] - o[kx] - sx * cz, vertices[c, ky] - o[ky] - sy * cz
    u, v, w = _edge(cx, cy, bx, by), _edge(ax, ay, cx, cy), _edge(bx, by, ax, ay)
    if (u < 0.0 or v < 0.0 or w < 0.0) and (u > 0.0 or v > 0.0 or w > 0.0):
        return 0.0, 0.0
    return u + v + w, sz * (u * az + v * bz + w * cz)


@njit(cache=True, nogil=True, inline="always")
def _meets(o, kx, ky, kz, sx, sy, sz, vertices, faces, f, tmin, far):  # pragma: no cover - compiled
    """Whether the ray from ``o`` meets face ``f`` at some tmin < t < far, watertight (Woop, Benthin
    and Wald 2013): the face's corners are moved to the ray's frame (:func:`ray_frame`) one
    corner at a time, so neighbouring faces see a shared corner at the same place, and each
    edge's side is :func:`_edge`'s. A ray through an edge or a corner meets a face there."""
    det, t = face_det_t(o, kx, ky, kz, sx, sy, sz, vertices, faces, f)
    if det == 0.0:
        return False
    if det > 0.0:
        return t > tmin * det and t < far * det
    return t < tmin * det and t > far * det


@njit(cache=True, nogil=True, inline="always")
def ray_frame(d):  # pragma: no cover - compiled (and called from python by the twins)
    """The frame :func:`_meets` takes for a ray along ``d``: the axes ``kx, ky, kz`` (the
    dominant one last, the other two in the order that keeps the faces' winding) and the shear
    ``sx, sy, sz`` taking the ray to that axis."""
    kz = 0
    if abs(d[1]) > abs(d[kz]):
        kz = 1
    if abs(d[2]) > abs(d[kz]):
        kz = 2
    kx, ky = (kz + 1) % 3, (kz + 2) % 3
    if d[kz] < 0.0:
        kx, ky = ky, kx
    return kx, ky, kz, d[kx] / d[kz], d[ky] / d[kz], 1.0 / d[kz]


@njit(cache=True, nogil=True, inline="always")
def _side(x, low, cell, i, n, tol):  # pragma: no cover - compiled
    """−1 or 1: ``x`` lies within ``tol`` of cell ``i``'s low or high side with a cell beyond
    (of ``n``); else 0."""
    if x - low <= tol and i > 0:
        return -1
    if low + cell - x <= tol and i < n - 1:
        return 1
    return 0


@njit(cache=True, nogil=True, inline="always")
def walk_start(o, d, lo, cell, dims, ci, step, tmax, tdelta):  # pragma: no cover - compiled
    """Where the ray from ``o`` along ``d`` is inside the grid's box, ``(t0, t1)`` (``t0 > t1``:
    it misses the box), and the walk's state at ``t0`` filled in (Amanatides and Woo): the cell
    ``ci``, each axis's ``step``, the ``t`` of its next side ``tmax`` and between sides
    ``tdelta``."""
    t0, t1 = 0.0, np.inf
    for a in range(3):
        hi = lo[a] + dims[a] * cell
        if d[a] == 0.0:
            if o[a] < lo[a] or o[a] > hi:
                return 1.0, 0.0
        else:
            ta, tb = (lo[a] - o[a]) / d[a], (hi - o[a]) / d[a]
            if ta > tb:
                ta, tb = tb, ta
            t0, t1 = max(t0, ta), min(t1, tb)
    if t0 > t1:
        return t0, t1
    for a in range(3):
        x = o[a] + t0 * d[a]
        ci[a] = min(max(int(np.floor((x - lo[a]) / cell)), 0), dims[a] - 1)
        if d[a] > 0.0:
            step[a], tdelta[a] = 1, cell / d[a]
            tmax[a] = (lo[a] + (ci[a] + 1) * cell - o[a]) / d[a]
        elif d[a] < 0.0:
            step[a], tdelta[a] = -1, -cell / d[a]
            tmax[a] = (lo[a] + ci[a] * cell - o[a]) / d[a]
        else:
            step[a], tdelta[a], tmax[a] = 0, np.inf, np.inf
    return t0, t1


@njit(cache=True, nogil=True, inline="always")
def next_side(tmax, t1):  # pragma: no cover - compiled
    """The axis whose cell side the walk crosses next (the nearest of ``tmax``), and whether the
    ray leaves the grid's box (past ``t1``) before it."""
    a = 0
    if tmax[1] < tmax[a]:
        a = 1
    if tmax[2] < tmax[a]:
        a = 2
    return a, tmax[a] > t1


@njit(cache=True, nogil=True, inline="always")
def _sides(o, d, t, ci, skip, lo, cell, dims, tol):  # pragma: no cover - compiled
    """Per axis (:func:`_side`), where the ray's point at ``t`` lies on cell ``ci``'s sides; 0
    across ``skip`` (the axis the walk itself crosses there)."""
    s0 = 0 if skip == 0 else _side(o[0] + t * d[0], lo[0] + ci[0] * cell, cell, ci[0], dims[0], tol)
    s1 = 0 if skip == 1 else _side(o[1] + t * d[1], lo[1] + ci[1] * cell, cell, ci[1], dims[1], tol)
    s2 = 0 if skip == 2 else _side(o[2] + t * d[2], lo[2] + ci[2] * cell, cell, ci[2], dims[2], tol)
    return s0, s1, s2


@njit(cache=True, nogil=True)
def _beside(s0, s1, s2, ci, frame, o, vertices, faces, dims, start, items, tmin, far):  # pragma: no cover
    """Whether the ray meets a face of the cells beyond cell ``ci`` across the sides ``s0, s1,
    s2`` (:func:`_sides`) that its point lies on, edges and corners included: rounding in the
    walk or in the binning cannot lose a face there."""
    kx, ky, kz, sx, sy, sz = frame
    for m0 in range(2 if s0 else 1):
        for m1 in range(2 if s1 else 1):
            for m2 in range(2 if s2 else 1):
                if m0 or m1 or m2:
                    c = ((ci[0] + m0 * s0) * dims[1] + ci[1] + m1 * s1) * dims[2] + ci[2] + m2 * s2
                    for n in range(start[c], start[c + 1]):
                        if _meets(o, kx, ky, kz, sx, sy, sz, vertices, faces, items[n], tmin, far):
                            return True
    return False


@njit(cache=True, nogil=True)
def _blocked(o, d, vertices, faces, lo, cell, dims, start, items, tmin, far):  # pragma: no cover
    """Whether the ray from ``o`` along the unit ``d`` meets a face between ``tmin`` and ``far``
    (the eye, or inf): the cells it crosses inside the grid's box, in order (Amanatides and
    Woo), each face tried where it is met, and where the ray passes within ``SIDE`` of a cell
    of a side, edge or corner, the cells beyond it too (:func:`_beside`: around the cell it
    leaves and the one it enters, which share the point's other sides)."""
    ci = np.empty(3, np.int64)
    step = np.empty(3, np.int64)
    tmax = np.empty(3, np.float64)
    tdelta = np.empty(3, np.float64)
    t0, t1 = walk_start(o, d, lo, cell, dims, ci, step, tmax, tdelta)
    t1 = min(t1, far)
    if t0 > t1:
        return False
    frame = ray_frame(d)
    kx, ky, kz, sx, sy, sz = frame
    tol = SIDE * cell
    s0, s1, s2 = _sides(o, d, t0, ci, -1, lo, cell, dims, tol)  # where the walk starts
    while True:
        c = (ci[0] * dims[1] + ci[1]) * dims[2] + ci[2]
        for n in range(start[c], start[c + 1]):
            if _meets(o, kx, ky, kz, sx, sy, sz, vertices, faces, items[n], tmin, far):
                return True
        near = s0 != 0 or s1 != 0 or s2 != 0  # the point the walk entered by
        if near and _beside(s0, s1, s2, ci, frame, o, vertices, faces, dims, start, items, tmin, far):
            return True
        a, leaves = next_side(tmax, t1)
        s0, s1, s2 = _sides(o, d, t1 if leaves else tmax[a], ci, -1 if leaves else a, lo, cell, dims, tol)
        near = s0 != 0 or s1 != 0 or s2 != 0  # the point it leaves by (the next cell's entry)
        if near and _beside(s0, s1, s2, ci, frame, o, vertices, faces, dims, start, items, tmin, far):
            return True
        if leaves:
            return False
        ci[a] += step[a]
        if ci[a] < 0 or ci[a] >= dims[a]:
            return False
        tmax[a] += tdelta[a]


@njit(cache=True, nogil=True, inline="always")
def _ray(o, d, px, py, pz, toward, eye, persp):  # pragma: no cover - compiled
    """Fill ``o`` and the unit ``d`` of the ray from (px, py, pz) toward the camera; its reach
    (the eye's distance, inf for a camera looking along one direction; 0 for a point at the
    eye, which nothing hides)."""
    o[0], o[1], o[2] = px, py, pz
    if not persp:
        d[0], d[1], d[2] = toward[0], toward[1], toward[2]
        return np.inf
    dx, dy, dz = eye[0] - px, eye[1] - py, eye[2] - pz
    reach = np.sqrt(dx * dx + dy * dy + dz * dz)
    if reach > 0.0:
        d[0], d[1], d[2] = dx / reach, dy / reach, dz / reach
    return reach


@njit(cache=True, nogil=True)
def _hidden_kernel(  # pragma: no cover - compiled
    points, offsets, cursor, r2, toward, eye, persp, vertices, faces, lo, cell, dims, start, items, tmin, out
):
    """One thread: the bear's 192,452 vertices against a 3,968-face occluder in 0.74-1.3 ms a
    move (``benchmarks/front_by_sight.py``; in parallel 12 ms on the loaded 2-core host, waking
    its threads)."""
    o = np.empty(3, np.float64)
    d = np.empty(3, np.float64)
    for s in range(offsets.size - 1):
        near, seen = False, False
        for i in range(offsets[s], offsets[s + 1]):
            px, py, pz = np.float64(points[i, 0]), np.float64(points[i, 1]), np.float64(points[i, 2])
            ex, ey, ez = px - cursor[0], py - cursor[1], pz - cursor[2]
            if ex * ex + ey * ey + ez * ez > r2:
                continue
            near = True
            far = _ray(o, d, px, py, pz, toward, eye, persp)
            if far == 0.0 or not _blocked(o, d, vertices, faces, lo, cell, dims, start, items, tmin, far):
                seen = True
                break
        out[s] = near and not seen


def _toward_eye(view: ArrayLike) -> np.ndarray:
    v = np.asarray(view, np.float64)
    return -v / np.linalg.norm(v)


def _camera(view: ArrayLike, eye: ArrayLike | None) -> tuple[np.ndarray, np.ndarray, bool]:
    """The kernels' camera: the direction toward it, its eye point and whether rays go there."""
    if eye is None:
        return _toward_eye(view), np.zeros(3), False
    return np.zeros(3), np.asarray(eye, np.float64).reshape(3), True


def hidden_strands(
    points: np.ndarray,
    offsets: np.ndarray,
    cursor: ArrayLike,
    radius: float,
    view: ArrayLike,
    grid: FaceGrid,
    eye: ArrayLike | None = None,
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
    eye : array_like, optional
        ``(3,)`` a perspective camera's eye: each ray goes from its vertex to it (``view`` then
        unused). None: every ray goes against ``view`` (an orthographic camera).

    Returns
    -------
    numpy.ndarray
        ``(S,)`` bool.
    """
    toward, at, persp = _camera(view, eye)
    out = np.empty(len(offsets) - 1, np.bool_)
    # read-only inputs: one compilation per dtype, whoever made them
    _hidden_kernel(
        readonly(points), readonly(np.asarray(offsets, np.int64)), np.asarray(cursor, np.float64),
        float(radius) ** 2,
        toward, at, persp, grid.vertices, grid.faces, grid.lo, grid.cell, grid.dims, grid.start,
        grid.items, START * grid.size, out,
    )  # fmt: skip
    return out


def hidden_strands_reference(
    points: ArrayLike,
    offsets: np.ndarray,
    cursor: ArrayLike,
    radius: float,
    view: ArrayLike,
    grid: FaceGrid,
    eye: ArrayLike | None = None,
) -> np.ndarray:
    """Numpy twin of :func:`hidden_strands`: every face tried for every vertex within reach."""
    p = np.asarray(points).astype(np.float64)
    e = p - np.asarray(cursor, np.float64)
    near = e[:, 0] * e[:, 0] + e[:, 1] * e[:, 1] + e[:, 2] * e[:, 2] <= float(radius) ** 2
    blocked = np.zeros(len(p), bool)
    blocked[near] = hidden_points_reference(p[near], view, grid, eye)
    starts, filled = np.asarray(offsets[:-1], np.int64), np.diff(offsets) > 0
    if len(p) == 0:
        return np.zeros(len(starts), bool)
    any_near = np.logical_or.reduceat(near, starts) & filled
    any_seen = np.logical_or.reduceat(near & ~blocked, starts) & filled
    return any_near & ~any_seen


@njit(cache=True, nogil=True)
def _points_kernel(  # pragma: no cover - compiled
    points, toward, eye, persp, vertices, faces, lo, cell, dims, start, items, tmin, out
):
    o = np.empty(3, np.float64)
    d = np.empty(3, np.float64)
    for i in range(points.shape[0]):
        px, py, pz = np.float64(points[i, 0]), np.float64(points[i, 1]), np.float64(points[i, 2])
        far = _ray(o, d, px, py, pz, toward, eye, persp)
        out[i] = far > 0.0 and _blocked(o, d, vertices, faces, lo, cell, dims, start, items, tmin, far)


def hidden_points(
    points: np.ndarray, view: ArrayLike, grid: FaceGrid, eye: ArrayLike | None = None
) -> np.ndarray:
    """``(P,)`` the points ``(P, 3)`` the head hides from a camera looking along ``view`` (or,
    given a perspective camera's ``eye``, from that point): the ray from each toward the eye
    meets a face of ``grid`` (the vertex a press starts a stroke on is one in sight)."""
    toward, at, persp = _camera(view, eye)
    out = np.empty(len(points), np.bool_)
    # read-only points: one compilation per dtype (a box's float64 copies, a groom's own)
    _points_kernel(
        readonly(points), toward, at, persp, grid.vertices, grid.faces, grid.lo, grid.cell, grid.dims,
        grid.start, grid.items, START * grid.size, out,
    )  # fmt: skip
    return out


def _product_error_numpy(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """:func:`_product_error` on arrays."""
    p = a * b
    c = _SPLIT * a
    ah = c - (c - a)
    al = a - ah
    c = _SPLIT * b
    bh = c - (c - b)
    bl = b - bh
    return ((ah * bh - p) + ah * bl + al * bh) + al * bl


def _edge_numpy(ax: np.ndarray, ay: np.ndarray, bx: np.ndarray, by: np.ndarray) -> np.ndarray:
    """:func:`_edge` on arrays."""
    e = ax * by - ay * bx
    tie = e == 0.0
    e[tie] = _product_error_numpy(ax[tie], by[tie]) - _product_error_numpy(ay[tie], bx[tie])
    return e


def hidden_points_reference(
    points: ArrayLike, view: ArrayLike, grid: FaceGrid, eye: ArrayLike | None = None
) -> np.ndarray:
    """Numpy twin of :func:`hidden_points`: every face tried for every point."""
    p = np.asarray(points).astype(np.float64)
    v, f = grid.vertices, grid.faces
    tmin = START * grid.size
    out = np.zeros(len(p), bool)
    for i in range(len(p)):
        if eye is None:
            d, far = _toward_eye(view), np.inf
        else:
            d = np.asarray(eye, np.float64).reshape(3) - p[i]
            far = np.sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2])
            if far == 0.0:
                continue  # the point is the eye: nothing hides it
            d = d / far
        kx, ky, kz, sx, sy, sz = ray_frame(d)
        o = p[i]
        z = [v[f[:, j], kz] - o[kz] for j in range(3)]
        x = [v[f[:, j], kx] - o[kx] - sx * z[j] for j in range(3)]
        y = [v[f[:, j], ky] - o[ky] - sy * z[j] for j in range(3)]
        u = _edge_numpy(x[2], y[2], x[1], y[1])
        w = _edge_numpy(x[0], y[0], x[2], y[2])
        q = _edge_numpy(x[1], y[1], x[0], y[0])
        det = u + w + q
        t = sz * (u * z[0] + w * z[1] + q * z[2])
        with np.errstate(invalid="ignore"):
            ahead = np.where(
                det > 0.0, (t > tmin * det) & (t < far * det), (t < tmin * det) & (t > far * det)
            )
        mixed = ((u < 0.0) | (w < 0.0) | (q < 0.0)) & ((u > 0.0) | (w > 0.0) | (q > 0.0))
        out[i] = bool((~mixed & (det != 0.0) & ahead).any())
    return out
