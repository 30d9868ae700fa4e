"""Worst-frame segment tables: W[i, j] = max over skipped frames i < k < j of the frame cost e_k.

The objective of Salient Poses (Roberts et al. 2019): bound the worst frame instead of the sum.
A maximum does not split into prefix sums, so each entry visits its frames, but every frame
cost comes from the Gram matrix in O(1): O(n³) in all, independent of the feature size D.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange
from numpy.typing import NDArray

from hairtool.keys.gram import check_gram, frame_errors_reference
from hairtool.keys.segment_hermite import hermite_quad_terms, stencil_at

F64 = NDArray[np.float64]


@njit(cache=True, nogil=True, parallel=True)
def _worst_kernel(g, curv, lam, hermite):  # pragma: no cover - compiled
    n = g.shape[0]
    out = np.zeros((n, n))
    for i in prange(n):
        li, hi, wi = stencil_at(i, n)
        for j in range(i + 2, n):
            lj, hj, wj = stencil_at(j, n)
            el = float(j - i)
            u = hermite_quad_terms(g, i, j, n)
            worst = -np.inf
            for k in range(i + 1, j):
                s = (k - i) / el
                if hermite:
                    s2 = s * s
                    s3 = s2 * s
                    p0 = 1.0 - 3.0 * s2 + 2.0 * s3
                    p1 = s - 2.0 * s2 + s3
                    p2 = 3.0 * s2 - 2.0 * s3
                    p3 = s3 - s2
                    ti = el * wi * p1
                    tj = el * wj * p3
                    cross = (
                        p0 * g[k, i] + ti * (g[k, hi] - g[k, li]) + p2 * g[k, j] + tj * (g[k, hj] - g[k, lj])
                    )
                    # u = (u00, u01, u11, u02, u03, u12, u13, u22, u23, u33) with L·m scaled in
                    quad = (
                        p0 * p0 * u[0]
                        + p1 * p1 * u[2]
                        + p2 * p2 * u[7]
                        + p3 * p3 * u[9]
                        + 2.0 * (p0 * p1 * u[1] + p0 * p2 * u[3] + p0 * p3 * u[4])
                        + 2.0 * (p1 * p2 * u[5] + p1 * p3 * u[6] + p2 * p3 * u[8])
                    )
                else:
                    r = 1.0 - s
                    cross = r * g[k, i] + s * g[k, j]
                    quad = r * r * g[i, i] + 2.0 * r * s * g[i, j] + s * s * g[j, j]
                e = g[k, k] - 2.0 * cross + quad + lam * curv[k]
                if e > worst:
                    worst = e
            out[i, j] = worst
    return out


def worst_table_reference(g: F64, curv: F64, lam: float = 0.0, interp: str = "linear") -> F64:
    """Numpy twin of the worst-frame kernel (per-pair maxima of :func:`frame_errors_reference`)."""
    n = g.shape[0]
    out = np.zeros((n, n))
    for i in range(n):
        for j in range(i + 2, n):
            out[i, j] = frame_errors_reference(g, curv, lam, i, j, interp).max()
    return out


def worst_table(g: F64, curv: F64, lam: float = 0.0, interp: str = "linear", use_numba: bool = True) -> F64:
    """``(n, n)`` worst-frame table from a centred Gram matrix; entries i < j meaningful."""
    g, curv = check_gram(g, curv, lam)
    if not use_numba:
        return worst_table_reference(g, curv, lam, interp)
    return _worst_kernel(g, curv, float(lam), interp == "hermite")
