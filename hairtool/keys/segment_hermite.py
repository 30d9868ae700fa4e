"""Hermite segment costs (seed 003) from the Gram matrix: the kernel and its numpy twin.

h(s) = h00(s)·x_i + h10(s)·L·m_i + h01(s)·x_j + h11(s)·L·m_j with s = (k−i)/L, L = j − i and
m_c = w_c·(x_{hi_c} − x_{lo_c}) (:func:`hairtool.keys.gram.tangent_stencil`). Σ_k |h_k|² is
Σ_ab Q_ab(L)·⟨u_a, u_b⟩ with Q from closed-form power sums; the cross terms Σ_k ⟨x_k, h_k⟩ are
cubic moments Σ_k d^p·G_kc accumulated from i (columns near i) and from j (columns near j).
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange
from numpy.typing import NDArray

from hairtool.keys.gram import HERMITE_BASIS, frame_errors_reference

F64 = NDArray[np.float64]


def hermite_quad_weights(n: int) -> F64:
    """``(n, 4, 4)``: Q[L, a, b] = Σ_{d=1}^{L−1} P_a(d/L)·P_b(d/L) for the four Hermite basis P.

    Parameters
    ----------
    n : int
        Frames.

    Returns
    -------
    ndarray
        ``(n, 4, 4)`` float64.
    """
    d = np.arange(n, dtype=np.float64)
    sums = np.zeros((n, 7))
    for p in range(7):
        power = np.cumsum(d**p) - d**p  # Σ_{d'<L} d'^p, then drop d' = 0 below
        power -= 0.0**p
        with np.errstate(divide="ignore", invalid="ignore"):
            sums[:, p] = np.where(d > 0, power / np.maximum(d, 1.0) ** p, 0.0)
    q = np.zeros((n, 4, 4))
    for a in range(4):
        for b in range(4):
            conv = np.convolve(HERMITE_BASIS[a], HERMITE_BASIS[b])  # coefficients of s^0..s^6
            q[:, a, b] = sums @ conv
    return q


@njit(cache=True, nogil=True)
def stencil_at(c, n):  # pragma: no cover - compiled
    if c == 0:
        return 0, 1, 1.0
    if c == n - 1:
        return n - 2, n - 1, 1.0
    return c - 1, c + 1, 0.5


@njit(cache=True, nogil=True)
def hermite_quad_terms(g, i, j, n):  # pragma: no cover - compiled
    """⟨u_a, u_b⟩ for u = (x_i, L·m_i, x_j, L·m_j): (00, 01, 11, 02, 03, 12, 13, 22, 23, 33)."""
    li, hi, wi = stencil_at(i, n)
    lj, hj, wj = stencil_at(j, n)
    el = float(j - i)
    ti = el * wi
    tj = el * wj
    return (
        g[i, i],
        ti * (g[i, hi] - g[i, li]),
        ti * ti * (g[hi, hi] - 2.0 * g[hi, li] + g[li, li]),
        g[i, j],
        tj * (g[i, hj] - g[i, lj]),
        ti * (g[j, hi] - g[j, li]),
        ti * tj * (g[hi, hj] - g[hi, lj] - g[li, hj] + g[li, lj]),
        g[j, j],
        tj * (g[j, hj] - g[j, lj]),
        tj * tj * (g[hj, hj] - 2.0 * g[hj, lj] + g[lj, lj]),
    )


@njit(cache=True, nogil=True)
def _hermite_quad(g, q, i, j, n):  # pragma: no cover - compiled
    """Σ_k |h_k|² = Σ_ab Q_ab⟨u_a, u_b⟩ with Q from :func:`hermite_quad_weights`."""
    u = hermite_quad_terms(g, i, j, n)
    m = j - i
    return (
        q[m, 0, 0] * u[0]
        + q[m, 1, 1] * u[2]
        + q[m, 2, 2] * u[7]
        + q[m, 3, 3] * u[9]
        + 2.0 * (q[m, 0, 1] * u[1] + q[m, 0, 2] * u[3] + q[m, 0, 3] * u[4])
        + 2.0 * (q[m, 1, 2] * u[5] + q[m, 1, 3] * u[6] + q[m, 2, 3] * u[8])
    )


@njit(cache=True, nogil=True, parallel=True)
def _hermite_kernel(g, curv, lam, q):  # pragma: no cover - compiled
    n = g.shape[0]
    a = np.zeros((n, n))
    bt = np.zeros((n, n))
    for i in prange(n):
        li, hi, wi = stencil_at(i, n)
        a0 = a2 = a3 = 0.0  # Σ d^p G_ki, d = k − i
        t1 = t2 = t3 = 0.0  # Σ d^p (G_k,hi − G_k,lo)
        dsum = 0.0
        csum = 0.0
        for j in range(i + 2, n):
            k = j - 1
            d = float(k - i)
            gk = g[i, k]
            tk = g[hi, k] - g[li, k]
            a0 += gk
            a2 += d * d * gk
            a3 += d * d * d * gk
            t1 += d * tk
            t2 += d * d * tk
            t3 += d * d * d * tk
            dsum += g[k, k]
            csum += curv[k]
            il = 1.0 / (j - i)
            el = float(j - i)
            # Σ h00(s)G_ki + L·w_i·Σ h10(s)(G_k,hi − G_k,lo)
            cross = a0 - 3.0 * a2 * il * il + 2.0 * a3 * il * il * il
            cross += el * wi * (t1 * il - 2.0 * t2 * il * il + t3 * il * il * il)
            a[i, j] = dsum - 2.0 * cross + _hermite_quad(g, q, i, j, n) + lam * csum
    for j in prange(n):
        lj, hj, wj = stencil_at(j, n)
        b0 = b2 = b3 = 0.0  # Σ e^p G_kj, e = j − k, r = e/L = 1 − s
        v1 = v2 = v3 = 0.0
        for i in range(j - 2, -1, -1):
            k = i + 1
            e = float(j - k)
            gk = g[j, k]
            vk = g[hj, k] - g[lj, k]
            b0 += gk
            b2 += e * e * gk
            b3 += e * e * e * gk
            v1 += e * vk
            v2 += e * e * vk
            v3 += e * e * e * vk
            il = 1.0 / (j - i)
            el = float(j - i)
            # h01(s) = h00(r), h11(s) = −h10(r)
            cross = b0 - 3.0 * b2 * il * il + 2.0 * b3 * il * il * il
            cross -= el * wj * (v1 * il - 2.0 * v2 * il * il + v3 * il * il * il)
            bt[j, i] = -2.0 * cross
    for i in prange(n):
        for j in range(i + 2, n):
            a[i, j] += bt[j, i]
    return a


def hermite_table_reference(g: F64, curv: F64, lam: float = 0.0) -> F64:
    """Numpy twin of the Hermite kernel: per-pair sums of :func:`frame_errors_reference`.

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
    n = g.shape[0]
    out = np.zeros((n, n))
    for i in range(n):
        for j in range(i + 2, n):
            out[i, j] = frame_errors_reference(g, curv, lam, i, j, "hermite").sum()
    return out


def hermite_table(g: F64, curv: F64, lam: float = 0.0) -> F64:
    """``(n, n)`` Σ-of-frame-costs table for Hermite interpolation (numba).

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
    return _hermite_kernel(g, curv, float(lam), hermite_quad_weights(max(g.shape[0], 2)))
