"""Smooth: each inner vertex moves half way (at full weight) toward the mean of its neighbours (a
Laplacian step of 1/2, from the positions before the sample: larger steps flip zigzags instead
of flattening them), lengths restored: curvature falls, roots stay."""

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
    name="smooth",
    order=2,
    local=True,
    straightens=True,
    studio=Studio(
        "Smooth",
        "S",
        "Takes out kinks and curls; roots stay put (a Laplacian step, lengths kept)",
        1.0,  # the full step at the brush's centre (0.5 took out a fifth of a crinkle per drag)
        place=2,
    ),
)


@njit(cache=True, nogil=True, parallel=True)
def _smooth_kernel(p, offsets, locked, c, radius, strength, lut, out):  # pragma: no cover - compiled
    for s in prange(offsets.size - 1):
        o, e = offsets[s], offsets[s + 1]
        n = e - o
        for i in range(o, e):
            out[i, 0], out[i, 1], out[i, 2] = p[i, 0], p[i, 1], p[i, 2]
        if locked[s] or n < 2:
            continue
        moved = False
        for i in range(o + 1, e):
            w = weight(p[i, 0], p[i, 1], p[i, 2], c, radius, lut) * strength
            if w == 0.0:
                continue
            moved = True
            if i < e - 1:
                for a in range(3):
                    out[i, a] = p[i, a] + 0.5 * w * (0.5 * (p[i - 1, a] + p[i + 1, a]) - p[i, a])
        if moved:
            follow_lengths(out, p, o, n)


def smooth(groom: Groom, sample: BrushSample, locked: ArrayLike, centre: ArrayLike | None = None) -> Groom:
    """One smooth sample (numba).

    Parameters
    ----------
    groom : Groom
        The groom before the sample.
    sample : BrushSample
        A smooth sample.
    locked : array_like, ``(S,)`` bool
        Strands left as they are.
    centre : array_like, optional
        Unused.

    Returns
    -------
    Groom
        The groom after the sample.
    """
    return run_move(_smooth_kernel, groom, sample, "smooth", locked)


def smooth_reference(
    groom: Groom, sample: BrushSample, locked: ArrayLike, centre: ArrayLike | None = None
) -> Groom:
    """Numpy twin of :func:`smooth`."""

    def strand(p, c, lut):
        wm = weights_reference(p, c, sample.radius, lut) * sample.strength
        if not np.any(wm[1:] != 0):
            return None
        q = p.copy()
        q[1:-1] = p[1:-1] + 0.5 * wm[1:-1, None] * (0.5 * (p[:-2] + p[2:]) - p[1:-1])
        return follow_lengths_reference(q, p)

    return move_reference(groom, sample, "smooth", locked, strand)


class Smooth(StrandMove):
    spec = SPEC
    move = staticmethod(smooth)
    move_reference = staticmethod(smooth_reference)


BRUSH = Smooth()
