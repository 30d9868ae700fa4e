"""Cut (Blender's curves Cut brush): the strands under the brush are cut where they first enter
it, at the brush's surface (the sphere of its radius around the cursor).

Walking a strand from its root, at the first vertex inside the sphere the strand ends: the
vertices from there on leave, and a new tip is placed where the segment that enters crosses the
sphere (its per-vertex attributes interpolated there). A strand whose root lies inside the
brush is left whole (removing strands is delete's), and so are masked, hidden and facing-away
strands, and every strand with strength 0. The strand count and order stay; the pipeline keeps
the strands' state, undo brings back the cut parts (the snapshot holds the groom before), and a
stroke log names the brush ``cut``. The per-strand search is a numba kernel with a numpy twin.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange
from numpy.typing import ArrayLike

from hairtool.frozen.brushes.sample import BrushSample
from hairtool.frozen.brushes.spec import Brush, BrushSpec, StrokeContext, Studio
from hairtool.frozen.brushes.strand_moves import checked
from hairtool.groom import Groom

SPEC = BrushSpec(
    name="cut",
    order=14,
    moves_points=False,
    changes_strands=True,
    takes_strength=False,
    studio=Studio(
        "Cut",
        "Shift+T",
        "Cuts the strands under the brush where they enter it (undo brings the ends back)",
        1.0,
    ),
)


@njit(cache=True, nogil=True, parallel=True)
def _cut_kernel(p, offsets, locked, c, radius, kept, t_out, tips):  # pragma: no cover - compiled
    r2 = radius * radius
    for s in prange(offsets.size - 1):
        o, e = offsets[s], offsets[s + 1]
        kept[s], t_out[s] = e - o, -1.0
        if locked[s] or e - o < 2:
            continue
        fx, fy, fz = p[o, 0] - c[0], p[o, 1] - c[1], p[o, 2] - c[2]
        if fx * fx + fy * fy + fz * fz < r2:
            continue  # the root is inside
        for i in range(o + 1, e):
            fx, fy, fz = p[i, 0] - c[0], p[i, 1] - c[1], p[i, 2] - c[2]
            if fx * fx + fy * fy + fz * fz >= r2:
                continue
            dx, dy, dz = p[i, 0] - p[i - 1, 0], p[i, 1] - p[i - 1, 1], p[i, 2] - p[i - 1, 2]
            fx, fy, fz = p[i - 1, 0] - c[0], p[i - 1, 1] - c[1], p[i - 1, 2] - c[2]
            a = dx * dx + dy * dy + dz * dz
            b = fx * dx + fy * dy + fz * dz
            q = fx * fx + fy * fy + fz * fz - r2
            t = (-b - np.sqrt(max(b * b - a * q, 0.0))) / a  # |f + t·d| = r, the entering root
            t = min(t, 1.0)
            if t > 0.0:
                kept[s], t_out[s] = i - o, t
                tips[s, 0], tips[s, 1], tips[s, 2] = (
                    p[i - 1, 0] + t * dx,
                    p[i - 1, 1] + t * dy,
                    p[i - 1, 2] + t * dz,
                )
            break


def cut_points(
    groom: Groom, sample: BrushSample, locked: ArrayLike
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Where one cut sample cuts each strand (numba).

    Parameters
    ----------
    groom : Groom
        The groom before the sample.
    sample : BrushSample
        A cut sample (strength 0 cuts nothing).
    locked : array_like, ``(S,)`` bool
        Strands left whole.

    Returns
    -------
    kept : numpy.ndarray
        ``(S,)`` int64 vertices each strand keeps before its new tip (all of them where uncut).
    t : numpy.ndarray
        ``(S,)`` float64 where the new tip lies on the segment after the kept vertices, in (0, 1];
        −1 for a strand not cut.
    tips : numpy.ndarray
        ``(S, 3)`` float64 the new tips (rows of uncut strands undefined).
    """
    checked(sample, "cut")
    s = groom.strand_count
    kept, t, tips = np.empty(s, np.int64), np.empty(s), np.zeros((s, 3))
    lock = np.asarray(locked, np.bool_) | (sample.strength <= 0)
    c = np.asarray(sample.cursor, np.float64)
    _cut_kernel(groom.points.astype(np.float64), groom.offsets, lock, c, float(sample.radius), kept, t, tips)
    return kept, t, tips


