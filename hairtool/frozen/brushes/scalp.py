"""The scalp as the brushes see it: its centre, the outward normal at each root, and which
strands face away from a camera (a front-facing sample leaves them as if locked).

Every kernel has a numpy twin (``*_reference``).
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange
from numpy.typing import ArrayLike, NDArray

from hairtool.frozen.brushes.falloff import EPS
from hairtool.groom import Groom
from hairtool.serial_twins import twin_njit

F64 = NDArray[np.float64]


def _sphere_centre(groom: Groom) -> F64 | None:
    """Centre of the sphere fitted to the roots (least squares, |x|² = 2c·x + k), or None where
    the roots do not determine one (fewer than 4, coplanar, or a sphere far larger than them)."""
    r = groom.roots.astype(np.float64)
    if len(r) < 4:
        return None
    a = np.column_stack([2.0 * r, np.ones(len(r))])
    b = np.einsum("ij,ij->i", r, r)
    sol, *_ = np.linalg.lstsq(a, b, rcond=None)
    centre = sol[:3]
    if not np.all(np.isfinite(centre)) or np.linalg.matrix_rank(a) < 4:
        return None
    return centre


def scalp_centre(groom: Groom) -> F64:
    """Centre of the sphere fitted to the roots (least squares, |x|² = 2c·x + k): the scalp's
    outward normal at a root points away from it; where the roots are coplanar (or fewer than
    4), a point below their centroid, along the scene's −up (its up axis, +y or +z)."""
    centre = _sphere_centre(groom)
    if centre is None:
        r = groom.roots.astype(np.float64)
        up = groom.metadata.up
        centre = r.mean(axis=0) - up * float(np.ptp(r @ up) + 1.0)
    return centre


PLANAR_RATIO = 100.0  # a fitted sphere this many times wider than the roots' extent: a flat scalp


def root_normals(groom: Groom) -> F64:
    """``(S, 3)`` unit outward scalp normal at each root, for front-facing brushes.

    On a head (the roots fit a sphere, as puff uses): away from the sphere's centre. A headless
    groom whose roots lie in a plane (or on a sphere over PLANAR_RATIO times wider than they
    are: numerically a plane) has one normal, the plane's, on the side its strands grow to (the
    mean root-to-tip direction): seen from that side every strand faces the camera, from
    behind none does. Roots on a line or a point (no plane): zero normals, so no strand ever
    faces away and front-facing changes nothing."""
    r = groom.roots.astype(np.float64)
    s = len(r)
    centre = _sphere_centre(groom)
    extent = float(np.ptp(r, axis=0).max()) if s else 0.0
    if centre is not None and np.linalg.norm(r - centre, axis=1).max() <= PLANAR_RATIO * extent:
        n = r - centre
        norm = np.linalg.norm(n, axis=1, keepdims=True)
        return np.divide(n, norm, out=np.zeros_like(n), where=norm > EPS)
    out = np.zeros((s, 3))
    if s < 3:
        return out
    _, sv, vt = np.linalg.svd(r - r.mean(axis=0), full_matrices=False)
    if sv[1] <= 1e-9 * max(sv[0], EPS):
        return out  # the roots lie on a line: no plane
    normal = vt[2]
    tips = groom.points[groom.topology.tip_indices].astype(np.float64)
    if float(np.mean(tips - r, axis=0) @ normal) < 0:
        normal = -normal
    out[:] = normal
    return out


@twin_njit(nogil=True, parallel=True)
def _facing_away_kernel(normals, view, out):  # pragma: no cover - compiled
    for s in prange(normals.shape[0]):
        out[s] = normals[s, 0] * view[0] + normals[s, 1] * view[1] + normals[s, 2] * view[2] > 0.0


def facing_away(normals: ArrayLike, view: ArrayLike) -> np.ndarray:
    """``(S,)`` the strands whose root normal faces away from a camera looking along ``view``
    (n·view > 0): a front-facing brush leaves them as if locked."""
    n = np.ascontiguousarray(normals, dtype=np.float64)
    out = np.empty(len(n), dtype=np.bool_)
    _facing_away_kernel(n, np.asarray(view, np.float64), out)
    return out


def facing_away_reference(normals: ArrayLike, view: ArrayLike) -> np.ndarray:
    """Numpy twin of :func:`facing_away`."""
    n = np.asarray(normals, np.float64)
    v = np.asarray(view, np.float64)
    return n[:, 0] * v[0] + n[:, 1] * v[1] + n[:, 2] * v[2] > 0.0


@njit(cache=True, nogil=True)
def _any_within_kernel(points, cx, cy, cz, r2):
    for i in range(points.shape[0]):
        ex = np.float64(points[i, 0]) - cx
        ey = np.float64(points[i, 1]) - cy
        ez = np.float64(points[i, 2]) - cz
        if ex * ex + ey * ey + ez * ez <= r2:
            return True
    return False


def any_within(points: np.ndarray, centre: ArrayLike, radius: float) -> bool:
    """Whether a vertex of ``points`` ``(V, 3)`` lies within ``radius`` of ``centre`` (float64
    differences): the press asks it of the whole groom, so it stops at the first one found and
    makes no array the groom's size (the numpy twin made four: 5-7 ms on the bear)."""
    c = np.asarray(centre, np.float64)
    return bool(_any_within_kernel(points, float(c[0]), float(c[1]), float(c[2]), float(radius) ** 2))


def any_within_reference(points: np.ndarray, centre: ArrayLike, radius: float) -> bool:
    """Numpy twin of :func:`any_within`."""
    d = np.asarray(points, np.float64) - np.asarray(centre, np.float64)
    return bool(np.any(np.einsum("ij,ij->i", d, d) <= float(radius) ** 2))
