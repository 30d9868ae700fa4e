"""The groom's vertex nearest the mouse on screen: where a stroke's press keeps its cursor level.

A press looked at every vertex through numpy: the projection of the bear's 192,000 vertices and
their distances to the mouse made ~25 MB of arrays afresh at each press, most of the press's
30 ms on the 2-core VM going to their page faults. One parallel pass computes each vertex's
pixel and keeps the nearest within the brush, allocating nothing the size of the groom.
:func:`nearest_on_screen_reference` is the numpy twin (:meth:`Camera.project` and the same
choice: the smallest distance, ties to the lower vertex index).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from numba import prange
from numpy.typing import ArrayLike

from hairtool.kernel_arrays import readonly
from hairtool.serial_twins import twin_njit

CHUNKS = 64  # parallel tasks (each keeps its nearest; the first of equals wins, as in the twin)
_NO_SKIP = np.zeros(0, np.bool_)


@twin_njit(nogil=True, parallel=True)
def _nearest_kernel(points, m, width, height, cx, cy, r2, strand, skip, best_d, best_i):
    n = points.shape[0]
    tasks = best_d.size
    for c in prange(tasks):
        bd, bi = np.inf, np.int64(-1)
        for i in range(n * c // tasks, n * (c + 1) // tasks):
            if skip.size > 0 and skip[strand[i]]:
                continue
            x, y, z = np.float64(points[i, 0]), np.float64(points[i, 1]), np.float64(points[i, 2])
            w = x * m[0, 3] + y * m[1, 3] + z * m[2, 3] + m[3, 3]
            sx = ((x * m[0, 0] + y * m[1, 0] + z * m[2, 0] + m[3, 0]) / w + 1.0) * 0.5 * width
            sy = (1.0 - (x * m[0, 1] + y * m[1, 1] + z * m[2, 1] + m[3, 1]) / w) * 0.5 * height
            d = (sx - cx) * (sx - cx) + (sy - cy) * (sy - cy)
            if d <= r2 and d < bd:
                bd, bi = d, i
        best_d[c], best_i[c] = bd, bi


def nearest_on_screen(
    points: np.ndarray,
    view_projection: ArrayLike,
    size: tuple[float, float],
    cursor: tuple[float, float],
    radius_px: float,
    strand: np.ndarray,
    skip: np.ndarray | None = None,
) -> int:
    """Index of the vertex of ``points`` ((V, 3) float32) whose pixel (widget pixels, origin
    top-left, y down) is nearest ``cursor`` within ``radius_px``, leaving out the vertices of the
    strands flagged in ``skip`` ((S,) bool; ``strand``: each vertex's strand); −1 for none."""
    m = np.ascontiguousarray(view_projection, np.float64)
    best_d, best_i = np.empty(CHUNKS), np.empty(CHUNKS, np.int64)
    _nearest_kernel(
        readonly(points), m, float(size[0]), float(size[1]), float(cursor[0]), float(cursor[1]),
        float(radius_px) ** 2, readonly(strand), readonly(_NO_SKIP if skip is None else skip), best_d, best_i,
    )  # fmt: skip
    found = np.flatnonzero(best_i >= 0)
    if found.size == 0:
        return -1
    return int(best_i[found[np.argmin(best_d[found])]])  # argmin: the first (lowest-index) task


def nearest_on_screen_reference(
    camera, points: np.ndarray, size: tuple[float, float], cursor, radius_px: float, strand, skip=None
) -> int:
    """numpy twin of :func:`nearest_on_screen` through ``camera.project``."""
    xy = camera.project(points, size[0], size[1])
    d2 = ((xy - np.asarray(cursor, np.float64)) ** 2).sum(axis=1)
    near = d2 <= float(radius_px) ** 2
    if skip is not None:
        near &= ~np.asarray(skip)[strand]
    return int(np.argmin(np.where(near, d2, np.inf))) if near.any() else -1


PICKS = 16  # the strands a press tries, nearest first, for one the head does not hide


def nearest_in_sight(
    points: np.ndarray,
    view_projection: ArrayLike,
    size: tuple[float, float],
    cursor: tuple[float, float],
    radius_px: float,
    strand: np.ndarray,
    hidden: Callable[[np.ndarray], bool],
) -> int:
    """:func:`nearest_on_screen` over the vertices in sight: where ``hidden(point)`` says the
    head hides the nearest vertex from the camera, its strand is left out and the next nearest
    tried, at most :data:`PICKS` strands (a press on the crown seen from the face finds the
    crown's hair, not the hair behind the head); −1 for none."""
    skip = np.zeros(int(strand[-1]) + 1 if len(strand) else 0, np.bool_)
    for _ in range(PICKS):
        i = nearest_on_screen(points, view_projection, size, cursor, radius_px, strand, skip)
        if i < 0 or not hidden(points[i]):
            return i
        skip[strand[i]] = True
    return -1
