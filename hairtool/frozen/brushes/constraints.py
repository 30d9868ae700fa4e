"""The constraint every length-keeping brush ends with: segments back to their lengths.

Follow-the-leader, root to tip (:func:`follow_lengths`): each vertex at its original distance
from the (already placed) one before, toward where the brush put it, so the vertices past a
moved one follow it. Comb, smooth and pinch end with one pass; snake hook runs rounds of it from
both ends (FABRIK, :func:`place`). Not :func:`hairtool.frozen.lengths.restore_lengths`, which
keeps each clumped segment's own direction and would pull a combed tip back.
"""

from __future__ import annotations

import numpy as np
from numba import njit
from numpy.typing import NDArray

from hairtool.frozen.brushes.falloff import EPS
from hairtool.frozen.brushes.twin_math import norm3

F64 = NDArray[np.float64]


@njit(cache=True, nogil=True)
def follow_lengths(q, p, o, n):  # pragma: no cover - compiled
    """q[o+1 .. o+n−1] pulled back, root to tip, to the segment lengths of p (in place): each
    vertex at its original distance from the one before, toward where q has it (the original
    direction where q collapses onto it)."""
    for i in range(o + 1, o + n):
        lx, ly, lz = p[i, 0] - p[i - 1, 0], p[i, 1] - p[i - 1, 1], p[i, 2] - p[i - 1, 2]
        length = np.sqrt(lx * lx + ly * ly + lz * lz)
        dx, dy, dz = q[i, 0] - q[i - 1, 0], q[i, 1] - q[i - 1, 1], q[i, 2] - q[i - 1, 2]
        d = np.sqrt(dx * dx + dy * dy + dz * dz)
        if d < EPS:
            dx, dy, dz, d = lx, ly, lz, length
        s = length / d if d >= EPS else 0.0
        q[i, 0] = q[i - 1, 0] + dx * s
        q[i, 1] = q[i - 1, 1] + dy * s
        q[i, 2] = q[i - 1, 2] + dz * s


def follow_lengths_reference(q: F64, p: F64) -> F64:
    """Numpy twin of :func:`follow_lengths` on one strand.

    Parameters
    ----------
    q : numpy.ndarray, ``(n, 3)`` float64
        The strand where the brush put it.
    p : numpy.ndarray, ``(n, 3)`` float64
        The strand before the brush: its segment lengths are kept.

    Returns
    -------
    numpy.ndarray
        ``(n, 3)`` the strand with its lengths back (a new array).
    """
    out = q.copy()
    for i in range(1, len(p)):
        seg = p[i] - p[i - 1]
        d = out[i] - out[i - 1]
        if norm3(d) < EPS:
            d = seg
        norm = norm3(d)
        out[i] = out[i - 1] + d * (norm3(seg) / norm if norm >= EPS else 0.0)
    return out


@njit(cache=True, nogil=True, inline="always")
def dist(p, i, j):  # pragma: no cover - compiled
    """|p[i] − p[j]| of two rows of ``p``."""
    dx, dy, dz = p[i, 0] - p[j, 0], p[i, 1] - p[j, 1], p[i, 2] - p[j, 2]
    return np.sqrt(dx * dx + dy * dy + dz * dz)


@njit(cache=True, nogil=True, inline="always")
def place(q, i, j, length, fx, fy, fz):  # pragma: no cover - compiled
    """q[i] at ``length`` from q[j], toward where q[i] is (along f where it sits on q[j])."""
    dx, dy, dz = q[i, 0] - q[j, 0], q[i, 1] - q[j, 1], q[i, 2] - q[j, 2]
    d = np.sqrt(dx * dx + dy * dy + dz * dz)
    if d < EPS:
        dx, dy, dz = fx, fy, fz
        d = np.sqrt(dx * dx + dy * dy + dz * dz)
    s = length / d if d >= EPS else 0.0
    q[i, 0] = q[j, 0] + dx * s
    q[i, 1] = q[j, 1] + dy * s
    q[i, 2] = q[j, 2] + dz * s


def place_reference(q: F64, i: int, j: int, length: float, fallback: F64) -> None:
    """Numpy twin of :func:`place` (in place on ``q``)."""
    d = q[i] - q[j]
    if norm3(d) < EPS:
        d = fallback
    n = norm3(d)
    q[i] = q[j] + d * (length / n if n >= EPS else 0.0)
