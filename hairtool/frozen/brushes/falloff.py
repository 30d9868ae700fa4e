"""The falloff a brush weighs its points by, and the weights every brush reads from it.

A falloff is a table of LUT_SIZE weights over t = distance / radius in [0, 1] (a preset: smooth,
linear, constant; or the artist's curve of [t, w] points), read linearly between its samples.
:func:`weight` is the per-point weight the kernels inline, :func:`weights_reference` its numpy
twin, :func:`end_weights` one point per strand (its root or its tip) weighed at once.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numba import njit, prange
from numpy.typing import ArrayLike, NDArray

from hairtool.errors import ParameterError

F64 = NDArray[np.float64]

FALLOFFS = ("smooth", "linear", "constant")
LUT_SIZE = 257  # samples of a falloff curve over [0, 1]: interpolated linearly between
MAX_FALLOFF_POINTS = 4 * LUT_SIZE  # a curve of more points than this says nothing more
EPS = 1e-12


def falloff_lut(falloff: str | Sequence[Sequence[float]]) -> F64:
    """``(LUT_SIZE,)`` weights over t = distance / radius in [0, 1]: a preset name, or curve
    points ``[[t, w], ...]`` (t increasing from 0 to 1, w in [0, 1]) joined by straight lines."""
    t = np.linspace(0.0, 1.0, LUT_SIZE)
    if isinstance(falloff, str):
        if falloff == "smooth":
            return 1.0 - t * t * (3.0 - 2.0 * t)  # smoothstep, 1 at the centre, 0 at the rim
        if falloff == "linear":
            return 1.0 - t
        if falloff == "constant":
            return np.ones_like(t)
        raise ParameterError("falloff", falloff, f"one of {', '.join(FALLOFFS)} or a list of [t, w] points")
    pts = _curve_points(falloff)
    if pts.shape[0] < 2:
        raise ParameterError("falloff", "curve", "at least two [t, w] points")
    if not np.all(np.isfinite(pts)) or np.any(np.diff(pts[:, 0]) <= 0):
        raise ParameterError("falloff", "curve", "finite points with t strictly increasing")
    if pts[0, 0] != 0.0 or pts[-1, 0] != 1.0 or np.any((pts[:, 1] < 0) | (pts[:, 1] > 1)):
        raise ParameterError("falloff", "curve", "t from 0 to 1 and weights in [0, 1]")
    return np.interp(t, pts[:, 0], pts[:, 1])


def _curve_points(falloff: object) -> F64:
    """``(n, 2)`` float64 curve points, the shape and every value checked before numpy sees
    them: a ragged curve, a huge one, a string or an integer beyond float64 is a ParameterError."""
    if isinstance(falloff, np.ndarray):
        if falloff.ndim != 2 or falloff.shape[1:] != (2,) or falloff.dtype.kind not in "fiu":
            raise ParameterError("falloff", "curve", "a list of [t, w] points")
        falloff = falloff.tolist()
    if not isinstance(falloff, Sequence) or isinstance(falloff, str | bytes):
        raise ParameterError("falloff", type(falloff).__name__, "a preset name or a list of [t, w] points")
    if len(falloff) > MAX_FALLOFF_POINTS:
        raise ParameterError("falloff", f"{len(falloff)} points", f"at most {MAX_FALLOFF_POINTS} points")
    for p in falloff:
        if isinstance(p, str | bytes) or not isinstance(p, Sequence | np.ndarray) or len(p) != 2:
            raise ParameterError("falloff", "curve", "[t, w] points of two numbers each")
        for v in p:
            if isinstance(v, bool) or not isinstance(v, int | float | np.integer | np.floating):
                raise ParameterError("falloff", "curve", "[t, w] points of two numbers each")
            if isinstance(v, int) and abs(v) > 1:  # t and w lie in [0, 1]: refused before float()
                raise ParameterError("falloff", "curve", "t from 0 to 1 and weights in [0, 1]")
    return np.array(falloff, dtype=np.float64).reshape(len(falloff), 2)


@njit(cache=True, nogil=True, inline="always")
def weight(px, py, pz, c, radius, lut):  # pragma: no cover - compiled
    """The falloff weight of the point (px, py, pz) for a brush at ``c``: the table ``lut``
    read at distance / ``radius`` (linear between its samples), 0 at the rim and beyond."""
    dx, dy, dz = px - c[0], py - c[1], pz - c[2]
    t = np.sqrt(dx * dx + dy * dy + dz * dz) / radius
    if t >= 1.0:
        return 0.0
    f = t * (lut.size - 1)
    k = min(int(f), lut.size - 2)
    a = f - k
    return lut[k] * (1.0 - a) + lut[k + 1] * a


def weights_reference(p: F64, c: F64, radius: float, lut: F64) -> F64:
    """Numpy twin of :func:`weight` over the rows of ``p`` ``(V, 3)``: ``(V,)`` weights."""
    t = np.linalg.norm(p - c, axis=1) / radius
    f = np.clip(t, 0.0, 1.0) * (lut.size - 1)
    k = np.minimum(f.astype(np.int64), lut.size - 2)
    a = f - k
    return np.where(t < 1.0, lut[k] * (1.0 - a) + lut[k + 1] * a, 0.0)


@njit(cache=True, nogil=True, parallel=True)
def _end_weights_kernel(ends, c, radius, strength, lut, locked, out):  # pragma: no cover - compiled
    for s in prange(ends.shape[0]):
        out[s] = 0.0 if locked[s] else weight(ends[s, 0], ends[s, 1], ends[s, 2], c, radius, lut) * strength


def end_weights(ends: ArrayLike, sample, locked: ArrayLike) -> F64:
    """Strength × falloff weight of one point per strand (numba).

    Parameters
    ----------
    ends : array_like, ``(S, 3)``
        One point per strand (its tip, its root).
    sample : BrushSample
        The brush sample: its cursor, radius, strength and falloff table.
    locked : array_like, ``(S,)`` bool
        Strands that get weight 0.

    Returns
    -------
    numpy.ndarray
        ``(S,)`` float64 weights.
    """
    ends = np.ascontiguousarray(ends, np.float64)
    out = np.empty(len(ends))
    _end_weights_kernel(
        ends, np.asarray(sample.cursor, np.float64), float(sample.radius), float(sample.strength),
        np.asarray(sample.lut, np.float64), np.asarray(locked, np.bool_), out,
    )  # fmt: skip
    return out


def end_weights_reference(ends: ArrayLike, sample, locked: ArrayLike) -> F64:
    """Numpy twin of :func:`end_weights`."""
    lut = np.asarray(sample.lut, np.float64)
    w = weights_reference(np.asarray(ends, np.float64), np.asarray(sample.cursor, np.float64),
                          sample.radius, lut) * sample.strength  # fmt: skip
    return np.where(np.asarray(locked, bool), 0.0, w)


def strand_weights_reference(points: ArrayLike, offsets: np.ndarray, sample) -> F64:
    """``(S,)`` the largest falloff weight over each strand's vertices (numpy): what the
    painting brushes (mask, select, clump) and length read."""
    c, lut = np.asarray(sample.cursor, np.float64), np.asarray(sample.lut, np.float64)
    w = weights_reference(np.asarray(points, np.float64), c, sample.radius, lut)
    return np.maximum.reduceat(w, offsets[:-1])
