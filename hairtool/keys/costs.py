"""Segment cost tables for keyframe selection: C[i, j] is the cost of skipping frames i < k < j.

The total (Σ_k e_k) and worst-frame (max_k e_k) tables for linear and Hermite interpolation,
each in its own module over the shared terms of :mod:`hairtool.keys.gram`. Only entries i < j
are meaningful; the rest are 0.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from hairtool import budget
from hairtool.errors import ParameterError
from hairtool.keys.gram import centered_gram, check_gram, frame_curvature
from hairtool.keys.segment_fit import fit_table, fit_table_reference
from hairtool.keys.segment_hermite import hermite_table, hermite_table_reference
from hairtool.keys.segment_linear import linear_table, linear_table_reference
from hairtool.keys.segment_worst import worst_table

F64 = NDArray[np.float64]

#: linear (seed 000), Hermite with data tangents (seed 003), Hermite with fitted tangents
INTERPOLATIONS = ("linear", "hermite", "hermite-fit")
OBJECTIVES = ("total", "worst")
#: What a key search of n frames holds at once, in n × n float64 tables: the Gram matrix, the
#: segment table and the DP's copy of it. The frames are refused when these exceed the budget's
#: memory (:mod:`hairtool.budget`): a 22,750-frame capture (8.5 MB) asked for 3.9 GiB each.
TABLES = 3


def check_frame_count(n: int) -> int:
    """``n`` when its n × n tables fit the budget's memory, else one clear error (a hostile
    616-byte file can hold 50,000 frames of zeros, whose table alone is 18.6 GiB).

    Parameters
    ----------
    n : int
        Frames.

    Returns
    -------
    int
        ``n`` (a ParameterError past the limit).
    """
    most = int((budget.limit("memory") / (8 * TABLES)) ** 0.5)
    if n > most:
        gib = 8.0 * TABLES * n * n / 1024**3
        raise ParameterError(
            "frames", n, f"at most {most} frames at once (tables of {gib:.1f} GiB; hairtool --raise-limits)"
        )
    return n


def total_table(g: F64, curv: F64, lam: float = 0.0, interp: str = "linear", use_numba: bool = True) -> F64:
    """``(n, n)`` Σ-of-frame-costs table from a centred Gram matrix (see the module docstring).

    Parameters
    ----------
    g : ndarray
        ``(n, n)`` centred Gram matrix.
    curv : ndarray
        ``(n,)`` curvature terms.
    lam : float, default 0.0
        The curvature weight λ.
    interp : str, default "linear"
        The curve.
    use_numba : bool, default True
        False runs the numpy twin.

    Returns
    -------
    ndarray
        ``(n, n)`` float64.
    """
    g, curv = check_gram(g, curv, lam)
    if interp == "linear":
        return linear_table(g, curv, lam) if use_numba else linear_table_reference(g, curv, lam)
    if interp == "hermite":
        return hermite_table(g, curv, lam) if use_numba else hermite_table_reference(g, curv, lam)
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
    or O(n³) (worst) from the Gram matrix. Entries i < j are meaningful; the rest are 0.

    Parameters
    ----------
    x : ndarray
        ``(n, D)`` float64 frame features.
    interp : {"linear", "hermite", "hermite-fit"}, default "linear"
        The curve a segment is judged by.
    curvature : float, default 0.0
        Weight of the curvature term (≥ 0).
    objective : {"total", "worst"}, default "total"
        Sum over a segment's frames, or its worst frame.
    use_numba : bool, default True
        False runs the numpy twin (the tests' oracle).

    Returns
    -------
    ndarray
        ``(n, n)`` float64 costs; ``[i, j]`` for i < j is keying i and j and interpolating between.
    """
    if interp not in INTERPOLATIONS:
        raise ParameterError("interp", interp, " or ".join(INTERPOLATIONS))
    if objective not in OBJECTIVES:
        raise ParameterError("objective", objective, " or ".join(OBJECTIVES))
    if not np.isfinite(curvature) or curvature < 0:
        raise ParameterError("curvature", curvature, "a finite weight >= 0")
    check_frame_count(np.shape(x)[0])
    if interp == "hermite-fit":
        if objective != "total":
            raise ParameterError("objective", objective, "total with hermite-fit (least-squares handles)")
        curv = frame_curvature(x) if curvature > 0 else np.zeros(np.shape(x)[0])
        return fit_table(x, curv, curvature) if use_numba else fit_table_reference(x, curv, curvature)
    g = centered_gram(x)
    curv = frame_curvature(x) if curvature > 0 else np.zeros(g.shape[0])
    if objective == "worst":
        return worst_table(g, curv, curvature, interp, use_numba)
    return total_table(g, curv, curvature, interp, use_numba)
