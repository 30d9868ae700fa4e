"""Length: a strand's segments scale by 1 + strength·w, w the largest weight over its vertices:
strength > 0 grows, < 0 shrinks, as a fraction of the length, directions kept."""

from __future__ import annotations

from numba import njit, prange
from numpy.typing import ArrayLike

from hairtool.frozen.brushes.falloff import weight, weights_reference
from hairtool.frozen.brushes.sample import BrushSample
from hairtool.frozen.brushes.spec import BrushSpec, StrandMove, Studio
from hairtool.frozen.brushes.strand_moves import move_reference, run_move
from hairtool.groom import Groom

SPEC = BrushSpec(
    name="length",
    order=3,
    signed=True,
    local=True,
    studio=Studio(
        "Length",
        "L",
        "Grows or shrinks the strands under the brush (Ctrl: the other way)",
        0.1,
        ("Grow", "Shrink"),
        "Grow or shrink",
        place=3,
    ),
)


@njit(cache=True, nogil=True, parallel=True)
def _length_kernel(p, offsets, locked, c, radius, strength, lut, out):  # pragma: no cover - compiled
    for s in prange(offsets.size - 1):
        o, e = offsets[s], offsets[s + 1]
        for i in range(o, e):
            out[i, 0], out[i, 1], out[i, 2] = p[i, 0], p[i, 1], p[i, 2]
        if locked[s] or e - o < 2:
            continue
        w = 0.0
        for i in range(o, e):
            w = max(w, weight(p[i, 0], p[i, 1], p[i, 2], c, radius, lut))
        factor = max(1.0 + strength * w, 0.0)
        if w > 0.0:
            for i in range(o + 1, e):
                for a in range(3):
                    out[i, a] = out[i - 1, a] + factor * (p[i, a] - p[i - 1, a])


def length(groom: Groom, sample: BrushSample, locked: ArrayLike, centre: ArrayLike | None = None) -> Groom:
    """One length sample (numba).

    Parameters
    ----------
    groom : Groom
        The groom before the sample.
    sample : BrushSample
        A length sample (strength > 0 grows, < 0 shrinks).
    locked : array_like, ``(S,)`` bool
        Strands left as they are.
    centre : array_like, optional
        Unused.

    Returns
    -------
    Groom
        The groom after the sample.
    """
    return run_move(_length_kernel, groom, sample, "length", locked)


def length_reference(
    groom: Groom, sample: BrushSample, locked: ArrayLike, centre: ArrayLike | None = None
) -> Groom:
    """Numpy twin of :func:`length`."""

    def strand(p, c, lut):
        w = weights_reference(p, c, sample.radius, lut)
        if not w.max() > 0:
            return None
        factor = max(1.0 + sample.strength * w.max(), 0.0)
        q = p.copy()
        for i in range(1, len(p)):
            q[i] = q[i - 1] + factor * (p[i] - p[i - 1])
        return q

    return move_reference(groom, sample, "length", locked, strand)


class Length(StrandMove):
    spec = SPEC
    move = staticmethod(length)
    move_reference = staticmethod(length_reference)


BRUSH = Length()
