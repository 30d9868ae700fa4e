"""Axis-angle rotations (Rodrigues' formula), batched over rows, in float64; the best rigid
motion between two point sets (:func:`rigid_fit`)."""

from __future__ import annotations

import numpy as np
from numba import njit
from numpy.typing import ArrayLike, NDArray

EPS = 1e-12


def normalize(v: ArrayLike, eps: float = EPS) -> NDArray[np.float64]:
    """Unit vectors along the rows of ``v``; rows shorter than ``eps`` stay zero."""
    a = np.asarray(v, dtype=np.float64)
    n = np.linalg.norm(a, axis=-1, keepdims=True)
    return np.where(n > eps, a / np.maximum(n, eps), 0.0)


def any_perpendicular(v: ArrayLike, frame: ArrayLike | None = None) -> NDArray[np.float64]:
    """A unit vector perpendicular to each row of ``v`` (a fixed, deterministic choice).

    ``frame``: a 3×3 rotation whose columns are the axes to choose from (a scene's axes,
    :attr:`hairtool.metadata.Metadata.frame`; default x, y, z), so that the same groom turned
    into another frame gets the same vectors, turned."""
    a = np.asarray(v, dtype=np.float64)
    if frame is not None:
        f = np.asarray(frame, dtype=np.float64)
        return any_perpendicular(a @ f) @ f.T
    # Cross with the coordinate axis least aligned with v: never near-parallel.
    helper = np.zeros_like(a)
    helper[np.arange(len(a)) if a.ndim == 2 else ..., np.argmin(np.abs(a), axis=-1)] = 1.0
    return normalize(np.cross(a, helper))


@njit(cache=True, nogil=True, inline="always")
def perpendicular_axis(vx, vy, vz):  # pragma: no cover - compiled
    """The unit vector :func:`any_perpendicular` picks for one vector (v × e_k, e_k the axis least
    aligned with v), for kernels; (0, 0, 1) for a zero vector."""
    k = 0
    if abs(vy) < abs(vx):
        k = 1
    if abs(vz) < min(abs(vx), abs(vy)):
        k = 2
    if k == 0:
        ax, ay, az = 0.0, vz, -vy
    elif k == 1:
        ax, ay, az = -vz, 0.0, vx
    else:
        ax, ay, az = vy, -vx, 0.0
    an = np.sqrt(ax * ax + ay * ay + az * az)
    if an > 0.0:
        return ax / an, ay / an, az / an
    return 0.0, 0.0, 1.0


def rotate(vectors: ArrayLike, axes: ArrayLike, angles: ArrayLike) -> NDArray[np.float64]:
    """Rotate each row of ``vectors`` about the unit row of ``axes`` by ``angles`` (radians).

    Rodrigues: v cosθ + (a × v) sinθ + a (a·v)(1 − cosθ). Shapes broadcast row-wise.
    """
    v = np.asarray(vectors, dtype=np.float64)
    a = np.asarray(axes, dtype=np.float64)
    th = np.asarray(angles, dtype=np.float64)[..., None]
    c, s = np.cos(th), np.sin(th)
    return v * c + np.cross(a, v) * s + a * np.sum(a * v, axis=-1, keepdims=True) * (1.0 - c)


def axis_angle_matrix(axis: ArrayLike, angle: float) -> NDArray[np.float64]:
    """3×3 rotation matrix about a unit ``axis`` by ``angle`` radians."""
    a = np.asarray(axis, dtype=np.float64)
    k = np.array([[0.0, -a[2], a[1]], [a[2], 0.0, -a[0]], [-a[1], a[0], 0.0]])
    return np.eye(3) + np.sin(angle) * k + (1.0 - np.cos(angle)) * (k @ k)


@njit(cache=True, nogil=True, inline="always")
def turn_between(vx, vy, vz, ax, ay, az, bx, by, bz):
    """v turned by the smallest rotation taking unit a to unit b (Rodrigues with k = a × b,
    c = a·b: v·c + k × v + k (k·v)/(1 + c)); a half turn (c ≈ −1) reflects across a instead."""
    c = ax * bx + ay * by + az * bz
    kx = ay * bz - az * by
    ky = az * bx - ax * bz
    kz = ax * by - ay * bx
    if 1.0 + c < 1e-12:
        d = vx * ax + vy * ay + vz * az
        return vx - 2.0 * d * ax, vy - 2.0 * d * ay, vz - 2.0 * d * az
    kv = (kx * vx + ky * vy + kz * vz) / (1.0 + c)
    return (
        vx * c + (ky * vz - kz * vy) + kx * kv,
        vy * c + (kz * vx - kx * vz) + ky * kv,
        vz * c + (kx * vy - ky * vx) + kz * kv,
    )


def rigid_fit(a: ArrayLike, b: ArrayLike) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """``(R, t)``: the rotation (3×3) and translation minimising Σ|R aᵢ + t − bᵢ|² over the rows
    (Kabsch, the Gram sum in float64); the centroids' translation alone where ``a`` lies on a
    line or a point (the turn about that line is not determined)."""
    a = np.asarray(a, np.float64).reshape(-1, 3)
    b = np.asarray(b, np.float64).reshape(-1, 3)
    ca, cb = a.mean(axis=0), b.mean(axis=0)
    p, q = a - ca, b - cb
    rot = np.eye(3)
    if len(a) >= 3:
        sv = np.linalg.svd(p, compute_uv=False)
        if sv[0] > 0 and sv[1] > 1e-9 * sv[0]:
            u, _, vt = np.linalg.svd(p.T @ q)
            d = np.sign(np.linalg.det(vt.T @ u.T)) or 1.0
            rot = vt.T @ np.diag([1.0, 1.0, d]) @ u.T
    return rot, cb - rot @ ca
