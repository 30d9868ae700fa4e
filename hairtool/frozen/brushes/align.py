"""Align: the paper's UserAlign (Kim 2026, eqs. 8–13, :mod:`hairtool.frozen.align`) as a brush:
strands near the cursor turn toward it; masked, hidden and facing-away strands stay. Its
samples are :class:`AlignSample` (an intensity and a mode, no falloff)."""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from hairtool.frozen.align import align, align_reference, check_align_params
from hairtool.frozen.brushes.spec import Brush, BrushSpec, StrokeContext, Studio
from hairtool.groom import Groom, vertex_ids_of

SPEC = BrushSpec(
    name="align",
    order=0,
    local=True,
    studio=Studio(
        "Align",
        "Shift+C",
        "Strands turn toward the cursor's path (UserAlign, Kim 2026 eqs. 8–13)",
        0.8,
        place=0,
    ),
)


class AlignSample(NamedTuple):
    """One align sample; ``view`` as :class:`~hairtool.frozen.brushes.BrushSample`'s (None: every
    strand, as before the field existed)."""

    cursor: tuple[float, float, float]
    radius: float
    intensity: float
    mode: str
    view: tuple[float, float, float] | None = None
    collide: bool = True  # as BrushSample's
    only_selected: bool = False  # as BrushSample's
    pressure: float = 1.0  # as BrushSample's (already applied to radius and intensity)
    visible: bool = False  # as BrushSample's (front faces only by sight, not by root normal)
    eye: tuple[float, float, float] | None = None  # as BrushSample's (a perspective camera's eye)


def _locked_back(g: Groom, out: Groom, locked) -> Groom:
    """``out`` with the vertices of the strands ``locked`` where ``g`` has them."""
    if not locked.any():
        return out
    keep = vertex_ids_of(g.topology, np.flatnonzero(locked))
    pts = out.points.copy()
    pts[keep] = g.points[keep]
    return g.with_points(pts)


class Align(Brush):
    spec = SPEC

    def check(self, sample: AlignSample) -> None:
        check_align_params(sample.cursor, sample.radius, sample.intensity, sample.mode)

    def apply(self, ctx: StrokeContext, g: Groom, sample: AlignSample) -> Groom:
        out = align(g, sample.cursor, sample.radius, sample.intensity, sample.mode, planar=ctx.planar)
        return _locked_back(g, out, ctx.lock(sample))

    def reference(self, ctx: StrokeContext, g: Groom, sample: AlignSample) -> Groom:
        out = align_reference(g, sample.cursor, sample.radius, sample.intensity, sample.mode)
        return _locked_back(g, out, ctx.lock(sample))


BRUSH = Align()
