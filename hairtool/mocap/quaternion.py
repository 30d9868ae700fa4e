"""Unit quaternions ``(w, x, y, z)`` for joint rotations, batched over leading axes, in float64.

Conventions: a quaternion q rotates a column vector v as ``q v q⁻¹``; ``multiply(a, b)`` is the
rotation "first b, then a" (like the matrix product A·B). Euler angles follow BVH: the channels
are intrinsic rotations applied in the listed order, so for order "ZXY" the rotation is
R = R_z · R_x · R_y.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from hairtool.errors import ParameterError

F64 = NDArray[np.float64]

_AXIS = {"X": 0, "Y": 1, "Z": 2}


def _check_order(order: str) -> str:
    o = order.upper()
    if len(o) == 0 or any(c not in _AXIS for c in o):
        raise ParameterError("order", order, "a string of the axes X, Y, Z such as 'ZXY'")
    return o


def identity(shape: tuple[int, ...] = ()) -> F64:
    """Identity rotations ``[1, 0, 0, 0]`` (w first).

    Parameters
    ----------
    shape : tuple of int, default ()
        The leading shape.

    Returns
    -------
    ndarray
        ``(*shape, 4)`` float64.
    """
    q = np.zeros((*shape, 4))
    q[..., 0] = 1.0
    return q


def normalize(q: ArrayLike) -> F64:
    """Quaternions scaled to unit length (a zero one stays zero).

    Parameters
    ----------
    q : array_like
        ``(..., 4)`` quaternions.

    Returns
    -------
    ndarray
        ``(..., 4)`` float64.
    """
    a = np.asarray(q, dtype=np.float64)
    n = np.linalg.norm(a, axis=-1, keepdims=True)
    return a / np.maximum(n, 1e-300)


def conjugate(q: ArrayLike) -> F64:
    """The inverse of a unit quaternion.

    Parameters
    ----------
    q : array_like
        ``(..., 4)`` unit quaternions.

    Returns
    -------
    ndarray
        ``(..., 4)`` float64.
    """
    a = np.array(q, dtype=np.float64, copy=True)
    a[..., 1:] *= -1.0
    return a


inverse = conjugate


def multiply(a: ArrayLike, b: ArrayLike) -> F64:
    """Hamilton product a ⊗ b (broadcast over leading axes).

    Parameters
    ----------
    a, b : array_like
        ``(..., 4)`` quaternions.

    Returns
    -------
    ndarray
        ``(..., 4)`` float64.
    """
    a = np.asarray(a, dtype=np.float64)
    b = np.asarray(b, dtype=np.float64)
    aw, ax, ay, az = np.moveaxis(a, -1, 0)
    bw, bx, by, bz = np.moveaxis(b, -1, 0)
    return np.stack(
        [
            aw * bw - ax * bx - ay * by - az * bz,
            aw * bx + ax * bw + ay * bz - az * by,
            aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw,
        ],
        axis=-1,
    )


def from_axis_angle(axis: ArrayLike, angle: ArrayLike) -> F64:
    """Rotation by ``angle`` radians about the unit ``axis``.

    Parameters
    ----------
    axis : array_like
        ``(..., 3)`` unit axes.
    angle : array_like
        ``(...)`` angles in radians.

    Returns
    -------
    ndarray
        ``(..., 4)`` float64.
    """
    ax = np.asarray(axis, dtype=np.float64)
    half = 0.5 * np.asarray(angle, dtype=np.float64)[..., None]
    return np.concatenate([np.cos(half), np.sin(half) * ax], axis=-1)


def from_euler(angles: ArrayLike, order: str, degrees: bool = True) -> F64:
    """``(..., k)`` angles, one per letter of ``order``, → ``(..., 4)``: q = q_c1 ⊗ q_c2 ⊗ … (intrinsic).

    Parameters
    ----------
    angles : array_like
        ``(..., k)`` angles.
    order : str
        k axis letters, e.g. "ZXY".
    degrees : bool, default True
        The angles are degrees (else radians).

    Returns
    -------
    ndarray
        ``(..., 4)`` float64.
    """
    o = _check_order(order)
    a = np.asarray(angles, dtype=np.float64)
    if a.shape[-1] != len(o):
        raise ParameterError("angles", a.shape, f"a last axis of {len(o)} angles for order {order!r}")
    if degrees:
        a = np.radians(a)
    q = identity(a.shape[:-1])
    for k, c in enumerate(o):
        half = 0.5 * a[..., k]
        r = np.zeros((*a.shape[:-1], 4))
        r[..., 0] = np.cos(half)
        r[..., 1 + _AXIS[c]] = np.sin(half)
        q = multiply(q, r)
    return q


def to_matrix(q: ArrayLike) -> F64:
    """``(..., 4)`` → ``(..., 3, 3)`` rotation matrices (q need not be exactly unit).

    Parameters
    ----------
    q : array_like
        ``(..., 4)`` quaternions.

    Returns
    -------
    ndarray
        ``(..., 3, 3)`` float64.
    """
    w, x, y, z = np.moveaxis(normalize(q), -1, 0)
    m = np.empty((*w.shape, 3, 3))
    m[..., 0, 0] = 1 - 2 * (y * y + z * z)
    m[..., 0, 1] = 2 * (x * y - w * z)
    m[..., 0, 2] = 2 * (x * z + w * y)
    m[..., 1, 0] = 2 * (x * y + w * z)
    m[..., 1, 1] = 1 - 2 * (x * x + z * z)
    m[..., 1, 2] = 2 * (y * z - w * x)
    m[..., 2, 0] = 2 * (x * z - w * y)
    m[..., 2, 1] = 2 * (y * z + w * x)
    m[..., 2, 2] = 1 - 2 * (x * x + y * y)
    return m


def rotate(q: ArrayLike, v: ArrayLike) -> F64:
    """Rotate vectors ``(..., 3)`` by quaternions ``(..., 4)`` (broadcast): q v q⁻¹.

    Parameters
    ----------
    q : array_like
        ``(..., 4)`` unit quaternions.
    v : array_like
        ``(..., 3)`` vectors.

    Returns
    -------
    ndarray
        ``(..., 3)`` float64.
    """
    q = np.asarray(q, dtype=np.float64)
    v = np.asarray(v, dtype=np.float64)
    u = q[..., 1:]
    w = q[..., :1]
    t = 2.0 * np.cross(u, v)
    return v + w * t + np.cross(u, t)


def _euler_from_matrix(m: F64, order: str) -> F64:
    """Angles (radians) for a three-letter order with three distinct axes (Tait–Bryan)."""
    i, j, k = (_AXIS[c] for c in order)
    # R = R_i(a) R_j(b) R_k(c); parity of the permutation (i, j, k) gives the signs.
    sign = 1.0 if (j - i) % 3 == 1 else -1.0
    s = np.clip(sign * m[..., i, k], -1.0, 1.0)
    b = np.arcsin(s)
    a = np.arctan2(-sign * m[..., j, k], m[..., k, k])
    c = np.arctan2(-sign * m[..., i, j], m[..., i, i])
    # Gimbal lock (|sin b| = 1): fold the whole i/k rotation into a, c = 0.
    lock = np.abs(s) > 1.0 - 1e-12
    if np.any(lock):
        a_lock = np.arctan2(sign * m[..., k, j], m[..., j, j])
        a = np.where(lock, a_lock, a)
        c = np.where(lock, 0.0, c)
    return np.stack([a, b, c], axis=-1)


def to_euler(q: ArrayLike, order: str, degrees: bool = True) -> F64:
    """Inverse of :func:`from_euler` for three distinct axes (e.g. "ZXY"); angles in (−180°, 180°].

    Parameters
    ----------
    q : array_like
        ``(..., 4)`` unit quaternions.
    order : str
        Three distinct axis letters.
    degrees : bool, default True
        Give degrees (else radians).

    Returns
    -------
    ndarray
        ``(..., 3)`` float64 angles.
    """
    o = _check_order(order)
    if len(o) != 3 or len(set(o)) != 3:
        raise ParameterError("order", order, "three distinct axes such as 'ZXY'")
    out = _euler_from_matrix(to_matrix(q), o)
    return np.degrees(out) if degrees else out


def align_hemisphere(q: ArrayLike, axis: int = 0) -> F64:
    """Flip signs along ``axis`` (time) so consecutive quaternions have a non-negative dot product.

    q and −q are the same rotation; aligned sequences interpolate the short way and can be
    compared component-wise.

    Parameters
    ----------
    q : array_like
        Quaternions, 4 components on the last axis.
    axis : int, default 0
        The time axis.

    Returns
    -------
    ndarray
        The aligned quaternions, float64.
    """
    a = np.moveaxis(np.array(q, dtype=np.float64, copy=True), axis, 0)
    if a.shape[0] > 1:
        dots = np.sum(a[1:] * a[:-1], axis=-1)
        flips = np.cumsum(dots < 0.0, axis=0) % 2
        a[1:] *= np.where(flips == 1, -1.0, 1.0)[..., None]
    return np.moveaxis(a, 0, axis)


def distance(q1: ArrayLike, q2: ArrayLike) -> F64:
    """Seed 003's Dist(q1, q2) = arccos(|w|) with [w, x, y, z] = q2 q1⁻¹ (radians, in [0, π/2]).

    For unit quaternions w of q2 q1⁻¹ equals the 4-D dot product q1·q2; |w| picks the shorter of
    q and −q. This is half the rotation angle between the two orientations.

    Parameters
    ----------
    q1, q2 : array_like
        ``(..., 4)`` unit quaternions.

    Returns
    -------
    ndarray
        ``(...)`` float64 radians.
    """
    q1 = np.asarray(q1, dtype=np.float64)
    q2 = np.asarray(q2, dtype=np.float64)
    return np.arccos(np.clip(np.abs(np.sum(q1 * q2, axis=-1)), 0.0, 1.0))


def slerp(q1: ArrayLike, q2: ArrayLike, t: ArrayLike) -> F64:
    """Spherical linear interpolation along the shorter arc; t = 0 gives q1, t = 1 gives q2 (or −q2).

    Parameters
    ----------
    q1, q2 : array_like
        ``(..., 4)`` unit quaternions.
    t : array_like
        ``(...)`` shares in [0, 1].

    Returns
    -------
    ndarray
        ``(..., 4)`` float64 unit quaternions.
    """
    a = np.asarray(q1, dtype=np.float64)
    b = np.asarray(q2, dtype=np.float64)
    t = np.asarray(t, dtype=np.float64)[..., None]
    d = np.sum(a * b, axis=-1, keepdims=True)
    b = np.where(d < 0.0, -b, b)
    d = np.abs(d)
    theta = np.arccos(np.clip(d, -1.0, 1.0))
    s = np.sin(theta)
    small = s < 1e-9
    safe = np.where(small, 1.0, s)
    wa = np.where(small, 1.0 - t, np.sin((1.0 - t) * theta) / safe)
    wb = np.where(small, t, np.sin(t * theta) / safe)
    return normalize(wa * a + wb * b)
