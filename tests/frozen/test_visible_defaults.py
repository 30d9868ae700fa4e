"""Every registered brush, at the studio's default strength, size and direction, changes a
Sintel-sized groom visibly in one stroke: a drag of twelve moves across the front of Sintel's
guides. A brush that moves vertices moves those under the stroke by a share of the groom's size
on average; one that paints a per-strand value changes it on most strands under the stroke;
one that removes or plants strands changes the strand or vertex count. A brush that keeps what
its first move took (a snake hook) starts at the front tips and is measured on the strands
under that move. Generated over the registry, so a new brush is held to it too."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from app.ui.brush_tool import BrushTool
from app.ui.scene import BRUSH_SHARE
from hairtool import io
from hairtool.frozen.brushes import registry
from hairtool.frozen.pipeline import FrozenParams, FrozenPipeline
from hairtool.guides.planting import HeadSurface
from hairtool.io.obj import read_mesh

DATA = Path(__file__).parents[1] / "data" / "grooms"
MOVES = 12
#: a mean move of this share of the groom's largest side is visible (a few pixels with the
#: groom framed in the viewport)
VISIBLE_MOVE = 0.005
VISIBLE_PAINT = 0.25  # the mean change of a painted value in [0, 1] over the strands under it
#: brushes that do not pass yet, and why (strict: one that starts to pass must leave the list)
NOT_YET = {
    "smooth": "Sintel's guides have no kinks for smooth to take out along a drag",
    "select": "a new groom has every strand selected, so select's first stroke changes nothing",
}


@pytest.fixture(scope="module")
def sintel():
    return io.read_groom(DATA / "sintel_hair.tfx"), HeadSurface(read_mesh(DATA / "sintel_head.obj"))


def stroke(tool: BrushTool, groom) -> list:
    """Twelve moves left to right across the front of the hair, a quarter down from its top
    (from the front tips for a brush that takes what its first move holds: a snake hook hooks
    the tips there), the camera looking at its front (-z)."""
    lo, hi = (b.astype(np.float64) for b in groom.bounds)
    r, mid = tool.radius[tool.brush], 0.5 * (lo[0] + hi[0])
    start = np.array([mid - 2.0 * r, hi[1] - 0.25 * (hi[1] - lo[1]), hi[2] - 0.3 * r])
    if registry.spec_of(tool.brush).keeps_stroke:
        front = groom.topology.tip_indices[np.argsort(groom.points[groom.topology.tip_indices, 2])[-20:]]
        start = groom.points[front].astype(np.float64).mean(axis=0) - np.array([2.0 * r, 0.0, 0.0])
    step = np.array([4.0 * r / (MOVES - 1), 0.0, 0.0])
    out = []
    for i in range(MOVES):
        out += tool.samples(start + i * step, step, (0.0, 0.0, -1.0), mid, start=i == 0)
    return out


def painted(pipe: FrozenPipeline) -> np.ndarray:
    """``(S, 3)`` what the painting brushes paint per strand: mask, clump strength, selection."""
    return np.column_stack([pipe.locked, pipe.clump_strength, pipe.selected]).astype(np.float64)


@pytest.mark.parametrize(
    "name",
    [pytest.param(n, marks=pytest.mark.xfail(reason=NOT_YET[n], strict=True)) if n in NOT_YET else n
     for n in registry.names()],
)  # fmt: skip
def test_each_brush_at_its_defaults_changes_sintel_visibly_in_one_stroke(sintel, name):
    groom, surface = sintel
    spec = registry.spec_of(name)
    lo, hi = (b.astype(np.float64) for b in groom.bounds)
    extent = float(np.max(hi - lo))
    tool = BrushTool()
    tool.reset_radius(BRUSH_SHARE * extent)  # as the studio sizes the brush for a new groom
    tool.set_brush(name)
    pipe = FrozenPipeline(groom, FrozenParams(), surface)
    before, flags = pipe.result, painted(pipe)
    samples = stroke(tool, groom)
    pipe.apply_samples(samples)
    after = pipe.settle()
    if spec.changes_strands:
        assert (after.strand_count, after.vertex_count) != (before.strand_count, before.vertex_count)
        return
    held = samples[:1] if spec.keeps_stroke else samples  # (a hook moves what its press took)
    cursors = np.array([s.cursor for s in held])
    near = np.linalg.norm(groom.points[:, None, :] - cursors[None], axis=2).min(axis=1) < tool.radius[name]
    top = groom.topology
    under = np.logical_or.reduceat(near, top.offsets[:-1])
    assert under.sum() >= 10  # the stroke crosses the hair
    if spec.moves_points:
        moved = np.linalg.norm(after.points - before.points, axis=1)[np.repeat(under, top.counts)]
        assert moved.mean() >= VISIBLE_MOVE * extent, f"{moved.mean() / extent:.4f} of the groom's size"
    else:
        change = np.abs(painted(pipe) - flags)[under].max(axis=1)
        assert change.mean() >= VISIBLE_PAINT, f"{change.mean():.3f} on average"


def test_a_mask_dab_on_the_crown_seen_from_the_front_masks_most_strands_under_it(sintel):
    """The crown's roots tilt back from a camera level with the face, but its hair is in sight:
    the studio's samples judge front faces by sight (:mod:`hairtool.frozen.brushes.sight`)."""
    groom, surface = sintel
    lo, hi = (b.astype(np.float64) for b in groom.bounds)
    tool = BrushTool()
    tool.reset_radius(BRUSH_SHARE * float(np.max(hi - lo)))
    tool.set_brush("mask")
    crown = groom.roots[np.argsort(groom.roots[:, 1])[-5]].astype(np.float64)
    pipe = FrozenPipeline(groom, FrozenParams(), surface)
    pipe.apply_samples(tool.samples(crown, (0.1, 0.0, 0.0), (0.0, 0.0, -1.0), 0.0, start=True))
    near = np.linalg.norm(groom.points - crown, axis=1) < tool.radius["mask"]
    under = np.logical_or.reduceat(near, groom.topology.offsets[:-1])
    assert pipe.locked[under].mean() >= 0.5
