"""The terms every segment cost is built from: the centred Gram matrix of the features, the
curvature term, the Hermite basis and tangent stencil, and the per-frame cost written plainly.

A segment between keys i < j costs, for each skipped frame k,
``e_k = |x_k − h_k|² + λ·|x_{k+1} − 2x_k + x_{k−1}|²`` (seed 000's curvature term), where h_k
is the linear (seed 000) or cubic Hermite (seed 003) interpolation of the keys at k; Hermite
tangents are m_c = (x_{c+1} − x_{c−1})/2 (one-sided at the sequence ends), time the parameter.
In the Gram matrix G = X̄X̄ᵀ of the centred features, ``e_k = G_kk − 2⟨x_k, h_k⟩ + |h_k|²`` and
h_k is a fixed combination of at most six frames, so every table (:mod:`.segment_linear`,
:mod:`.segment_hermite`, :mod:`.segment_worst`) reads G, never the features.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from hairtool.errors import ParameterError

F64 = NDArray[np.float64]

# Hermite basis as coefficients of 1, s, s², s³: h00, h10, h01, h11.
HERMITE_BASIS = np.array([[1, 0, -3, 2], [0, 1, -2, 1], [0, 0, 3, -2], [0, 0, -1, 1]], dtype=np.float64)


def centered_gram(x: F64, chunk_columns: int | None = None) -> F64:
    """``(n, n)`` float64 Gram matrix of the features minus their mean frame.

    Centring first keeps |x_k|² close to the size of the errors, so the expansion loses little
    to cancellation. Columns are centred and multiplied in chunks of max(1024, n) columns (no
    second copy of X); near-square blocks stay in cache, much wider ones ran up to 2x slower.

    Parameters
    ----------
    x : ndarray
        ``(n, D)`` features.
    chunk_columns : int, optional
        Columns per chunk (None: max(1024, n)).

    Returns
    -------
    ndarray
        ``(n, n)`` float64.
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
    """``(n,)`` |x_{k+1} − 2x_k + x_{k−1}|² in float64 (0 at the first and last frame).

    Parameters
    ----------
    x : ndarray
        ``(n, D)`` features.

    Returns
    -------
    ndarray
        ``(n,)`` float64.
    """
    x = np.asarray(x, dtype=np.float64)
    c = np.zeros(x.shape[0], dtype=np.float64)
    if x.shape[0] >= 3:
        dd = x[2:] - 2.0 * x[1:-1] + x[:-2]
        c[1:-1] = np.einsum("kd,kd->k", dd, dd)
    return c


def tangent_stencil(n: int) -> tuple[NDArray[np.int64], NDArray[np.int64], F64]:
    """m_c = w_c·(x_{hi_c} − x_{lo_c}): the averaged (one-sided at the ends) difference tangent.

    Parameters
    ----------
    n : int
        Frames.

    Returns
    -------
    tuple of (ndarray, ndarray, ndarray)
        ``lo``, ``hi`` and ``w``.
    """
    c = np.arange(n)
    lo = np.clip(c - 1, 0, n - 1)
    hi = np.clip(c + 1, 0, n - 1)
    w = np.where((c == 0) | (c == n - 1), 1.0, 0.5)
    return lo.astype(np.int64), hi.astype(np.int64), w


def check_gram(g: F64, curv: F64, lam: float) -> tuple[F64, F64]:
    """``g`` and ``curv`` as contiguous float64, or a ParameterError for a shape that does not
    fit or a bad λ.

    Parameters
    ----------
    g : ndarray
        ``(n, n)`` centred Gram matrix.
    curv : ndarray
        ``(n,)`` curvature terms.
    lam : float
        The curvature weight λ, ≥ 0.

    Returns
    -------
    tuple of (ndarray, ndarray)
        ``g`` and ``curv``.
    """
    g = np.ascontiguousarray(g, dtype=np.float64)
    if g.ndim != 2 or g.shape[0] != g.shape[1]:
        raise ParameterError("gram", f"shape {g.shape}", "a square (n, n) matrix")
    curv = np.ascontiguousarray(curv, dtype=np.float64)
    if curv.shape != (g.shape[0],):
        raise ParameterError("curvature", f"shape {curv.shape}", f"({g.shape[0]},)")
    if not np.isfinite(lam) or lam < 0:
        raise ParameterError("curvature", lam, "a finite weight >= 0")
    return g, curv


def frame_errors_reference(g: F64, curv: F64, lam: float, i: int, j: int, interp: str) -> F64:
    """Per-frame costs e_k, i < k < j, from the Gram matrix: the plain form both twins share.

    Parameters
    ----------
    g : ndarray
        ``(n, n)`` centred Gram matrix.
    curv : ndarray
        ``(n,)`` curvature terms.
    lam : float
        The curvature weight λ.
    i, j : int
        The keys, i < j.
    interp : str
        The curve.

    Returns
    -------
    ndarray
        ``(j − i − 1,)`` float64.
    """
    n = g.shape[0]
    k = np.arange(i + 1, j)
    el = float(j - i)
    s = (k - i) / el
    basis = HERMITE_BASIS @ np.stack([np.ones_like(s), s, s**2, s**3])  # (4, len(k))
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
