"""Hermite segments with fitted tangents ("hermite-fit"): free handles, as a Bezier key in a DCC.

Seed 003 takes each key's tangent from the data (the averaged neighbouring differences). Here
each segment (i, j) gets its own two end tangents, fitted by least squares to the frames between
its keys: with L = j − i, s_k = (k − i)/L and the Hermite basis h00, h10, h01, h11,

    h(s) = h00(s)·x_i + h01(s)·x_j + h10(s)·a + h11(s)·b,      a = L·m_i⁺, b = L·m_j⁻,

and the segment costs min over a, b of Σ_k |x_k − h(s_k)|² (+ seed 000's curvature term). The
tangents of two segments that meet at a key are independent (broken handles), so segments stay
separable and the DP stays exact over them. The data tangents are one choice of (a, b), so a
fitted segment never costs more than seed 003's.

With r_k = x_k − h00·x_i − h01·x_j, α_k = h10(s_k), β_k = h11(s_k), the minimum is
Σ|r_k|² − [R_a R_b]·M⁻¹·[R_a R_b]ᵀ, M = [[Σα², Σαβ], [Σαβ, Σβ²]] (the same for every
dimension), R_a = Σ α_k r_k, R_b = Σ β_k r_k. Every sum over k is a combination of the moment
vectors A_p = Σ_k (k − i)^p x_k, p ≤ 3, which grow by one frame as j does: O(D) per segment,
O(n²·D) per table, with no sum spanning more than its own segment. Features wider than the
frame count are first replaced by an n-column factor of their Gram matrix (the costs depend on
inner products only), so D never exceeds n.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange
from numpy.typing import ArrayLike, NDArray

from hairtool.errors import ParameterError
from hairtool.keys.gram import HERMITE_BASIS, tangent_stencil
from hairtool.keys.segment_hermite import hermite_quad_weights

F64 = NDArray[np.float64]


def fit_basis(n: int) -> F64:
    """``(n, 10)`` per segment length L: Σh00², Σh00h01, Σh01², Σαh00, Σαh01, Σβh00, Σβh01 and
    the inverse of M as (M⁻¹_aa, M⁻¹_ab, M⁻¹_bb); rows L < 3 hold zeros for M⁻¹ (one skipped
    frame is fitted exactly, none needs no fit).

    Parameters
    ----------
    n : int
        Frames.

    Returns
    -------
    ndarray
        ``(n, 10)`` float64.
    """
    q = hermite_quad_weights(max(n, 3))  # Q[L, a, b] over the basis (h00, h10, h01, h11)
    out = np.zeros((max(n, 3), 10))
    out[:, 0], out[:, 1], out[:, 2] = q[:, 0, 0], q[:, 0, 2], q[:, 2, 2]
    out[:, 3], out[:, 4], out[:, 5], out[:, 6] = q[:, 1, 0], q[:, 1, 2], q[:, 3, 0], q[:, 3, 2]
    maa, mab, mbb = q[:, 1, 1], q[:, 1, 3], q[:, 3, 3]
    det = maa * mbb - mab * mab
    ok = np.arange(out.shape[0]) >= 3
    out[ok, 7] = mbb[ok] / det[ok]
    out[ok, 8] = -mab[ok] / det[ok]
    out[ok, 9] = maa[ok] / det[ok]
    return out


def reduced_features(x: ArrayLike) -> F64:
    """The centred features, or, when they are wider than they are long, an ``(n, r)`` factor
    Y with Y·Yᵀ equal to their centred Gram matrix (r its rank, eigenvalues below 1e-13 of
    the largest dropped): every fitted cost depends on inner products only.

    Parameters
    ----------
    x : array_like
        ``(n, D)`` features.

    Returns
    -------
    ndarray
        ``(n, D)`` or ``(n, r)`` float64.
    """
    x = np.asarray(x, dtype=np.float64)
    xc = x - x.mean(axis=0)
    n, d = xc.shape
    if d <= n:
        return np.ascontiguousarray(xc)
    from hairtool.keys.gram import centered_gram

    vals, vecs = np.linalg.eigh(centered_gram(x))
    keep = vals > max(float(vals[-1]), 0.0) * 1e-13
    return np.ascontiguousarray(vecs[:, keep] * np.sqrt(vals[keep]))


@njit(cache=True, nogil=True)
def _fit_row(y, curv, lam, basis, i, out):  # pragma: no cover - compiled
    """out[j] = the fitted cost of segment (i, j) for every j > i + 1."""
    n, d = y.shape
    a0 = np.zeros(d)
    a1 = np.zeros(d)
    a2 = np.zeros(d)
    a3 = np.zeros(d)
    yi = y[i]
    gii = 0.0
    for c in range(d):
        gii += yi[c] * yi[c]
    dsum = 0.0  # Σ |x_k|²
    csum = 0.0  # Σ curvature
    for j in range(i + 2, n):
        k = j - 1
        yk = y[k]
        dk = float(k - i)
        dk2 = dk * dk
        dk3 = dk2 * dk
        gkk = 0.0
        for c in range(d):
            v = yk[c]
            a0[c] += v
            a1[c] += dk * v
            a2[c] += dk2 * v
            a3[c] += dk3 * v
            gkk += v * v
        dsum += gkk
        csum += curv[k]
        el = float(j - i)
        il = 1.0 / el
        il2 = il * il
        il3 = il2 * il
        yj = y[j]
        # one pass over the dimensions: every inner product the cost needs
        gij = gjj = 0.0
        p_i = p_j = 0.0  # ⟨x_i, Σh00·x⟩, ⟨x_j, Σh01·x⟩
        vaa = vab = vbb = vai = vaj = vbi = vbj = 0.0
        for c in range(d):
            xi_c, xj_c = yi[c], yj[c]
            h00 = a0[c] - 3.0 * a2[c] * il2 + 2.0 * a3[c] * il3  # Σ h00(s_k) x_k
            h01 = a0[c] - h00
            va = a1[c] * il - 2.0 * a2[c] * il2 + a3[c] * il3  # Σ α_k x_k
            vb = a3[c] * il3 - a2[c] * il2  # Σ β_k x_k
            gij += xi_c * xj_c
            gjj += xj_c * xj_c
            p_i += xi_c * h00
            p_j += xj_c * h01
            vaa += va * va
            vab += va * vb
            vbb += vb * vb
            vai += va * xi_c
            vaj += va * xj_c
            vbi += vb * xi_c
            vbj += vb * xj_c
        m = j - i
        s00, s01, s11 = basis[m, 0], basis[m, 1], basis[m, 2]
        ca0, ca1, cb0, cb1 = basis[m, 3], basis[m, 4], basis[m, 5], basis[m, 6]
        residual = dsum - 2.0 * (p_i + p_j) + s00 * gii + 2.0 * s01 * gij + s11 * gjj  # Σ |r_k|²
        if m >= 3:
            # R_a = Σαx − ca0·x_i − ca1·x_j, R_b likewise: their Gram entries from the sums above
            raa = vaa - 2.0 * (ca0 * vai + ca1 * vaj) + ca0 * ca0 * gii + 2.0 * ca0 * ca1 * gij
            raa += ca1 * ca1 * gjj
            rbb = vbb - 2.0 * (cb0 * vbi + cb1 * vbj) + cb0 * cb0 * gii + 2.0 * cb0 * cb1 * gij
            rbb += cb1 * cb1 * gjj
            rab = (
                vab
                - (cb0 * vai + cb1 * vaj)
                - (ca0 * vbi + ca1 * vbj)
                + ca0 * cb0 * gii
                + (ca0 * cb1 + ca1 * cb0) * gij
                + ca1 * cb1 * gjj
            )
            fitted = basis[m, 7] * raa + 2.0 * basis[m, 8] * rab + basis[m, 9] * rbb
            out[j] = max(residual - fitted, 0.0) + lam * csum
        else:  # one skipped frame: the handles fit it exactly
            out[j] = lam * csum


@njit(cache=True, nogil=True, parallel=True)
def _fit_kernel(y, curv, lam, basis):  # pragma: no cover - compiled
    # Row i costs ~(n − i)·D: each parallel step takes a row from each end, for equal work.
    n = y.shape[0]
    out = np.zeros((n, n))
    for step in prange(n // 2):
        _fit_row(y, curv, lam, basis, step, out[step])
        _fit_row(y, curv, lam, basis, n - 1 - step, out[n - 1 - step])
    if n % 2 == 1:
        _fit_row(y, curv, lam, basis, n // 2, out[n // 2])
    return out


def fit_table(x: ArrayLike, curv: ArrayLike, lam: float = 0.0) -> F64:
    """``(n, n)`` total cost of each segment with fitted Hermite tangents (numba); entries i < j
    meaningful. ``x``: ``(n, D)`` features; ``curv``: per-frame curvature terms, weighted by λ.

    Parameters
    ----------
    x : array_like
        ``(n, D)`` features.
    curv : array_like
        ``(n,)`` curvature terms.
    lam : float, default 0.0
        The curvature weight λ.

    Returns
    -------
    ndarray
        ``(n, n)`` float64.
    """
    y = reduced_features(x)
    curv = np.ascontiguousarray(curv, dtype=np.float64)
    if curv.shape != (y.shape[0],):
        raise ParameterError("curvature", f"shape {curv.shape}", f"({y.shape[0]},)")
    return _fit_kernel(y, curv, float(lam), fit_basis(y.shape[0]))


def fit_segment(x: ArrayLike, i: int, j: int) -> tuple[F64, F64, F64]:
    """``(a, b, residuals)`` of the least-squares handles of segment (i, j) of ``(n, D)`` frames,
    from the definition: ``a = L·m_i⁺``, ``b = L·m_j⁻``. One skipped frame: the exact fit
    closest to the data tangents; none: the data tangents.

    Parameters
    ----------
    x : array_like
        ``(n, D)`` frames.
    i, j : int
        The segment's keys, i < j.

    Returns
    -------
    tuple of (ndarray, ndarray, ndarray)
        The handles ``a`` and ``b`` and the skipped frames' residuals.
    """
    x = np.asarray(x, dtype=np.float64)
    n, el = x.shape[0], j - i
    lo, hi, w = (a[[i, j]] for a in tangent_stencil(n))
    a_data, b_data = el * w[:, None] * (x[hi] - x[lo])  # seed 003's, scaled by L
    k = np.arange(i + 1, j)
    s = (k - i) / el
    basis = HERMITE_BASIS @ np.stack([np.ones_like(s), s, s**2, s**3])  # h00, h10, h01, h11
    r = x[k] - basis[0][:, None] * x[i] - basis[2][:, None] * x[j]
    design = np.column_stack([basis[1], basis[3]])  # (L − 1, 2)
    if k.size == 0:
        return a_data, b_data, r
    if k.size == 1:
        alpha, beta = design[0]
        t = (r[0] - alpha * a_data - beta * b_data) / (alpha * alpha + beta * beta)
        a, b = a_data + alpha * t, b_data + beta * t
    else:
        (a, b), *_ = np.linalg.lstsq(design, r, rcond=None)
    return a, b, r - design[:, :1] * a - design[:, 1:] * b


def fit_table_reference(x: ArrayLike, curv: ArrayLike, lam: float = 0.0) -> F64:
    """Numpy twin of :func:`fit_table`: a least-squares solve per segment (O(n³·D): tests only).

    Parameters
    ----------
    x, curv, lam
        As :func:`fit_table` takes them.

    Returns
    -------
    ndarray
        ``(n, n)`` float64.
    """
    x = np.asarray(x, dtype=np.float64)
    curv = np.asarray(curv, dtype=np.float64)
    n = x.shape[0]
    out = np.zeros((n, n))
    for i in range(n):
        for j in range(i + 2, n):
            _, _, res = fit_segment(x, i, j)
            out[i, j] = float(np.sum(res * res)) + lam * float(curv[i + 1 : j].sum())
    return out
