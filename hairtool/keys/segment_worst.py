"""Worst-frame segment tables: W[i, j] = max over skipped frames i < k < j of the frame cost e_k.

The objective of Salient Poses (Roberts et al. 2019): bound the worst frame instead of the sum.
A maximum does not split into prefix sums, so each entry visits its frames, but every frame
cost comes from the Gram matrix in O(1): O(n³) in all, independent of the feature size D.
"""

from __future__ import annotations

import numpy as np
from numba import get_num_threads, njit, prange
from numpy.typing import NDArray

from hairtool.kernel_arrays import borrowed
from hairtool.keys.gram import check_gram, frame_errors_reference
from hairtool.keys.segment_hermite import hermite_quad_terms, stencil_at

F64 = NDArray[np.float64]


@njit(cache=True, nogil=True, parallel=True)
def _worst_kernel(g, curv, lam, hermite, n_hands):  # pragma: no cover - compiled
    # Row i costs ~(n − i)²/2: rows are dealt like cards (i ≡ c mod n_hands), one hand per thread,
    # so the threads get equal work to within a row, and each row is one thread's, whatever the
    # thread count.
    n = g.shape[0]
    out = np.zeros((n, n))
    base = np.empty(n)
    diag = np.empty(n)
    for k in range(n):
        diag[k] = g[k, k]
        base[k] = g[k, k] + lam * curv[k]
    # Per hand, the rows' scratch (1/(j − i), and the Hermite terms): arguments of the row, so
    # alive while it borrows them.
    inv = np.zeros((n_hands, n))
    u = np.empty((n_hands, 10, n) if hermite else (n_hands, 10, 0))
    for c in prange(n_hands):
        for i in range(c, n, n_hands):
            _worst_row(g, base, diag, hermite, i, out[i], inv[c], u[c])
    return out


@njit(cache=True, nogil=True)
def _worst_row(g, base, diag, hermite, i, w, inv, u):  # pragma: no cover - compiled
    """w[j] = W[i, j] for every j > i + 1, skipped frame by skipped frame: for each k, the cost
    of frame k in every segment (i, j > k) at once, kept where it is the largest so far.

    The loop over j reads rows of G (symmetric: G[k, j] is row k), needs no reduction and runs
    the length of the row, so it vectorises; the maximum is exact in any order, so the table is
    the numpy twin's whatever the loop order. Its per-frame views are of borrowed arrays: both
    threads slicing G had fought over its reference count (:mod:`hairtool.kernel_arrays`).
    """
    n = g.shape[0]
    g, base, diag, w = borrowed(g), borrowed(base), borrowed(diag), borrowed(w)
    inv, u = borrowed(inv), borrowed(u)
    gi = g[i]
    for j in range(i + 2, n):
        inv[j] = 1.0 / (j - i)
        w[j] = -np.inf
    if not hermite:
        gii = gi[i]
        for k in range(i + 1, n - 1):
            gk = g[k]
            a, gik = base[k], gi[k]
            di = float(k - i)
            _linear_span(w, gi, gk, diag, inv, a, gii, gik, di, k + 1, n)
        return
    # Hermite: per j, the ten ⟨u_a, u_b⟩ of hermite_quad_terms; the end tangent's stencil is
    # (j − 1, j + 1, 1/2) but at the last frame, which gets its own pass so the loop stays plain
    for j in range(i + 2, n):
        t = hermite_quad_terms(g, i, j, n)
        for m in range(10):
            u[m, j] = t[m]
    li, hi, wi = stencil_at(i, n)
    last = n - 1
    lj, hj, wj = stencil_at(last, n)
    for k in range(i + 1, last):
        gk = g[k]
        a, gki, gkt = base[k], gk[i], gk[hi] - gk[li]
        di = float(k - i)
        _hermite_span(w, gk, inv, u, a, gki, gkt, di, i, wi, k + 1, last)
        e = _hermite_frame_cost(
            a, gki, gkt, gk[last], gk[hj] - gk[lj], di * inv[last], float(last - i), wi, wj,
            u[0, last], u[1, last], u[2, last], u[3, last], u[4, last],
            u[5, last], u[6, last], u[7, last], u[8, last], u[9, last],
        )  # fmt: skip
        w[last] = max(w[last], e)


@njit(cache=True, nogil=True, inline="always")
def _linear_span(w, gi, gk, diag, inv, a, gii, gik, di, lo, hi):  # pragma: no cover - compiled
    """w[j] = max(w[j], e_k of the linear segment (i, j)) for lo ≤ j < hi, on views from ``lo``."""
    ww, g_i, g_k, dg, iv = w[lo:hi], gi[lo:hi], gk[lo:hi], diag[lo:hi], inv[lo:hi]
    for t in range(hi - lo):
        s = di * iv[t]
        r = 1.0 - s
        quad = r * r * gii + 2.0 * r * s * g_i[t] + s * s * dg[t]
        ww[t] = max(ww[t], a - 2.0 * (r * gik + s * g_k[t]) + quad)


