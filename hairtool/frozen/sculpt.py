"""Posing and trimming brushes after Blender's curves sculpt set: delete, pinch and snake hook.

- delete: the strands whose root lies within the radius of the cursor (falloff ignored; masked
  and back-facing strands spared) leave the groom. The pipeline records which strands remain
  (:attr:`~hairtool.frozen.pipeline.FrozenPipeline.origin`), so undo and replay are exact.
- pinch: every vertex but the root moves toward the brush centre by the fraction strength·w of
  its distance to it (w the falloff weight at the vertex; strength < 0 spreads away from the
  centre), then each segment gets its length back root to tip (follow-the-leader, as comb does).
- snake hook: at a stroke's first sample the strands whose tip lies within the radius are
  hooked, each with the weight h = strength·w of its tip and its tip's position a there. Every
  sample of the stroke pulls the tip of each hooked strand toward a + h·(cursor − the cursor at
  the start), so a tip hooked at the centre (h = 1) runs along the cursor's path, and the strand
  follows it with its root fixed and every segment length kept: rounds of follow-the-leader from
  the pulled tip toward the root and back from the fixed root toward the tip (FABRIK) until the
  tip is there (or HOOK_ROUNDS), the last from the root, so lengths are exact up to float32
  rounding; where the target is out of reach the strand points at it.

Each kernel (numba) has a numpy twin (``*_reference``) computing the same bytes.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange
from numpy.typing import ArrayLike, NDArray

from hairtool.errors import ParameterError
from hairtool.frozen.brushes import (
    EPS,
    BrushSample,
    _restore_lengths,
    _restore_lengths_reference,
    _weight,
    _weights_reference,
    check_sample,
)
from hairtool.groom import Groom

F64 = NDArray[np.float64]

HOOK_ROUNDS = 256  # most FABRIK rounds per snake-hook sample (near full stretch it converges slowly)
HOOK_TOLERANCE = 1e-7  # of the strand's length: a tip this close to its target is there


# -- delete ------------------------------------------------------------------------------------
@njit(cache=True, nogil=True, parallel=True)
def _under_kernel(roots, c, radius, locked, out):  # pragma: no cover - compiled
    for s in prange(roots.shape[0]):
        dx, dy, dz = roots[s, 0] - c[0], roots[s, 1] - c[1], roots[s, 2] - c[2]
        out[s] = not locked[s] and np.sqrt(dx * dx + dy * dy + dz * dz) / radius < 1.0


def strands_to_delete(groom: Groom, sample: BrushSample, locked: ArrayLike) -> np.ndarray:
    """``(S,)`` the strands one delete sample removes: root within the radius, not ``locked``
    (masked or facing away), and only with strength > 0 (numba)."""
    _check(sample, "delete")
    out = np.zeros(groom.strand_count, dtype=np.bool_)
    if sample.strength > 0:
        _under_kernel(
            groom.roots.astype(np.float64), np.asarray(sample.cursor, np.float64), float(sample.radius),
            np.asarray(locked, np.bool_), out,
        )  # fmt: skip
    return out


def strands_to_delete_reference(groom: Groom, sample: BrushSample, locked: ArrayLike) -> np.ndarray:
    """Numpy twin of :func:`strands_to_delete`."""
    _check(sample, "delete")
    r = groom.roots.astype(np.float64)
    inside = np.linalg.norm(r - np.asarray(sample.cursor, np.float64), axis=1) / sample.radius < 1.0
    return inside & ~np.asarray(locked, bool) & (sample.strength > 0)


# -- pinch -------------------------------------------------------------------------------------
@njit(cache=True, nogil=True, parallel=True)
def _pinch_kernel(p, offsets, locked, c, radius, strength, lut, out):  # pragma: no cover - compiled
    for s in prange(offsets.size - 1):
        o, e = offsets[s], offsets[s + 1]
        for i in range(o, e):
            out[i, 0], out[i, 1], out[i, 2] = p[i, 0], p[i, 1], p[i, 2]
        if locked[s] or e - o < 2:
            continue
        moved = False
        for i in range(o + 1, e):
            w = _weight(p[i, 0], p[i, 1], p[i, 2], c, radius, lut) * strength
            if w == 0.0:
                continue
            moved = True
            for a in range(3):
                out[i, a] = p[i, a] + w * (c[a] - p[i, a])
        if moved:
            _restore_lengths(out, p, o, e - o)


def pinch(groom: Groom, sample: BrushSample, locked: ArrayLike) -> Groom:
    """One pinch sample (numba): vertices toward the centre (away with strength < 0), roots
    fixed, lengths kept."""
    _check(sample, "pinch")
    out = np.empty((groom.vertex_count, 3))
    _pinch_kernel(
        groom.points.astype(np.float64), groom.offsets, np.asarray(locked, np.bool_),
        np.asarray(sample.cursor, np.float64), float(sample.radius), float(sample.strength),
        np.asarray(sample.lut, np.float64), out,
    )  # fmt: skip
    return groom.with_points(out.astype(np.float32))


def pinch_reference(groom: Groom, sample: BrushSample, locked: ArrayLike) -> Groom:
    """Numpy twin of :func:`pinch`."""
    _check(sample, "pinch")
    p_all = groom.points.astype(np.float64)
    out = p_all.copy()
    c, lut = np.asarray(sample.cursor, np.float64), np.asarray(sample.lut, np.float64)
    locked = np.asarray(locked, bool)
    for s, (o, e) in enumerate(zip(groom.offsets[:-1], groom.offsets[1:], strict=True)):
        p = p_all[o:e]
        if locked[s] or len(p) < 2:
            continue
        w = _weights_reference(p, c, sample.radius, lut) * sample.strength
        w[0] = 0.0
        if not np.any(w != 0):
            continue
        q = p + w[:, None] * (c - p)
        out[o:e] = _restore_lengths_reference(q, p)
    return groom.with_points(out.astype(np.float32))


# -- snake hook --------------------------------------------------------------------------------
@njit(cache=True, nogil=True, parallel=True)
def _hook_weights_kernel(tips, c, radius, strength, lut, locked, out):  # pragma: no cover - compiled
    for s in prange(tips.shape[0]):
        out[s] = 0.0 if locked[s] else _weight(tips[s, 0], tips[s, 1], tips[s, 2], c, radius, lut) * strength


def end_weights(ends: ArrayLike, sample: BrushSample, locked: ArrayLike) -> F64:
    """``(S,)`` strength × falloff weight of one point per strand (its tip, its root), 0 where
    ``locked`` (numba)."""
    ends = np.ascontiguousarray(ends, np.float64)
    out = np.empty(len(ends))
    _hook_weights_kernel(
        ends, np.asarray(sample.cursor, np.float64), float(sample.radius), float(sample.strength),
        np.asarray(sample.lut, np.float64), np.asarray(locked, np.bool_), out,
    )  # fmt: skip
    return out


def hook_weights(groom: Groom, sample: BrushSample, locked: ArrayLike) -> F64:
    """``(S,)`` the weight h = strength·w(tip) with which a snake-hook stroke's first sample
    hooks each strand (0: not hooked; masked or facing-away strands are not) (numba)."""
    _check(sample, "snake_hook")
    return end_weights(groom.tips, sample, locked)


def hook_weights_reference(groom: Groom, sample: BrushSample, locked: ArrayLike) -> F64:
    """Numpy twin of :func:`hook_weights`."""
    _check(sample, "snake_hook")
    lut = np.asarray(sample.lut, np.float64)
    w = _weights_reference(groom.tips.astype(np.float64), np.asarray(sample.cursor, np.float64),
                           sample.radius, lut) * sample.strength  # fmt: skip
    return np.where(np.asarray(locked, bool), 0.0, w)


@njit(cache=True, nogil=True, inline="always")
def _place(q, i, j, length, fx, fy, fz):  # pragma: no cover - compiled
    """q[i] at ``length`` from q[j], toward where q[i] is (along f where it sits on q[j])."""
    dx, dy, dz = q[i, 0] - q[j, 0], q[i, 1] - q[j, 1], q[i, 2] - q[j, 2]
    d = np.sqrt(dx * dx + dy * dy + dz * dz)
    if d < EPS:
        dx, dy, dz = fx, fy, fz
        d = np.sqrt(dx * dx + dy * dy + dz * dz)
    s = length / d if d >= EPS else 0.0
    q[i, 0] = q[j, 0] + dx * s
    q[i, 1] = q[j, 1] + dy * s
    q[i, 2] = q[j, 2] + dz * s


@njit(cache=True, nogil=True, parallel=True)
def _snake_kernel(p, offsets, hook, anchors, offset, rounds, tolerance, out):  # pragma: no cover
    for s in prange(offsets.size - 1):
        o, e = offsets[s], offsets[s + 1]
        for i in range(o, e):
            out[i, 0], out[i, 1], out[i, 2] = p[i, 0], p[i, 1], p[i, 2]
        h = hook[s]
        if h == 0.0 or e - o < 2:
            continue
        tx = anchors[s, 0] + h * offset[0]
        ty = anchors[s, 1] + h * offset[1]
        tz = anchors[s, 2] + h * offset[2]
        total = 0.0
        for i in range(o + 1, e):
            total += _dist(p, i, i - 1)
        for _ in range(rounds):
            dx, dy, dz = out[e - 1, 0] - tx, out[e - 1, 1] - ty, out[e - 1, 2] - tz
            if np.sqrt(dx * dx + dy * dy + dz * dz) <= tolerance * total:
                break
            out[e - 1, 0], out[e - 1, 1], out[e - 1, 2] = tx, ty, tz
            for i in range(e - 2, o - 1, -1):  # the tip leads, toward the root
                _place(out, i, i + 1, _dist(p, i, i + 1),
                       p[i, 0] - p[i + 1, 0], p[i, 1] - p[i + 1, 1], p[i, 2] - p[i + 1, 2])  # fmt: skip
            out[o, 0], out[o, 1], out[o, 2] = p[o, 0], p[o, 1], p[o, 2]
            for i in range(o + 1, e):  # the root leads, toward the tip
                _place(out, i, i - 1, _dist(p, i, i - 1),
                       p[i, 0] - p[i - 1, 0], p[i, 1] - p[i - 1, 1], p[i, 2] - p[i - 1, 2])  # fmt: skip


@njit(cache=True, nogil=True, inline="always")
def _dist(p, i, j):  # pragma: no cover - compiled
    dx, dy, dz = p[i, 0] - p[j, 0], p[i, 1] - p[j, 1], p[i, 2] - p[j, 2]
    return np.sqrt(dx * dx + dy * dy + dz * dz)


def snake_hook(groom: Groom, hook: ArrayLike, anchors: ArrayLike, offset: ArrayLike) -> Groom:
    """One snake-hook sample (numba): the tip of each strand s with ``hook[s]`` ≠ 0 pulled to
    ``anchors[s] + hook[s]·offset`` (``offset``: the cursor's way since the stroke's start), the
    strand following with its root fixed, lengths kept."""
    out = np.empty((groom.vertex_count, 3))
    _snake_kernel(
        groom.points.astype(np.float64), groom.offsets, np.ascontiguousarray(hook, np.float64),
        np.ascontiguousarray(anchors, np.float64), np.asarray(offset, np.float64), HOOK_ROUNDS,
        HOOK_TOLERANCE, out,
    )  # fmt: skip
    return groom.with_points(out.astype(np.float32))


def _place_reference(q: F64, i: int, j: int, length: float, fallback: F64) -> None:
    d = q[i] - q[j]
    if np.sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]) < EPS:
        d = fallback
    n = np.sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2])
    q[i] = q[j] + d * (length / n if n >= EPS else 0.0)


def snake_hook_reference(groom: Groom, hook: ArrayLike, anchors: ArrayLike, offset: ArrayLike) -> Groom:
    """Numpy twin of :func:`snake_hook`."""
    p_all = groom.points.astype(np.float64)
    out = p_all.copy()
    hook, anchors = np.asarray(hook, np.float64), np.asarray(anchors, np.float64)
    offset = np.asarray(offset, np.float64)
    for s, (o, e) in enumerate(zip(groom.offsets[:-1], groom.offsets[1:], strict=True)):
        if hook[s] == 0.0 or e - o < 2:
            continue
        p, q = p_all[o:e], out[o:e]
        seg = np.diff(p, axis=0)
        lengths = np.sqrt(seg[:, 0] * seg[:, 0] + seg[:, 1] * seg[:, 1] + seg[:, 2] * seg[:, 2])
        total = 0.0
        for x in lengths:
            total += x
        target = anchors[s] + hook[s] * offset
        for _ in range(HOOK_ROUNDS):
            miss = q[-1] - target
            if np.sqrt(miss[0] * miss[0] + miss[1] * miss[1] + miss[2] * miss[2]) <= HOOK_TOLERANCE * total:
                break
            q[-1] = target
            for i in range(len(p) - 2, -1, -1):
                _place_reference(q, i, i + 1, lengths[i], -seg[i])
            q[0] = p[0]
            for i in range(1, len(p)):
                _place_reference(q, i, i - 1, lengths[i - 1], seg[i - 1])
    return groom.with_points(out.astype(np.float32))


def _check(sample: BrushSample, brush: str) -> None:
    check_sample(sample)
    if sample.brush != brush:
        raise ParameterError("brush", sample.brush, brush)
