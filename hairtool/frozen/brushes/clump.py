"""Clump: paints each strand's clump strength s in [0, 1], which ClumpWithGaps scales its
adhesion step by: s moves toward 1 (strength > 0) or 0 (< 0) by |strength|·w, w the largest
weight over the strand's vertices. No vertex moves."""

from __future__ import annotations

import numpy as np
from numba import njit, prange
from numpy.typing import ArrayLike

from hairtool.errors import ParameterError
from hairtool.frozen.brushes.falloff import weight, weights_reference
from hairtool.frozen.brushes.sample import BrushSample, check_sample
from hairtool.frozen.brushes.spec import Brush, BrushSpec, StrokeContext, Studio
from hairtool.groom import Groom

SPEC = BrushSpec(
    name="clump",
    order=6,
    signed=True,
    moves_points=False,
    local=True,
    studio=Studio(
        "Clump",
        "P",
        "Paints how strongly strands clump (ClumpWithGaps' per-strand strength): a new groom "
        "clumps fully, so it starts erasing (Ctrl paints clumping back)",
        0.5,
        ("Paint", "Erase"),
        "Paint or erase",
        place=5,
        starts_second=True,
    ),
)


@njit(cache=True, nogil=True, parallel=True)
def _paint_clump_kernel(p, offsets, locked, c, radius, strength, lut, s_in, s_out):  # pragma: no cover
    target = 1.0 if strength > 0.0 else 0.0
    amount = abs(strength)
    for s in prange(offsets.size - 1):
        s_out[s] = s_in[s]
        if locked[s]:
            continue
        w = 0.0
        for i in range(offsets[s], offsets[s + 1]):
            w = max(w, weight(p[i, 0], p[i, 1], p[i, 2], c, radius, lut))
        if w > 0.0:
            s_out[s] = s_in[s] + amount * w * (target - s_in[s])


def paint_clump(groom: Groom, sample: BrushSample, strength: ArrayLike, locked: ArrayLike) -> np.ndarray:
    """Clump strengths after one clump sample (numba): each unlocked strand's s moves toward 1
    (sample strength > 0) or 0 (< 0) by |strength|·w, w its largest vertex weight, so it stays
    in [0, 1].

    Parameters
    ----------
    groom : Groom
        The groom the sample paints.
    sample : BrushSample
        A clump sample.
    strength : array_like, ``(S,)``
        The clump strengths before it.
    locked : array_like, ``(S,)`` bool
        Strands left as they are.

    Returns
    -------
    numpy.ndarray
        ``(S,)`` float64 clump strengths (a new array).
    """
    check_sample(sample)
    if sample.brush != "clump":
        raise ParameterError("brush", sample.brush, "clump")
    s_in = np.ascontiguousarray(strength, dtype=np.float64)
    out = np.empty_like(s_in)
    _paint_clump_kernel(
        groom.points.astype(np.float64), groom.offsets, np.asarray(locked, np.bool_),
        np.asarray(sample.cursor, np.float64), float(sample.radius), float(sample.strength),
        np.asarray(sample.lut, np.float64), s_in, out,
    )  # fmt: skip
    return out


def paint_clump_reference(
    groom: Groom, sample: BrushSample, strength: ArrayLike, locked: ArrayLike
) -> np.ndarray:
    """Numpy twin of :func:`paint_clump`."""
    check_sample(sample)
    s_in = np.asarray(strength, dtype=np.float64)
    c, lut = np.asarray(sample.cursor, np.float64), np.asarray(sample.lut, np.float64)
    w = np.maximum.reduceat(
        weights_reference(groom.points.astype(np.float64), c, sample.radius, lut), groom.offsets[:-1]
    )
    w = np.where(np.asarray(locked, bool), 0.0, w)
    target = 1.0 if sample.strength > 0 else 0.0
    return np.where(w > 0, s_in + abs(sample.strength) * w * (target - s_in), s_in)


class Clump(Brush):
    spec = SPEC

    def apply(self, ctx: StrokeContext, g: Groom, sample) -> Groom:
        ctx.state = ctx.state.with_(
            clump_strength=paint_clump(g, sample, ctx.state.clump_strength, ctx.lock(sample))
        )
        return g

    def reference(self, ctx: StrokeContext, g: Groom, sample) -> Groom:
        now = paint_clump_reference(g, sample, ctx.state.clump_strength, ctx.lock(sample))
        ctx.state = ctx.state.with_(clump_strength=now)
        return g


BRUSH = Clump()
