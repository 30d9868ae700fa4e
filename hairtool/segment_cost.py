"""Segment cost tables for keyframe selection: C[i, j] is the cost of skipping frames i < k < j.

A segment between keys i < j costs Σ_k e_k with, for each skipped frame k,
``e_k = |x_k − h_k|² + λ·|x_{k+1} − 2x_k + x_{k−1}|²`` (seed 000's curvature term), where h_k
is the linear (seed 000) or cubic Hermite (seed 003) interpolation of the keys at k; Hermite
tangents are m_c = (x_{c+1} − x_{c−1})/2 (one-sided at the sequence ends), time the parameter.

Instead of rebuilding every skipped frame for every pair (O(n³D), kept as the oracle in
:mod:`hairtool.segment_direct`), the cost is expanded in the Gram matrix G = X̄X̄ᵀ of the
centred features: ``e_k = G_kk − 2⟨x_k, h_k⟩ + |h_k|²`` and h_k is a fixed combination of at
most six frames with polynomial weights in s = (k−i)/(j−i). The sums over k of G_kc·(k−i)^p
are prefix sums anchored at i (and, for the columns near j, at j), so every entry costs O(1)
after the O(n²D) product, and no sum ever spans more than its own segment (no cancellation
between long prefixes). Only entries i < j are meaningful; the rest are 0.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange
from numpy.typing import NDArray

from hairtool.errors import ParameterError

F64 = NDArray[np.float64]

INTERPOLATIONS = ("linear", "hermite")
OBJECTIVES = ("total", "worst")

# Hermite basis as coefficients of 1, s, s², s³: h00, h10, h01, h11.
_HERMITE = np.array([[1, 0, -3, 2], [0, 1, -2, 1], [0, 0, 3, -2], [0, 0, -1, 1]], dtype=np.float64)


def centered_gram(x: F64, chunk_columns: int | None = None) -> F64:
    """``(n, n)`` float64 Gram matrix of the features minus their mean frame.

    Centring first keeps |x_k|² close to the size of the errors, so the expansion loses little
    to cancellation. Columns are centred and multiplied in chunks of max(1024, n) columns (no
    second copy of X); near-square blocks stay in cache, much wider ones ran up to 2x slower.
    """
    x = np.asarray(x)
    n, d = x.shape
    mean = x.mean(axis=0, dtype=np.float64)
    g = np.zeros((n, n), dtype=np.float64)
    width = max(1, min(d, int(chunk_columns or max(1024, n))))
    buf = np.empty((n, width), dtype=np.float64)
    for c0 in range(0, d, width):
        w = min(width, d - c0)
        xc = buf if w == width else np.empty((n, w), dtype=np.float64)
        np.subtract(x[:, c0 : c0 + w], mean[c0 : c0 + w], out=xc)  # one pass, in float64
        g += xc @ xc.T  # numpy uses a symmetric rank-k update (syrk) for a @ a.T
    return g


def frame_curvature(x: F64) -> F64:
    """``(n,)`` |x_{k+1} − 2x_k + x_{k−1}|² in float64 (0 at the first and last frame)."""
    x = np.asarray(x, dtype=np.float64)
    c = np.zeros(x.shape[0], dtype=np.float64)
    if x.shape[0] >= 3:
        dd = x[2:] - 2.0 * x[1:-1] + x[:-2]
        c[1:-1] = np.einsum("kd,kd->k", dd, dd)
    return c


def tangent_stencil(n: int) -> tuple[NDArray[np.int64], NDArray[np.int64], F64]:
    """m_c = w_c·(x_{hi_c} − x_{lo_c}): the averaged (one-sided at the ends) difference tangent."""
    c = np.arange(n)
    lo = np.clip(c - 1, 0, n - 1)
    hi = np.clip(c + 1, 0, n - 1)
    w = np.where((c == 0) | (c == n - 1), 1.0, 0.5)
    return lo.astype(np.int64), hi.astype(np.int64), w


def _check(g: F64, curv: F64, lam: float) -> tuple[F64, F64]:
    g = np.ascontiguousarray(g, dtype=np.float64)
    if g.ndim != 2 or g.shape[0] != g.shape[1]:
        raise ParameterError("gram", f"shape {g.shape}", "a square (n, n) matrix")
    curv = np.ascontiguousarray(curv, dtype=np.float64)
    if curv.shape != (g.shape[0],):
        raise ParameterError("curvature", f"shape {curv.shape}", f"({g.shape[0]},)")
    if not np.isfinite(lam) or lam < 0:
        raise ParameterError("curvature", lam, "a finite weight >= 0")
    return g, curv


# -- linear ---------------------------------------------------------------------------------
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


def linear_table_numpy(g: F64, curv: F64, lam: float = 0.0) -> F64:
    """Numpy twin of the linear kernel, from global prefix sums (plain, less cancellation-proof)."""
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


def frame_errors_numpy(g: F64, curv: F64, lam: float, i: int, j: int, interp: str) -> F64:
    """Per-frame costs e_k, i < k < j, from the Gram matrix: the plain form both twins share."""
    n = g.shape[0]
    k = np.arange(i + 1, j)
    el = float(j - i)
    s = (k - i) / el
    basis = _HERMITE @ np.stack([np.ones_like(s), s, s**2, s**3])  # (4, len(k))
    if interp == "linear":
        refs, coef = [i, j], [1.0 - s, s]
    else:
        lo, hi, w = tangent_stencil(n)
        refs = [i, hi[i], lo[i], j, hi[j], lo[j]]
        ti, tj = el * w[i] * basis[1], el * w[j] * basis[3]
        coef = [basis[0], ti, -ti, basis[2], tj, -tj]
    refs = np.asarray(refs)
    alpha = np.stack(coef)  # (r, len(k))
    cross = np.einsum("rk,kr->k", alpha, g[np.ix_(k, refs)])
    quad = np.einsum("rk,rt,tk->k", alpha, g[np.ix_(refs, refs)], alpha)
    return g[k, k] - 2.0 * cross + quad + lam * curv[k]


def total_table(g: F64, curv: F64, lam: float = 0.0, interp: str = "linear", use_numba: bool = True) -> F64:
    """``(n, n)`` Σ-of-frame-costs table from a centred Gram matrix (see the module docstring)."""
    g, curv = _check(g, curv, lam)
    if interp == "linear":
        return _linear_kernel(g, curv, float(lam)) if use_numba else linear_table_numpy(g, curv, lam)
    if interp == "hermite":
        from hairtool.segment_hermite import _hermite_kernel, hermite_quad_weights, hermite_table_numpy

        if not use_numba:
            return hermite_table_numpy(g, curv, lam)
        return _hermite_kernel(g, curv, float(lam), hermite_quad_weights(max(g.shape[0], 2)))
    raise ParameterError("interp", interp, " or ".join(INTERPOLATIONS))


def cost_table(
    x: F64,
    interp: str = "linear",
    curvature: float = 0.0,
    objective: str = "total",
    *,
    use_numba: bool = True,
) -> F64:
    """``(n, n)`` segment costs of ``(n, D)`` features: O(n²D) Gram product, then O(n²) (total)
    or O(n³) (worst) from the Gram matrix. Entries i < j are meaningful; the rest are 0."""
    if interp not in INTERPOLATIONS:
        raise ParameterError("interp", interp, " or ".join(INTERPOLATIONS))
    if objective not in OBJECTIVES:
        raise ParameterError("objective", objective, " or ".join(OBJECTIVES))
    if not np.isfinite(curvature) or curvature < 0:
        raise ParameterError("curvature", curvature, "a finite weight >= 0")
    g = centered_gram(x)
    curv = frame_curvature(x) if curvature > 0 else np.zeros(g.shape[0])
    if objective == "worst":
        from hairtool.segment_worst import worst_table

        return worst_table(g, curv, curvature, interp, use_numba)
    return total_table(g, curv, curvature, interp, use_numba)
