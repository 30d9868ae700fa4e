"""Linear-interpolation segment costs (seed 000) from the Gram matrix: the kernel and its numpy twin.

Instead of rebuilding every skipped frame for every pair (O(n³D), kept as the oracle in
:mod:`hairtool.keys.segment_direct`), the sums over k of G_kc·(k−i)^p are prefix sums anchored
at i (and, for the columns near j, at j), so every entry costs O(1) after the O(n²D) product,
and no sum ever spans more than its own segment (no cancellation between long prefixes).
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange
from numpy.typing import NDArray

F64 = NDArray[np.float64]


@njit(cache=True, nogil=True, parallel=True)
def _linear_kernel(g, curv, lam):  # pragma: no cover - compiled
    n = g.shape[0]
    a = np.zeros((n, n))
    bt = np.zeros((n, n))
    # Pass A (row i, j growing): Σ G_kk, Σ(1 − s)G_ki and the |h|² terms.
    for i in prange(n):
        a0 = 0.0
        a1 = 0.0
        dsum = 0.0
        csum = 0.0
        for j in range(i + 2, n):
            k = j - 1
            gk = g[i, k]
            a0 += gk
            a1 += (k - i) * gk
            dsum += g[k, k]
            csum += curv[k]
            el = float(j - i)
            s1 = (el - 1.0) / 2.0  # Σ s
            s2 = (el - 1.0) * (2.0 * el - 1.0) / (6.0 * el)  # Σ s² = Σ (1 − s)²
            quad = s2 * g[i, i] + 2.0 * (s1 - s2) * g[i, j] + s2 * g[j, j]
            a[i, j] = dsum - 2.0 * (a0 - a1 / el) + quad + lam * csum
    # Pass B (column j, i falling): Σ s·G_kj with s = 1 − (j − k)/L.
    for j in prange(n):
        b0 = 0.0
        b1 = 0.0
        for i in range(j - 2, -1, -1):
            k = i + 1
            gk = g[j, k]
            b0 += gk
            b1 += (j - k) * gk
            bt[j, i] = -2.0 * (b0 - b1 / (j - i))
    for i in prange(n):
        for j in range(i + 2, n):
            a[i, j] += bt[j, i]
    return a


def linear_table_reference(g: F64, curv: F64, lam: float = 0.0) -> F64:
    """Numpy twin of the linear kernel, from global prefix sums (plain, less cancellation-proof).

    Parameters
    ----------
    g, curv, lam
        As :func:`linear_table` takes them.

    Returns
    -------
    ndarray
        ``(n, n)`` float64.
    """
    n = g.shape[0]
    k = np.arange(n, dtype=np.float64)
    p0 = np.zeros((n + 1, n))
    p1 = np.zeros((n + 1, n))
    p0[1:] = np.cumsum(g, axis=0)  # p0[k, c] = Σ_{k' < k} G[k', c]
    p1[1:] = np.cumsum(k[:, None] * g, axis=0)
    pd = np.concatenate([[0.0], np.cumsum(np.diag(g))])
    pc = np.concatenate([[0.0], np.cumsum(curv)])
    i, j = np.triu_indices(n, 2)
    el = (j - i).astype(np.float64)
    si = p0[j, i] - p0[i + 1, i]  # Σ_k G_ki over i < k < j
    di = (p1[j, i] - p1[i + 1, i]) - i * si  # Σ_k (k − i) G_ki
    sj = p0[j, j] - p0[i + 1, j]
    ej = j * sj - (p1[j, j] - p1[i + 1, j])  # Σ_k (j − k) G_kj
    s1 = (el - 1.0) / 2.0
    s2 = (el - 1.0) * (2.0 * el - 1.0) / (6.0 * el)
    quad = s2 * g[i, i] + 2.0 * (s1 - s2) * g[i, j] + s2 * g[j, j]
    out = np.zeros((n, n))
    out[i, j] = (
        (pd[j] - pd[i + 1]) - 2.0 * ((si - di / el) + (sj - ej / el)) + quad + lam * (pc[j] - pc[i + 1])
    )
    return out


def linear_table(g: F64, curv: F64, lam: float = 0.0) -> F64:
    """``(n, n)`` Σ-of-frame-costs table for linear interpolation (numba).

    Parameters
    ----------
    g : ndarray
        ``(n, n)`` centred Gram matrix.
    curv : ndarray
        ``(n,)`` curvature terms.
    lam : float, default 0.0
        The curvature weight λ.

    Returns
    -------
    ndarray
        ``(n, n)`` float64.
    """
    return _linear_kernel(g, curv, float(lam))
