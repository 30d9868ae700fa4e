"""What the brushes that move vertices share: the check that a sample is theirs, the float32
groom a kernel's float64 points make, and the two frames every per-strand move runs in: its
kernel's call (:func:`run_move`) and its numpy twin's loop over the strands (:func:`move_reference`)."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from numpy.typing import ArrayLike

from hairtool.errors import ParameterError
from hairtool.frozen.brushes.sample import BrushSample, check_sample
from hairtool.groom import Groom


def checked(sample: BrushSample, brush: str) -> BrushSample:
    """``sample``, checked (:func:`~hairtool.frozen.brushes.sample.check_sample`) and of ``brush``
    (ParameterError naming ``brush`` otherwise)."""
    check_sample(sample)
    if sample.brush != brush:
        raise ParameterError("brush", sample.brush, brush)
    return sample


def moved_groom(groom: Groom, out: np.ndarray) -> Groom:
    """``groom`` with the float64 points ``out`` a kernel wrote, as float32."""
    return groom.with_points(out.astype(np.float32))


def run_move(
    kernel: Callable, groom: Groom, sample: BrushSample, brush: str, locked: ArrayLike, *extra
) -> Groom:
    """One sample of the per-strand move ``brush`` through its numba kernel.

    Parameters
    ----------
    kernel : callable
        ``kernel(points, offsets, locked, cursor, radius, strength, lut, *extra, out)`` over
        float64 points, writing every vertex of ``out`` ``(V, 3)``.
    groom : Groom
        The groom before the sample.
    sample : BrushSample
        A sample of ``brush`` (checked; ParameterError otherwise).
    brush : str
        The brush's name.
    locked : array_like, ``(S,)`` bool
        Strands left as they are.
    *extra
        The kernel's own arguments after the falloff table (a direction, a centre).

    Returns
    -------
    Groom
        The groom after the sample (float32 points).
    """
    checked(sample, brush)
    out = np.empty((groom.vertex_count, 3))
    kernel(
        groom.points.astype(np.float64), groom.offsets, np.asarray(locked, np.bool_),
        np.asarray(sample.cursor, np.float64), float(sample.radius), float(sample.strength),
        np.asarray(sample.lut, np.float64), *extra, out,
    )  # fmt: skip
    return moved_groom(groom, out)


def move_reference(
    groom: Groom,
    sample: BrushSample,
    brush: str,
    locked: ArrayLike,
    strand: Callable[[np.ndarray, np.ndarray, np.ndarray], np.ndarray | None],
) -> Groom:
    """The numpy twin of a per-strand move: ``strand`` on each strand that is not locked and has
    two vertices or more.

    Parameters
    ----------
    groom : Groom
        The groom before the sample.
    sample : BrushSample
        A sample of ``brush`` (checked; ParameterError otherwise).
    brush : str
        The brush's name.
    locked : array_like, ``(S,)`` bool
        Strands left as they are.
    strand : callable
        ``strand(p, cursor, lut)``: the strand's float64 points ``(n, 3)`` moved (a new
        array), or None where the sample leaves it as it was.

    Returns
    -------
    Groom
        The groom after the sample (float32 points).
    """
    checked(sample, brush)
    p_all = groom.points.astype(np.float64)
    out = p_all.copy()
    c, lut = np.asarray(sample.cursor, np.float64), np.asarray(sample.lut, np.float64)
    locked = np.asarray(locked, bool)
    for s, (o, e) in enumerate(zip(groom.offsets[:-1], groom.offsets[1:], strict=True)):
        if locked[s] or e - o < 2:
            continue
        q = strand(p_all[o:e], c, lut)
        if q is not None:
            out[o:e] = q
    return moved_groom(groom, out)
