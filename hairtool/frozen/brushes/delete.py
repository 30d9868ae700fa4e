"""Delete: the strands whose root lies within the radius of the cursor (falloff ignored; masked
and back-facing strands spared) leave the groom. The pipeline records which strands remain
(:attr:`~hairtool.frozen.pipeline.FrozenPipeline.origin`), so undo and replay are exact."""

from __future__ import annotations

import numpy as np
from numba import njit, prange
from numpy.typing import ArrayLike

from hairtool.errors import ParameterError
from hairtool.frozen.brushes.sample import BrushSample
from hairtool.frozen.brushes.spec import Brush, BrushSpec, StrokeContext, Studio
from hairtool.frozen.brushes.strand_moves import checked
from hairtool.groom import Groom

SPEC = BrushSpec(
    name="delete",
    order=7,
    moves_points=False,
    changes_strands=True,
    takes_strength=False,
    studio=Studio(
        "Delete",
        "X",
        "Removes the strands whose roots are under the brush (undo brings them back)",
        1.0,
        place=9,
    ),
)


@njit(cache=True, nogil=True, parallel=True)
def _under_kernel(roots, c, radius, locked, out):  # pragma: no cover - compiled
    for s in prange(roots.shape[0]):
        dx, dy, dz = roots[s, 0] - c[0], roots[s, 1] - c[1], roots[s, 2] - c[2]
        out[s] = not locked[s] and np.sqrt(dx * dx + dy * dy + dz * dz) / radius < 1.0


def strands_to_delete(groom: Groom, sample: BrushSample, locked: ArrayLike) -> np.ndarray:
    """``(S,)`` the strands one delete sample removes: root within the radius, not ``locked``
    (masked or facing away), and only with strength > 0 (numba)."""
    checked(sample, "delete")
    out = np.zeros(groom.strand_count, dtype=np.bool_)
    if sample.strength > 0:
        _under_kernel(
            groom.roots.astype(np.float64), np.asarray(sample.cursor, np.float64), float(sample.radius),
            np.asarray(locked, np.bool_), out,
        )  # fmt: skip
    return out


def strands_to_delete_reference(groom: Groom, sample: BrushSample, locked: ArrayLike) -> np.ndarray:
    """Numpy twin of :func:`strands_to_delete`."""
    checked(sample, "delete")
    r = groom.roots.astype(np.float64)
    inside = np.linalg.norm(r - np.asarray(sample.cursor, np.float64), axis=1) / sample.radius < 1.0
    return inside & ~np.asarray(locked, bool) & (sample.strength > 0)


def remove(ctx: StrokeContext, g: Groom, gone: np.ndarray, brush: str) -> Groom:
    """``g`` without the strands ``gone`` (an ``(S,)`` mask), their state with them;
    ParameterError naming ``brush`` where none would be left."""
    if not gone.any():
        return g
    if gone.all():
        raise ParameterError(brush, "every strand", "a stroke that leaves at least one strand")
    return ctx.keep(g, np.flatnonzero(~gone))


class Delete(Brush):
    spec = SPEC

    def apply(self, ctx: StrokeContext, g: Groom, sample) -> Groom:
        return remove(ctx, g, strands_to_delete(g, sample, ctx.lock(sample)), "delete")

    def reference(self, ctx: StrokeContext, g: Groom, sample) -> Groom:
        return remove(ctx, g, strands_to_delete_reference(g, sample, ctx.lock(sample)), "delete")


BRUSH = Delete()
