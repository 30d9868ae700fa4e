"""The direct O(n³D) segment costs: rebuild every skipped frame of every pair from the features.

Slow on purpose and written from the definitions only (no Gram matrix, no prefix sums): the
test oracle for :mod:`hairtool.keys.costs` and the baseline its benchmark is timed against.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

F64 = NDArray[np.float64]


def difference_tangents(x: F64) -> F64:
    """m_c = ((x_c − x_{c−1}) + (x_{c+1} − x_c))/2, one-sided at the ends (seed 003).

    Parameters
    ----------
    x : ndarray
        ``(n, D)`` frames.

    Returns
    -------
    ndarray
        ``(n, D)`` float64.
    """
    x = np.asarray(x, dtype=np.float64)
    m = np.empty_like(x)
    m[0] = x[1] - x[0]
    m[-1] = x[-1] - x[-2]
    m[1:-1] = (x[2:] - x[:-2]) / 2.0
    return m


def interpolate_segment(x: F64, m: F64 | None, i: int, j: int, frames: NDArray) -> F64:
    """Frames at times ``frames`` rebuilt from keys i, j (Hermite when tangents m are given).

    Parameters
    ----------
    x : ndarray
        ``(n, D)`` frames.
    m : ndarray or None
        ``(n, D)`` tangents (None: linear).
    i, j : int
        The keys.
    frames : ndarray
        The frame numbers wanted.

    Returns
    -------
    ndarray
        ``(len(frames), D)`` float64.
    """
    el = float(j - i)
    s = ((np.asarray(frames, dtype=np.float64) - i) / el)[:, None]
    if m is None:
        return (1.0 - s) * x[i] + s * x[j]
    h00 = 2 * s**3 - 3 * s**2 + 1
    h10 = s**3 - 2 * s**2 + s
    h01 = -2 * s**3 + 3 * s**2
    h11 = s**3 - s**2
    return h00 * x[i] + h10 * el * m[i] + h01 * x[j] + h11 * el * m[j]


def direct_cost_table(
    x: F64, interp: str = "linear", curvature: float = 0.0, objective: str = "total"
) -> F64:
    """``(n, n)``: for every pair i < j, the skipped frames' costs summed (or their maximum).

    Parameters
    ----------
    x : ndarray
        ``(n, D)`` frames.
    interp : str, default "linear"
        The curve.
    curvature : float, default 0.0
        The curvature weight.
    objective : {"total", "worst"}, default "total"
        Sum or maximum.

    Returns
    -------
    ndarray
        ``(n, n)`` float64.
    """
    x = np.asarray(x, dtype=np.float64)
    n = x.shape[0]
    m = difference_tangents(x) if interp == "hermite" else None
    curv = np.zeros(n)
    if n >= 3:
        curv[1:-1] = np.sum((x[2:] - 2.0 * x[1:-1] + x[:-2]) ** 2, axis=1)
    out = np.zeros((n, n))
    for i in range(n):
        for j in range(i + 2, n):
            k = np.arange(i + 1, j)
            r = x[k] - interpolate_segment(x, m, i, j, k)
            e = np.sum(r * r, axis=1) + curvature * curv[k]
            out[i, j] = e.max() if objective == "worst" else e.sum()
    return out
