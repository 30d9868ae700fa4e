"""Mask: strength > 0 locks the strands a sample touches, < 0 frees them; masked strands are
locked for every brush. No vertex moves."""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from hairtool.frozen.brushes.falloff import strand_weights_reference
from hairtool.frozen.brushes.sample import BrushSample, check_sample
from hairtool.frozen.brushes.spec import Brush, BrushSpec, StrokeContext, Studio
from hairtool.groom import Groom

SPEC = BrushSpec(
    name="mask",
    order=5,
    signed=True,
    moves_points=False,
    local=True,
    takes_strength=False,
    studio=Studio(
        "Mask",
        "M",
        "Paints a mask: masked strands are locked for every brush (Ctrl erases)",
        1.0,
        ("Paint", "Erase"),
        "Paint or erase",
        place=6,
    ),
)


def paint_mask(
    groom: Groom, sample: BrushSample, locked: ArrayLike, skip: ArrayLike | None = None
) -> np.ndarray:
    """A per-strand flag after one painting sample (mask's lock, select's selection).

    Parameters
    ----------
    groom : Groom
        The groom the sample paints.
    sample : BrushSample
        The sample: strands with a vertex inside its brush are set (strength > 0) or cleared (< 0).
    locked : array_like, ``(S,)`` bool
        The flags before it.
    skip : array_like, ``(S,)`` bool, optional
        Strands left as they are (hidden, facing away).

    Returns
    -------
    numpy.ndarray
        ``(S,)`` bool flags (a new array).
    """
    check_sample(sample)
    locked = np.array(locked, dtype=bool)
    touched = strand_weights_reference(groom.points.astype(np.float64), groom.offsets, sample) > 0
    if skip is not None:
        touched &= ~np.asarray(skip, dtype=bool)
    locked[touched] = sample.strength > 0
    return locked


class Mask(Brush):
    spec = SPEC

    def apply(self, ctx: StrokeContext, g: Groom, sample) -> Groom:
        ctx.state = ctx.state.with_(
            locked=paint_mask(g, sample, ctx.state.locked, ctx.lock(sample, mask=False))
        )
        return g


BRUSH = Mask()