@njit(cache=True, nogil=True, inline="always")
def _hermite_span(w, gk, inv, u, a, gki, gkt, di, i, wi, lo, hi):  # pragma: no cover - compiled
    """w[j] = max(w[j], e_k of the segment (i, j)) for lo ≤ j < hi (interior ends: stencil 1/2).

    :func:`_hermite_frame_cost` over views that start at ``lo``: plain non-negative
    indices into 1-D arrays, which the compiler turns into SIMD lanes (indexing the 2-D ``u``
    and ``gk[j ± 1]`` directly kept the loop scalar)."""
    m = hi - lo
    if m <= 0:
        return
    ww, g0, gp, gm, iv = w[lo:hi], gk[lo:hi], gk[lo + 1 : hi + 1], gk[lo - 1 : hi - 1], inv[lo:hi]
    u0, u1, u2, u3, u4 = u[0, lo:hi], u[1, lo:hi], u[2, lo:hi], u[3, lo:hi], u[4, lo:hi]
    u5, u6, u7, u8, u9 = u[5, lo:hi], u[6, lo:hi], u[7, lo:hi], u[8, lo:hi], u[9, lo:hi]
    first = float(lo - i)
    for t in range(m):
        e = _hermite_frame_cost(
            a, gki, gkt, g0[t], gp[t] - gm[t], di * iv[t], first + t, wi, 0.5,
            u0[t], u1[t], u2[t], u3[t], u4[t], u5[t], u6[t], u7[t], u8[t], u9[t],
        )  # fmt: skip
        ww[t] = max(ww[t], e)


@njit(cache=True, nogil=True, inline="always")
def _hermite_frame_cost(  # pragma: no cover - compiled
    a, gki, gkt, gkj, gkt_j, s, el, wi, wj, u0, u1, u2, u3, u4, u5, u6, u7, u8, u9
):
    """e_k of the Hermite segment (i, j) at s = (k − i)/L, L = ``el``, from G's row k (gki =
    G[k, i], gkt = G[k, hi] − G[k, li], the same at j) and the ten ⟨u_a, u_b⟩ of the segment
    (u00, u01, u11, u02, u03, u12, u13, u22, u23, u33, with L·m scaled in). Scalars only, so the
    loop that calls it over views stays vectorised."""
    s2 = s * s
    s3 = s2 * s
    p0 = 1.0 - 3.0 * s2 + 2.0 * s3
    p1 = s - 2.0 * s2 + s3
    p2 = 3.0 * s2 - 2.0 * s3
    p3 = s3 - s2
    ti = el * wi * p1
    tj = el * wj * p3
    cross = p0 * gki + ti * gkt + p2 * gkj + tj * gkt_j
    quad = (
        p0 * p0 * u0
        + p1 * p1 * u2
        + p2 * p2 * u7
        + p3 * p3 * u9
        + 2.0 * (p0 * p1 * u1 + p0 * p2 * u3 + p0 * p3 * u4)
        + 2.0 * (p1 * p2 * u5 + p1 * p3 * u6 + p2 * p3 * u8)
    )
    return a - 2.0 * cross + quad


def worst_table_reference(g: F64, curv: F64, lam: float = 0.0, interp: str = "linear") -> F64:
    """Numpy twin of the worst-frame kernel (per-pair maxima of :func:`frame_errors_reference`).

    Parameters
    ----------
    g, curv, lam, interp
        As :func:`worst_table` takes them.

    Returns
    -------
    ndarray
        ``(n, n)`` float64.
    """
    n = g.shape[0]
    out = np.zeros((n, n))
    for i in range(n):
        for j in range(i + 2, n):
            out[i, j] = frame_errors_reference(g, curv, lam, i, j, interp).max()
    return out


def worst_table(g: F64, curv: F64, lam: float = 0.0, interp: str = "linear", use_numba: bool = True) -> F64:
    """``(n, n)`` worst-frame table from a centred Gram matrix; entries i < j meaningful.

    Parameters
    ----------
    g : ndarray
        ``(n, n)`` centred Gram matrix.
    curv : ndarray
        ``(n,)`` curvature terms.
    lam : float, default 0.0
        The curvature weight λ.
    interp : {"linear", "hermite"}, default "linear"
        The curve.
    use_numba : bool, default True
        False runs the numpy twin.

    Returns
    -------
    ndarray
        ``(n, n)`` float64.
    """
    g, curv = check_gram(g, curv, lam)
    if not use_numba:
        return worst_table_reference(g, curv, lam, interp)
    n_hands = max(1, min(g.shape[0], get_num_threads()))
    return _worst_kernel(g, curv, float(lam), interp == "hermite", n_hands)
