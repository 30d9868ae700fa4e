"""Segment lengths given back after ClumpWithGaps (the ``keep_lengths`` pass).

As printed (Kim 2026, eqs. 14–19) clumping moves each vertex with no length constraint, so a
strand pulled toward a neighbour stretches or shrinks: rubber hair. This pass walks every
strand from root to tip and sets each segment back to its length before clumping, keeping the
clumped segment's direction: q₀ = p₀, qᵢ = qᵢ₋₁ + ℓᵢ·(pᵢ − pᵢ₋₁)/|pᵢ − pᵢ₋₁| with ℓᵢ the
length before, p the clumped points. A segment clumping collapsed to a point keeps its
direction from before. The pass is per strand and reads only that strand, so a region update
that gives a full run's clumped bytes gives a full run's restored bytes too.
"""

from __future__ import annotations

import numpy as np
from numba import prange

from hairtool import serial_twins
from hairtool.groom import Topology
from hairtool.kernel_arrays import readonly
from hairtool.serial_twins import twin_njit


@twin_njit(nogil=True, parallel=True)
def _restore_kernel(before, after, offsets, strands, out):
    """The strands ``strands`` (all where it is empty) of ``after``, lengths from ``before``."""
    count = strands.size if strands.size > 0 else offsets.size - 1
    for m in prange(count):
        s = np.int64(m)
        if strands.size > 0:
            s = strands[m]
        a, b = offsets[s], offsets[s + 1]
        qx, qy, qz = float(after[a, 0]), float(after[a, 1]), float(after[a, 2])
        out[a, 0], out[a, 1], out[a, 2] = after[a, 0], after[a, 1], after[a, 2]
        for i in range(a + 1, b):
            lx = float(before[i, 0]) - float(before[i - 1, 0])
            ly = float(before[i, 1]) - float(before[i - 1, 1])
            lz = float(before[i, 2]) - float(before[i - 1, 2])
            length = np.sqrt(lx * lx + ly * ly + lz * lz)
            dx = float(after[i, 0]) - float(after[i - 1, 0])
            dy = float(after[i, 1]) - float(after[i - 1, 1])
            dz = float(after[i, 2]) - float(after[i - 1, 2])
            d = np.sqrt(dx * dx + dy * dy + dz * dz)
            if d > 0.0:
                k = length / d
                qx += dx * k
                qy += dy * k
                qz += dz * k
            else:  # collapsed: the direction before
                qx += lx
                qy += ly
                qz += lz
            out[i, 0], out[i, 1], out[i, 2] = qx, qy, qz


_ALL = np.zeros(0, np.int64)


def restore_lengths(
    before: np.ndarray,
    after: np.ndarray,
    topology: Topology,
    strands: np.ndarray | None = None,
    out: np.ndarray | None = None,
    parallel: bool = True,
) -> np.ndarray:
    """float32 ``(V, 3)``: ``after`` with every segment set back to its length in ``before``
    (directions from ``after``; float64 inside, roots as in ``after``). With ``strands`` (and
    ``out`` holding the others) only those strands are written.

    Parameters
    ----------
    before : ndarray
        ``(V, 3)`` the points whose segment lengths are kept.
    after : ndarray
        ``(V, 3)`` the moved points whose directions are kept.
    topology : Topology
        The strands of both.
    strands : ndarray, optional
        Only these strands are written (None: all).
    out : ndarray, optional
        ``(V, 3)`` float32, written in place; it holds the other strands.
    parallel : bool, default True
        Run the parallel kernel (False: its serial twin, for a few strands; the same bytes).

    Returns
    -------
    ndarray
        ``(V, 3)`` float32 points.
    """
    if out is None:
        out = np.empty((topology.vertex_count, 3), np.float32)
    picked = _ALL if strands is None else np.ascontiguousarray(strands, np.int64)
    if strands is None or picked.size > 0:
        kernel = _restore_kernel if parallel else serial_twins.serial(_restore_kernel)
        kernel(readonly(before), readonly(after), readonly(topology.offsets), picked, out)
    return out


def restore_lengths_reference(before: np.ndarray, after: np.ndarray, topology: Topology) -> np.ndarray:
    """Numpy twin of :func:`restore_lengths`: strand by strand, a cumulative sum of rescaled segments.

    Parameters
    ----------
    before, after : ndarray
        ``(V, 3)`` as :func:`restore_lengths` takes them.
    topology : Topology
        The strands of both.

    Returns
    -------
    ndarray
        ``(V, 3)`` float32, as :func:`restore_lengths` gives them.
    """
    out = np.empty((topology.vertex_count, 3), np.float32)
    for a, b in zip(topology.offsets[:-1], topology.offsets[1:], strict=True):
        p0 = before[a:b].astype(np.float64)
        p1 = after[a:b].astype(np.float64)
        ell = np.linalg.norm(np.diff(p0, axis=0), axis=1)
        d = np.diff(p1, axis=0)
        n = np.linalg.norm(d, axis=1)
        seg = np.where((n > 0)[:, None], d * (ell / np.where(n > 0, n, 1.0))[:, None], np.diff(p0, axis=0))
        out[a:b] = p1[0] + np.concatenate([np.zeros((1, 3)), np.cumsum(seg, axis=0)])
    return out