def cut_points_reference(
    groom: Groom, sample: BrushSample, locked: ArrayLike
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Numpy twin of :func:`cut_points`."""
    checked(sample, "cut")
    s_count = groom.strand_count
    kept, t_out, tips = groom.counts.astype(np.int64), np.full(s_count, -1.0), np.zeros((s_count, 3))
    lock = np.asarray(locked, bool) | (sample.strength <= 0)
    c, r2 = np.asarray(sample.cursor, np.float64), float(sample.radius) ** 2
    p_all = groom.points.astype(np.float64)
    for s, (o, e) in enumerate(zip(groom.offsets[:-1], groom.offsets[1:], strict=True)):
        if lock[s] or e - o < 2:
            continue
        f = p_all[o:e] - c
        inside = f[:, 0] * f[:, 0] + f[:, 1] * f[:, 1] + f[:, 2] * f[:, 2] < r2
        if inside[0] or not inside.any():
            continue
        i = int(np.argmax(inside))
        d, f0 = p_all[o + i] - p_all[o + i - 1], f[i - 1]
        a = d[0] * d[0] + d[1] * d[1] + d[2] * d[2]
        b = f0[0] * d[0] + f0[1] * d[1] + f0[2] * d[2]
        q = f0[0] * f0[0] + f0[1] * f0[1] + f0[2] * f0[2] - r2
        t = min((-b - np.sqrt(max(b * b - a * q, 0.0))) / a, 1.0)
        if t > 0.0:
            kept[s], t_out[s] = i, t
            tips[s] = [p_all[o + i - 1, k] + t * d[k] for k in range(3)]
    return kept, t_out, tips


def cut_groom(groom: Groom, kept: np.ndarray, t: np.ndarray, tips: np.ndarray) -> Groom:
    """The groom with each cut strand ending at its new tip (:func:`cut_points`' output).

    Parameters
    ----------
    groom : Groom
        The groom before the cut.
    kept, t, tips : numpy.ndarray
        As :func:`cut_points` returns them.

    Returns
    -------
    Groom
        The cut groom (``groom`` itself where no strand is cut); per-vertex attributes are
        interpolated at the new tips.
    """
    cut = t > 0.0
    if not cut.any():
        return groom
    counts = kept + cut
    new_off = np.concatenate([[0], np.cumsum(counts)])
    src = np.arange(new_off[-1]) - np.repeat(new_off[:-1] - groom.offsets[:-1], counts)
    tip_rows = new_off[1:][cut] - 1  # (their source: the first vertex inside, replaced)
    before, w = src[tip_rows] - 1, t[cut].astype(np.float32)
    points = groom.points[src]
    points[tip_rows] = tips[cut].astype(np.float32)
    attrs = {}
    for name, a in groom.attributes.items():
        if a is None:
            attrs[name] = None
            continue
        rows = a[src]
        step = w if a.ndim == 1 else w[:, None]
        rows[tip_rows] = a[before] + step * (a[before + 1] - a[before])
        attrs[name] = rows
    return Groom(points, counts, **attrs, metadata=groom.metadata.with_(curves=()))


class Cut(Brush):
    spec = SPEC

    def apply(self, ctx: StrokeContext, g: Groom, sample) -> Groom:
        return cut_groom(g, *cut_points(g, sample, ctx.lock(sample)))

    def reference(self, ctx: StrokeContext, g: Groom, sample) -> Groom:
        return cut_groom(g, *cut_points_reference(g, sample, ctx.lock(sample)))


BRUSH = Cut()
