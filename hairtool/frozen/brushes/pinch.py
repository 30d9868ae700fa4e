"""Pinch: every vertex but the root moves toward the brush centre by the fraction strength·w of
its distance to it (w the falloff weight at the vertex; strength < 0 spreads away from the
centre), then each segment gets its length back root to tip (follow-the-leader, as comb does)."""

from __future__ import annotations

import numpy as np
from numba import njit, prange
from numpy.typing import ArrayLike

from hairtool.frozen.brushes.constraints import follow_lengths, follow_lengths_reference
from hairtool.frozen.brushes.falloff import weight, weights_reference
from hairtool.frozen.brushes.sample import BrushSample
from hairtool.frozen.brushes.spec import BrushSpec, StrandMove, Studio
from hairtool.frozen.brushes.strand_moves import move_reference, run_move
from hairtool.groom import Groom

SPEC = BrushSpec(
    name="pinch",
    order=8,
    signed=True,
    local=True,
    studio=Studio(
        "Pinch",
        "Shift+P",
        "Gathers strands toward the brush centre (Ctrl: spreads them); roots stay, lengths kept",
        0.4,
        ("Gather", "Spread"),
        "Gather or spread",
        place=7,
    ),
)


@njit(cache=True, nogil=True, parallel=True)
def _pinch_kernel(p, offsets, locked, c, radius, strength, lut, out):  # pragma: no cover - compiled
    for s in prange(offsets.size - 1):
        o, e = offsets[s], offsets[s + 1]
        for i in range(o, e):
            out[i, 0], out[i, 1], out[i, 2] = p[i, 0], p[i, 1], p[i, 2]
        if locked[s] or e - o < 2:
            continue
        moved = False
        for i in range(o + 1, e):
            w = weight(p[i, 0], p[i, 1], p[i, 2], c, radius, lut) * strength
            if w == 0.0:
                continue
            moved = True
            for a in range(3):
                out[i, a] = p[i, a] + w * (c[a] - p[i, a])
        if moved:
            follow_lengths(out, p, o, e - o)


def pinch(groom: Groom, sample: BrushSample, locked: ArrayLike, centre: ArrayLike | None = None) -> Groom:
    """One pinch sample (numba): vertices toward the centre (away with strength < 0), roots
    fixed, lengths kept."""
    return run_move(_pinch_kernel, groom, sample, "pinch", locked)


def pinch_reference(
    groom: Groom, sample: BrushSample, locked: ArrayLike, centre: ArrayLike | None = None
) -> Groom:
    """Numpy twin of :func:`pinch`."""

    def strand(p, c, lut):
        w = weights_reference(p, c, sample.radius, lut) * sample.strength
        w[0] = 0.0
        if not np.any(w != 0):
            return None
        return follow_lengths_reference(p + w[:, None] * (c - p), p)

    return move_reference(groom, sample, "pinch", locked, strand)


class Pinch(StrandMove):
    spec = SPEC
    move = staticmethod(pinch)
    move_reference = staticmethod(pinch_reference)


BRUSH = Pinch()
