"""Puff: a strand turns rigidly about its root so that its root direction moves toward the scalp
normal (outward from the sphere fitted to the roots, :func:`~.scalp.scalp_centre`) by
strength·w at the root: tips lift away from the scalp, lengths kept."""

from __future__ import annotations

import numpy as np
from numba import njit, prange
from numpy.typing import ArrayLike, NDArray

from hairtool.frozen.brushes.falloff import EPS, weight, weights_reference
from hairtool.frozen.brushes.sample import BrushSample
from hairtool.frozen.brushes.spec import BrushSpec, StrandMove, Studio
from hairtool.frozen.brushes.strand_moves import move_reference, run_move
from hairtool.frozen.brushes.twin_math import dot3, norm3
from hairtool.groom import Groom

F64 = NDArray[np.float64]

SPEC = BrushSpec(
    name="puff",
    order=4,
    local=True,
    studio=Studio(
        "Puff",
        "I",
        "Lifts strands away from the scalp near the root (turns them toward the scalp normal)",
        0.6,
        place=4,
    ),
)


@njit(cache=True, nogil=True, parallel=True)
def _puff_kernel(p, offsets, locked, c, radius, strength, lut, centre, out):  # pragma: no cover - compiled
    for s in prange(offsets.size - 1):
        o, e = offsets[s], offsets[s + 1]
        for i in range(o, e):
            out[i, 0], out[i, 1], out[i, 2] = p[i, 0], p[i, 1], p[i, 2]
        if locked[s] or e - o < 2:
            continue
        w = weight(p[o, 0], p[o, 1], p[o, 2], c, radius, lut) * strength
        if w > 0.0:
            _puff_strand(p, o, e, w, centre, out)


@njit(cache=True, nogil=True)
def _puff_strand(p, o, e, w, centre, out):  # pragma: no cover - compiled
    """Turn the strand rigidly about its root: its first segment toward the outward normal by
    the fraction w of the angle between them (Rodrigues' rotation)."""
    nx, ny, nz = p[o, 0] - centre[0], p[o, 1] - centre[1], p[o, 2] - centre[2]
    nn = np.sqrt(nx * nx + ny * ny + nz * nz)
    tx, ty, tz = p[o + 1, 0] - p[o, 0], p[o + 1, 1] - p[o, 1], p[o + 1, 2] - p[o, 2]
    tn = np.sqrt(tx * tx + ty * ty + tz * tz)
    if nn < EPS or tn < EPS:
        return
    nx, ny, nz, tx, ty, tz = nx / nn, ny / nn, nz / nn, tx / tn, ty / tn, tz / tn
    ax, ay, az = ty * nz - tz * ny, tz * nx - tx * nz, tx * ny - ty * nx
    sin_a = np.sqrt(ax * ax + ay * ay + az * az)
    cos_a = tx * nx + ty * ny + tz * nz
    if sin_a < 1e-9:
        return  # already along the normal (or exactly against it: no unique way to turn)
    ax, ay, az = ax / sin_a, ay / sin_a, az / sin_a
    angle = w * np.arctan2(sin_a, cos_a)
    cs, sn = np.cos(angle), np.sin(angle)
    for i in range(o + 1, e):
        vx, vy, vz = p[i, 0] - p[o, 0], p[i, 1] - p[o, 1], p[i, 2] - p[o, 2]
        dot = ax * vx + ay * vy + az * vz
        cx, cy, cz = ay * vz - az * vy, az * vx - ax * vz, ax * vy - ay * vx
        out[i, 0] = p[o, 0] + vx * cs + cx * sn + ax * dot * (1.0 - cs)
        out[i, 1] = p[o, 1] + vy * cs + cy * sn + ay * dot * (1.0 - cs)
        out[i, 2] = p[o, 2] + vz * cs + cz * sn + az * dot * (1.0 - cs)


def puff(groom: Groom, sample: BrushSample, locked: ArrayLike, centre: ArrayLike) -> Groom:
    """One puff sample (numba).

    Parameters
    ----------
    groom : Groom
        The groom before the sample.
    sample : BrushSample
        A puff sample.
    locked : array_like, ``(S,)`` bool
        Strands left as they are.
    centre : array_like, ``(3,)``
        The scalp's centre: the outward normal at a root points away from it.

    Returns
    -------
    Groom
        The groom after the sample.
    """
    return run_move(_puff_kernel, groom, sample, "puff", locked, np.asarray(centre, np.float64))


def puff_reference(groom: Groom, sample: BrushSample, locked: ArrayLike, centre: ArrayLike) -> Groom:
    """Numpy twin of :func:`puff`."""
    centre = np.asarray(centre, np.float64)

    def strand(p, c, lut):
        w = weights_reference(p, c, sample.radius, lut)[0] * sample.strength
        return _puff_reference(p, w, centre) if w > 0 else None

    return move_reference(groom, sample, "puff", locked, strand)


def _puff_reference(p: F64, w: float, centre: F64) -> F64:
    """Numpy twin of :func:`_puff_strand` on one strand, in the kernel's order of operations."""
    n, t = p[0] - centre, p[1] - p[0]
    nn, tn = norm3(n), norm3(t)
    if nn < EPS or tn < EPS:
        return p
    n, t = n / nn, t / tn
    axis = np.cross(t, n)
    sin_a = norm3(axis)
    if sin_a < 1e-9:
        return p
    axis /= sin_a
    angle = w * np.arctan2(sin_a, dot3(t, n))
    cs, sn = np.cos(angle), np.sin(angle)
    v = p[1:] - p[0]
    out = p.copy()
    out[1:] = p[0] + v * cs + np.cross(axis, v) * sn + axis * dot3(v, axis)[:, None] * (1.0 - cs)
    return out


class Puff(StrandMove):
    spec = SPEC
    move = staticmethod(puff)
    move_reference = staticmethod(puff_reference)


BRUSH = Puff()
