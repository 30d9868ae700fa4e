"""Comb: the vertices move along the drag direction, more toward the tip (weight × arc-length
fraction), then every segment gets its length back root to tip: tips follow the drag, lengths
stay."""

from __future__ import annotations

import numpy as np
from numba import njit, prange
from numpy.typing import ArrayLike

from hairtool.frozen.brushes.constraints import follow_lengths, follow_lengths_reference
from hairtool.frozen.brushes.falloff import EPS, weight, weights_reference
from hairtool.frozen.brushes.sample import BrushSample
from hairtool.frozen.brushes.spec import BrushSpec, StrandMove, Studio
from hairtool.frozen.brushes.strand_moves import move_reference, run_move
from hairtool.frozen.brushes.twin_math import norm3, running_sum
from hairtool.groom import Groom

SPEC = BrushSpec(
    name="comb",
    order=1,
    local=True,
    needs_direction=True,
    studio=Studio("Comb", "C", "Tips follow the drag, strand lengths kept", 1.0, place=1),
)


@njit(cache=True, nogil=True, inline="always")
def _segment(p, i, j):  # pragma: no cover - compiled
    return np.sqrt((p[i, 0] - p[j, 0]) ** 2 + (p[i, 1] - p[j, 1]) ** 2 + (p[i, 2] - p[j, 2]) ** 2)


@njit(cache=True, nogil=True, parallel=True)
def _comb_kernel(p, offsets, locked, c, radius, strength, lut, direction, out):  # pragma: no cover
    for s in prange(offsets.size - 1):
        o, e = offsets[s], offsets[s + 1]
        n = e - o
        for i in range(o, e):
            out[i, 0], out[i, 1], out[i, 2] = p[i, 0], p[i, 1], p[i, 2]
        if locked[s] or n < 2:
            continue
        total = 0.0
        for i in range(o + 1, e):
            total += _segment(p, i, i - 1)
        run = 0.0
        moved = False
        for i in range(o + 1, e):
            run += _segment(p, i, i - 1)
            w = weight(p[i, 0], p[i, 1], p[i, 2], c, radius, lut) * strength
            if w == 0.0:
                continue
            moved = True
            u = run / total if total > EPS else 0.0
            for a in range(3):
                out[i, a] = p[i, a] + w * u * direction[a]
        if moved:
            follow_lengths(out, p, o, n)


def comb(groom: Groom, sample: BrushSample, locked: ArrayLike, centre: ArrayLike | None = None) -> Groom:
    """One comb sample (numba).

    Parameters
    ----------
    groom : Groom
        The groom before the sample.
    sample : BrushSample
        A comb sample.
    locked : array_like, ``(S,)`` bool
        Strands left as they are.
    centre : array_like, optional
        Unused (every strand move takes the scalp's centre).

    Returns
    -------
    Groom
        The groom after the sample (float32 points).
    """
    return run_move(_comb_kernel, groom, sample, "comb", locked, np.asarray(sample.direction, np.float64))


def comb_reference(
    groom: Groom, sample: BrushSample, locked: ArrayLike, centre: ArrayLike | None = None
) -> Groom:
    """Numpy twin of :func:`comb`."""
    d = np.asarray(sample.direction, np.float64)

    def strand(p, c, lut):
        wm = weights_reference(p, c, sample.radius, lut) * sample.strength
        if not np.any(wm[1:] != 0):
            return None
        run = running_sum(norm3(np.diff(p, axis=0)))
        u = run / run[-1] if run[-1] > EPS else np.zeros_like(run)
        q = p.copy()
        q[1:] = p[1:] + (wm * u)[1:, None] * d
        return follow_lengths_reference(q, p)

    return move_reference(groom, sample, "comb", locked, strand)


class Comb(StrandMove):
    spec = SPEC
    move = staticmethod(comb)
    move_reference = staticmethod(comb_reference)


BRUSH = Comb()
