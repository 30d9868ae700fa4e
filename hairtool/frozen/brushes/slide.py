"""The slide brush: roots slide along the head's surface in the drag direction, each strand
keeping its shape in its root frame.

A strand whose root lies within the radius (weight w = strength × falloff at the root; masked
and back-facing strands spared) has its root moved to the surface point closest to
(its root's closest surface point + w × the cursor's motion), and its whole shape turned by the
smallest rotation taking the surface normal at the old root to the one at the new root (the
rotation-minimising transport of the root frame): every vertex's offset from the root, in the
root frame, stays what it was, so lengths and curls are kept and the strand stands on the
surface as before. On a flat surface the shape is only translated.

The surface is anything with ``project(points) -> (closest points, unit normals)``
(:class:`Surface`); :class:`hairtool.guides.surface.MeshSurface` makes one of a head mesh (the
frozen package sits below ``guides`` and takes it as given). The kernel (numba) has the numpy
twin :func:`slide_reference`.
"""

from __future__ import annotations

from typing import Protocol

import numpy as np
from numba import njit, prange
from numpy.typing import ArrayLike, NDArray

from hairtool.errors import ParameterError
from hairtool.frozen.brushes.falloff import end_weights
from hairtool.frozen.brushes.sample import BrushSample, check_sample
from hairtool.frozen.brushes.spec import Brush, BrushSpec, StrokeContext, Studio
from hairtool.groom import Groom
from hairtool.rotation import turn_between

SPEC = BrushSpec(
    name="slide",
    order=10,
    needs_surface=True,
    needs_direction=True,
    studio=Studio(
        "Slide",
        "G",
        "Slides the roots under the brush along the head in the drag's direction; each "
        "strand keeps its shape (needs the head mesh)",
        1.0,
        place=10,
    ),
)


F64 = NDArray[np.float64]


class Surface(Protocol):
    """What the slide brush needs of a head: closest points and unit normals there."""

    def project(self, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]: ...


def no_surface() -> ParameterError:
    return ParameterError("scalp", None, "a head mesh for the slide brush (--scalp MESH.obj)")


@njit(cache=True, nogil=True, parallel=True)
def _slide_kernel(p, offsets, ids, roots, n0, n1, out):  # pragma: no cover - compiled
    out[:] = p
    for k in prange(ids.size):
        s = ids[k]
        o, e = offsets[s], offsets[s + 1]
        for i in range(o, e):
            vx, vy, vz = turn_between(p[i, 0] - p[o, 0], p[i, 1] - p[o, 1], p[i, 2] - p[o, 2],
                               n0[k, 0], n0[k, 1], n0[k, 2], n1[k, 0], n1[k, 1], n1[k, 2])  # fmt: skip
            out[i, 0], out[i, 1], out[i, 2] = roots[k, 0] + vx, roots[k, 1] + vy, roots[k, 2] + vz


def _turn_reference(v: F64, a: F64, b: F64) -> F64:
    c = a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
    k = np.array([a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]])
    if 1.0 + c < 1e-12:
        d = v[:, 0] * a[0] + v[:, 1] * a[1] + v[:, 2] * a[2]
        return v - 2.0 * d[:, None] * a
    kv = (k[0] * v[:, 0] + k[1] * v[:, 1] + k[2] * v[:, 2]) / (1.0 + c)
    cross = np.column_stack([
        k[1] * v[:, 2] - k[2] * v[:, 1], k[2] * v[:, 0] - k[0] * v[:, 2], k[0] * v[:, 1] - k[1] * v[:, 0]
    ])  # fmt: skip
    return v * c + cross + k * kv[:, None]


def _plan(groom: Groom, sample: BrushSample, locked: ArrayLike, surface: Surface | None):
    """The strands that slide, their new roots and the normals at the old and new ones."""
    check_sample(sample)
    if sample.brush != "slide":
        raise ParameterError("brush", sample.brush, "slide")
    if surface is None:
        raise no_surface()
    w = end_weights(groom.roots, sample, locked)
    ids = np.flatnonzero(w > 0)
    if ids.size == 0:
        return ids, None, None, None
    q0, n0 = surface.project(groom.roots[ids].astype(np.float64))
    q1, n1 = surface.project(q0 + w[ids, None] * np.asarray(sample.direction, np.float64))
    f64 = np.float64
    return ids, np.ascontiguousarray(q1, f64), np.ascontiguousarray(n0, f64), np.ascontiguousarray(n1, f64)


def slide(groom: Groom, sample: BrushSample, locked: ArrayLike, surface: Surface | None) -> Groom:
    """One slide sample (numba): roots along the surface by w × the drag, shapes kept in their
    root frames. ParameterError naming ``scalp`` without a surface."""
    ids, roots, n0, n1 = _plan(groom, sample, locked, surface)
    if ids.size == 0:
        return groom
    out = np.empty((groom.vertex_count, 3))
    _slide_kernel(groom.points.astype(np.float64), groom.offsets, ids, roots, n0, n1, out)
    return groom.with_points(out.astype(np.float32))


def slide_reference(groom: Groom, sample: BrushSample, locked: ArrayLike, surface: Surface | None) -> Groom:
    """Numpy twin of :func:`slide`."""
    ids, roots, n0, n1 = _plan(groom, sample, locked, surface)
    if ids.size == 0:
        return groom
    out = groom.points.astype(np.float64)
    for k, s in enumerate(ids):
        o, e = groom.offsets[s], groom.offsets[s + 1]
        p = groom.points[o:e].astype(np.float64)
        out[o:e] = roots[k] + _turn_reference(p - p[0], n0[k], n1[k])
    return groom.with_points(out.astype(np.float32))


class Slide(Brush):
    spec = SPEC

    def apply(self, ctx: StrokeContext, g: Groom, sample) -> Groom:
        return slide(g, sample, ctx.lock(sample), ctx.surface)

    def reference(self, ctx: StrokeContext, g: Groom, sample) -> Groom:
        return slide_reference(g, sample, ctx.lock(sample), ctx.surface)


BRUSH = Slide()
