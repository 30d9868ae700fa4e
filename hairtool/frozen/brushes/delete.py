"""Delete: the strands under the brush leave the groom (falloff ignored; masked and back-facing
strands spared). Two rules say which are under it: Blender's, any segment within the radius of
the cursor (``any_segment``, the studio's default), and the root rule, the root within it (what
every stroke log and project written before the choice meant, so they replay as they did). The
pipeline records which strands remain
(:attr:`~hairtool.frozen.pipeline.FrozenPipeline.origin`), so undo and replay are exact."""

from __future__ import annotations

import numpy as np
from numba import njit, prange
from numpy.typing import ArrayLike

from hairtool.errors import ParameterError
from hairtool.frozen.brushes.sample import BrushSample
from hairtool.frozen.brushes.spec import Brush, BrushSpec, Param, StrokeContext, Studio
from hairtool.frozen.brushes.strand_moves import checked
from hairtool.groom import Groom

#: Blender's rule (True) or the root rule (False: a sample that does not say, as older logs).
ANY_SEGMENT = Param("any_segment", bool, 0, 1, 0, "any_segment", "true (any segment) or false (the root)")

SPEC = BrushSpec(
    name="delete",
    order=7,
    moves_points=False,
    changes_strands=True,
    takes_strength=False,
    studio=Studio(
        "Delete",
        "X",
        "Removes the strands under the brush: those with any segment under it, or only those "
        "whose root is (undo brings them back)",
        1.0,
        place=9,
    ),
    params=(ANY_SEGMENT,),
)


@njit(cache=True, nogil=True, parallel=True)
def _under_kernel(roots, c, radius, locked, out):  # pragma: no cover - compiled
    for s in prange(roots.shape[0]):
        dx, dy, dz = roots[s, 0] - c[0], roots[s, 1] - c[1], roots[s, 2] - c[2]
        out[s] = not locked[s] and np.sqrt(dx * dx + dy * dy + dz * dz) / radius < 1.0


@njit(cache=True, nogil=True, parallel=True)
def _segment_kernel(p, offsets, c, radius, locked, out):  # pragma: no cover - compiled
    r2 = radius * radius
    for s in prange(offsets.size - 1):
        if locked[s]:
            continue
        a0, a1 = offsets[s], offsets[s + 1]
        hit = False
        if a1 == a0:
            continue
        for i in range(a0, max(a1 - 1, a0 + 1)):
            j = min(i + 1, a1 - 1)
            ax, ay, az = p[i, 0], p[i, 1], p[i, 2]
            ex, ey, ez = p[j, 0] - ax, p[j, 1] - ay, p[j, 2] - az
            wx, wy, wz = c[0] - ax, c[1] - ay, c[2] - az
            len2 = ex * ex + ey * ey + ez * ez
            t = 0.0
            if len2 > 0.0:
                t = min(max((wx * ex + wy * ey + wz * ez) / len2, 0.0), 1.0)
            qx, qy, qz = ax + t * ex - c[0], ay + t * ey - c[1], az + t * ez - c[2]
            if qx * qx + qy * qy + qz * qz < r2:
                hit = True
                break
        out[s] = hit


def strands_to_delete(groom: Groom, sample: BrushSample, locked: ArrayLike) -> np.ndarray:
    """``(S,)`` the strands one delete sample removes: any segment within the radius (with
    ``any_segment``) or the root within it, not ``locked`` (masked or facing away), and only
    with strength > 0 (numba)."""
    checked(sample, "delete")
    out = np.zeros(groom.strand_count, dtype=np.bool_)
    if sample.strength <= 0:
        return out
    c, r, lock = np.asarray(sample.cursor, np.float64), float(sample.radius), np.asarray(locked, np.bool_)
    if sample.any_segment:
        _segment_kernel(groom.points.astype(np.float64), groom.offsets, c, r, lock, out)
    else:
        _under_kernel(groom.roots.astype(np.float64), c, r, lock, out)
    return out


def _segments_within(groom: Groom, c: np.ndarray, radius: float) -> np.ndarray:
    """``(S,)`` the strands with a segment (or, for a one-vertex strand, the vertex) closer
    than ``radius`` to ``c``, as the kernel computes it, operation for operation."""
    p, off = groom.points.astype(np.float64), groom.offsets
    last = off[1:] - 1
    i = np.arange(p.shape[0] - 1 if p.shape[0] > 1 else 0)
    i = i[groom.topology.strand_index[i] == groom.topology.strand_index[i + 1]]
    single = off[:-1][last == off[:-1]]
    i, j = np.concatenate([i, single]), np.concatenate([i + 1, single])
    a, e, w = p[i], p[j] - p[i], c - p[i]
    len2 = e[:, 0] * e[:, 0] + e[:, 1] * e[:, 1] + e[:, 2] * e[:, 2]
    dot = w[:, 0] * e[:, 0] + w[:, 1] * e[:, 1] + w[:, 2] * e[:, 2]
    with np.errstate(divide="ignore", invalid="ignore"):
        t = np.where(len2 > 0.0, np.minimum(np.maximum(dot / len2, 0.0), 1.0), 0.0)
    q = a + t[:, None] * e - c
    d2 = q[:, 0] * q[:, 0] + q[:, 1] * q[:, 1] + q[:, 2] * q[:, 2]
    out = np.zeros(groom.strand_count, bool)
    out[groom.topology.strand_index[i[d2 < radius * radius]]] = True
    return out


def strands_to_delete_reference(groom: Groom, sample: BrushSample, locked: ArrayLike) -> np.ndarray:
    """Numpy twin of :func:`strands_to_delete`."""
    checked(sample, "delete")
    c = np.asarray(sample.cursor, np.float64)
    if sample.any_segment:
        inside = _segments_within(groom, c, float(sample.radius))
    else:
        r = groom.roots.astype(np.float64)
        inside = np.linalg.norm(r - c, axis=1) / sample.radius < 1.0
    return inside & ~np.asarray(locked, bool) & (sample.strength > 0)


class EveryStrandGone(ParameterError):
    """A stroke that would delete every strand of the groom (a groom holds at least one). Where
    the groom is one prim of a scene, the command keeps that prim empty instead
    (:mod:`hairtool.prims`), as Blender keeps an empty Curves object."""

    def __init__(self, brush: str) -> None:
        super().__init__(brush, "every strand", "a stroke that leaves at least one strand")


def remove(ctx: StrokeContext, g: Groom, gone: np.ndarray, brush: str) -> Groom:
    """``g`` without the strands ``gone`` (an ``(S,)`` mask), their state with them;
    :class:`EveryStrandGone` naming ``brush`` where none would be left."""
    if not gone.any():
        return g
    if gone.all():
        raise EveryStrandGone(brush)
    return ctx.keep(g, np.flatnonzero(~gone))


class Delete(Brush):
    spec = SPEC

    def apply(self, ctx: StrokeContext, g: Groom, sample) -> Groom:
        return remove(ctx, g, strands_to_delete(g, sample, ctx.lock(sample)), "delete")

    def reference(self, ctx: StrokeContext, g: Groom, sample) -> Groom:
        return remove(ctx, g, strands_to_delete_reference(g, sample, ctx.lock(sample)), "delete")


BRUSH = Delete()
