"""Snake hook: at a stroke's first sample the strands whose tip lies within the radius are
hooked, each with the weight h = strength·w of its tip and its tip's position a there. Every
sample of the stroke pulls the tip of each hooked strand toward a + h·(cursor − the cursor at
the start), so a tip hooked at the centre (h = 1) runs along the cursor's path, and the strand
follows it with its root fixed and every segment length kept: rounds of follow-the-leader from
the pulled tip toward the root and back from the fixed root toward the tip (FABRIK,
:func:`~.constraints.place`) until the tip is there (or HOOK_ROUNDS), the last from the root, so
lengths are exact up to float32 rounding; where the target is out of reach the strand points at
it. The hooked strands are the stroke's memory (:class:`~.spec.StrokeMemory`): one set per start
sample (the stroke's and its mirror's), used in turn.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange
from numpy.typing import ArrayLike, NDArray

from hairtool.frozen.brushes.constraints import dist, place, place_reference
from hairtool.frozen.brushes.falloff import end_weights, end_weights_reference
from hairtool.frozen.brushes.sample import BrushSample
from hairtool.frozen.brushes.spec import Brush, BrushSpec, StrokeContext, Studio
from hairtool.frozen.brushes.strand_moves import checked, moved_groom
from hairtool.groom import Groom

F64 = NDArray[np.float64]

HOOK_ROUNDS = 256  # most FABRIK rounds per snake-hook sample (near full stretch it converges slowly)
HOOK_TOLERANCE = 1e-7  # of the strand's length: a tip this close to its target is there

SPEC = BrushSpec(
    name="snake_hook",
    order=9,
    keeps_stroke=True,
    studio=Studio(
        "Snake Hook",
        "K",
        "The strands whose tips are under the brush when you press follow the "
        "cursor, roots fixed, lengths kept",
        1.0,
        place=8,
    ),
)


def hook_weights(groom: Groom, sample: BrushSample, locked: ArrayLike) -> F64:
    """``(S,)`` the weight h = strength·w(tip) with which a snake-hook stroke's first sample
    hooks each strand (0: not hooked; masked or facing-away strands are not) (numba)."""
    checked(sample, "snake_hook")
    return end_weights(groom.tips, sample, locked)


def hook_weights_reference(groom: Groom, sample: BrushSample, locked: ArrayLike) -> F64:
    """Numpy twin of :func:`hook_weights`."""
    checked(sample, "snake_hook")
    return end_weights_reference(groom.tips, sample, locked)


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
            total += dist(p, i, i - 1)
        for _ in range(rounds):
            dx, dy, dz = out[e - 1, 0] - tx, out[e - 1, 1] - ty, out[e - 1, 2] - tz
            if np.sqrt(dx * dx + dy * dy + dz * dz) <= tolerance * total:
                break
            out[e - 1, 0], out[e - 1, 1], out[e - 1, 2] = tx, ty, tz
            for i in range(e - 2, o - 1, -1):  # the tip leads, toward the root
                place(out, i, i + 1, dist(p, i, i + 1),
                       p[i, 0] - p[i + 1, 0], p[i, 1] - p[i + 1, 1], p[i, 2] - p[i + 1, 2])  # fmt: skip
            out[o, 0], out[o, 1], out[o, 2] = p[o, 0], p[o, 1], p[o, 2]
            for i in range(o + 1, e):  # the root leads, toward the tip
                place(out, i, i - 1, dist(p, i, i - 1),
                       p[i, 0] - p[i - 1, 0], p[i, 1] - p[i - 1, 1], p[i, 2] - p[i - 1, 2])  # fmt: skip


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
    return moved_groom(groom, out)


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
                place_reference(q, i, i + 1, lengths[i], -seg[i])
            q[0] = p[0]
            for i in range(1, len(p)):
                place_reference(q, i, i - 1, lengths[i - 1], seg[i - 1])
    return moved_groom(groom, out)


class SnakeHook(Brush):
    spec = SPEC

    def _hooked(self, ctx: StrokeContext, g: Groom, sample: BrushSample, weigh) -> tuple:
        """A start hooks strands (a run of starts, one set each); the later samples use the sets in turn."""
        memory = ctx.memory
        if sample.start or not memory.entries:
            if not memory.starting:
                memory.entries = []
            hook = weigh(g, sample, ctx.lock(sample))
            memory.entries.append((hook, g.tips.astype(np.float64), np.asarray(sample.cursor, np.float64)))
            memory.starting, memory.next = True, len(memory.entries) - 1
        else:
            memory.starting = False
            memory.next = (memory.next + 1) % len(memory.entries)
        return memory.entries[memory.next]

    def apply(self, ctx: StrokeContext, g: Groom, sample) -> Groom:
        hook, anchors, start = self._hooked(ctx, g, sample, hook_weights)
        return snake_hook(g, hook, anchors, np.asarray(sample.cursor, np.float64) - start)

    def reference(self, ctx: StrokeContext, g: Groom, sample) -> Groom:
        hook, anchors, start = self._hooked(ctx, g, sample, hook_weights_reference)
        return snake_hook_reference(g, hook, anchors, np.asarray(sample.cursor, np.float64) - start)


BRUSH = SnakeHook()
