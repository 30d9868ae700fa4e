"""BasisCurves arithmetic without usd-core: which vertex counts a basis accepts, and primvars of any
interpolation spread to one value per control point.

USD's curve primvars come in four interpolations (the "Curve Data Interpolation" section of the
UsdGeomBasisCurves schema): ``constant`` (one value), ``uniform`` (one per curve), ``vertex``
(one per control point) and ``varying`` (one per segment end: for a cubic curve fewer than its
control points). hairtool keeps one value per control point, so ``varying`` values are placed at
the control point where each segment ends (for B-spline and Catmull-Rom, the points the curve
passes nearest) and interpolated linearly along the strand between them, held at its ends.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

I64 = NDArray[np.int64]


def fits(counts: I64, basis: str, wrap: str) -> bool:
    """Whether every curve has a vertex count the basis can draw (e.g. 4 + 3k for a bezier).

    Parameters
    ----------
    counts : ndarray
        Each curve's vertex count.
    basis : str
        The curves' basis (``linear``, ``bezier``, ``bspline``, ``catmullRom``).
    wrap : str
        Their wrap (``nonperiodic``, ``periodic``, ``pinned``).

    Returns
    -------
    bool
        True where every curve fits.
    """
    n = np.asarray(counts, dtype=np.int64)
    if basis == "linear":
        return bool(np.all(n >= 2))
    if basis == "bezier":
        if wrap == "periodic":
            return bool(np.all((n >= 3) & (n % 3 == 0)))
        return bool(np.all((n >= 4) & ((n - 4) % 3 == 0)))
    if wrap == "pinned":
        return bool(np.all(n >= 2))
    return bool(np.all(n >= (3 if wrap == "periodic" else 4)))


def varying_layout(counts: I64, basis: str, wrap: str) -> tuple[I64, I64, I64]:
    """Per curve: the control point of its first varying value, the step between them, and how many.

    The counts must fit the basis (:func:`fits`).

    Parameters
    ----------
    counts, basis, wrap
        As :func:`fits` takes them.

    Returns
    -------
    tuple of (ndarray, ndarray, ndarray)
        Starts, steps and counts, int64.
    """
    n = np.asarray(counts, dtype=np.int64)
    zero, one = np.zeros_like(n), np.ones_like(n)
    if basis == "linear":
        return zero, one, n.copy()
    if basis == "bezier":
        three = np.full_like(n, 3)
        return zero, three, n // 3 if wrap == "periodic" else (n - 1) // 3 + 1
    if wrap in ("pinned", "periodic"):
        return zero, one, n.copy()
    return one, one, n - 2


def expected_count(interpolation: str, counts: I64, basis: str, wrap: str) -> int | None:
    """How many values a primvar of this interpolation needs (None for an unknown interpolation).

    Parameters
    ----------
    interpolation : str
        ``constant``, ``uniform``, ``varying``, ``vertex`` or ``faceVarying``.
    counts, basis, wrap
        As :func:`fits` takes them.

    Returns
    -------
    int or None
        The count.
    """
    n = np.asarray(counts, dtype=np.int64)
    if interpolation == "constant":
        return 1
    if interpolation == "uniform":
        return int(n.size)
    if interpolation == "vertex":
        return int(n.sum())
    if interpolation in ("varying", "faceVarying"):
        return int(varying_layout(n, basis, wrap)[2].sum())
    return None


def per_vertex(values: np.ndarray, interpolation: str, counts: I64, basis: str, wrap: str) -> np.ndarray:
    """``(V, ...)`` one value per control point from ``values`` of ``interpolation`` (float64).

    ``values`` must hold :func:`expected_count` rows.

    Parameters
    ----------
    values : ndarray
        The primvar's values.
    interpolation : str
        Their interpolation.
    counts, basis, wrap
        As :func:`fits` takes them.

    Returns
    -------
    ndarray
        ``(V, ...)`` float64.
    """
    a = np.asarray(values, dtype=np.float64)
    n = np.asarray(counts, dtype=np.int64)
    if interpolation == "constant":
        return np.repeat(a[:1], int(n.sum()), axis=0)
    if interpolation == "uniform":
        return np.repeat(a, n, axis=0)
    if interpolation == "vertex":
        return a.copy()
    start, step, m = varying_layout(n, basis, wrap)
    strand = np.repeat(np.arange(n.size), n)
    first = np.zeros(n.size + 1, dtype=np.int64)
    np.cumsum(n, out=first[1:])
    local = np.arange(int(n.sum()), dtype=np.int64) - first[strand]
    # Position of each control point in units of varying samples, held at the curve's ends.
    u = np.clip((local - start[strand]) / step[strand], 0.0, (m - 1)[strand].astype(np.float64))
    j0 = np.floor(u).astype(np.int64)
    j1 = np.minimum(j0 + 1, (m - 1)[strand])
    w = u - j0
    base = np.zeros(n.size + 1, dtype=np.int64)
    np.cumsum(m, out=base[1:])
    b = base[strand]
    if a.ndim > 1:
        w = w[:, None]
    return (1.0 - w) * a[b + j0] + w * a[b + j1]


def per_vertex_reference(values, interpolation: str, counts, basis: str, wrap: str) -> np.ndarray:
    """Curve-by-curve twin of :func:`per_vertex`, for tests.

    Parameters
    ----------
    values, interpolation, counts, basis, wrap
        As :func:`per_vertex` takes them.

    Returns
    -------
    ndarray
        As :func:`per_vertex` gives it.
    """
    a = np.asarray(values, dtype=np.float64)
    out, at = [], 0
    for s, c in enumerate(np.asarray(counts, dtype=np.int64).tolist()):
        if interpolation == "constant":
            out.append(np.repeat(a[:1], c, axis=0))
            continue
        if interpolation == "uniform":
            out.append(np.repeat(a[s : s + 1], c, axis=0))
            continue
        if interpolation == "vertex":
            out.append(a[at : at + c])
            at += c
            continue
        start, step, m = (int(x[0]) for x in varying_layout(np.array([c]), basis, wrap))
        knots = start + step * np.arange(m)
        samples = a[at : at + m]
        at += m
        cols = samples.reshape(m, -1)
        curve = np.column_stack([np.interp(np.arange(c), knots, cols[:, k]) for k in range(cols.shape[1])])
        out.append(curve.reshape((c, *samples.shape[1:])))
    return np.concatenate(out)
