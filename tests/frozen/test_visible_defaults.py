"""Every registered brush, at the studio's default strength, size and direction, changes a
Sintel-sized groom visibly in one stroke: a drag of twelve moves across the front of Sintel's
guides. A brush that moves vertices moves those under the stroke by a share of the groom's size
on average; one that paints a per-strand value changes it on most strands under the stroke;
one whose plain stroke starts anew (select: a new selection) changes it on most strands of the
groom and leaves it set on most of those under the stroke; one that removes or plants strands
changes the strand or vertex count. A brush that keeps what its first move took (a snake hook)
starts at the front tips and is measured on the strands under that move. A brush that takes out
bends (smooth) has none to take out of Sintel's guides, so it strokes them kinked first (a
seeded zig-zag along every strand) and must take a share of the kinks out of the vertices under
the stroke (of the brushed guides: the clumping the pipeline adds after them bends them again,
its own way, on every stroke). Generated over the registry, so a new brush is held to it too."""

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
#: the kinks' zig-zag, of the mean segment length (each inner vertex turns its strand by about
#: 11°, a fine crinkle), and the share of the mean turning angle over the vertices under the
#: stroke a brush that takes out bends must remove
KINK = 0.05
VISIBLE_STRAIGHTENING = 0.25
#: brushes that do not pass yet, and why (strict: one that starts to pass must leave the list)
NOT_YET: dict[str, str] = {}


@pytest.fixture(scope="module")
def sintel():
    return io.read_groom(DATA / "sintel_hair.tfx"), HeadSurface(read_mesh(DATA / "sintel_head.obj"))


def kinked(groom):
    """``groom`` with every vertex but the root pushed to alternate sides of its strand, along a
    direction drawn per strand (seeded), by :data:`KINK` of the mean segment length."""
    top, p = groom.topology, groom.points.astype(np.float64)
    inner = top.strand_index[:-1] == top.strand_index[1:]
    segment = float(np.linalg.norm(np.diff(p, axis=0), axis=1)[inner].mean())
    side = np.random.default_rng(47).normal(size=(groom.strand_count, 3))
    side /= np.linalg.norm(side, axis=1, keepdims=True)
    k = np.arange(groom.vertex_count) - np.repeat(top.offsets[:-1], top.counts)  # 0 at the root
    zig = np.where(k % 2 == 1, 1.0, -1.0) * (k > 0)
    return groom.with_points((p + KINK * segment * zig[:, None] * side[top.strand_index]).astype(np.float32))


def turning(groom, points) -> np.ndarray:
    """``(V,)`` the angle (radians) each inner vertex turns its strand by; NaN at roots and tips."""
    top, q = groom.topology, points.astype(np.float64)
    e = np.diff(q, axis=0)
    a, b = e[:-1], e[1:]
    cos = np.einsum("ij,ij->i", a, b) / np.maximum(
        np.linalg.norm(a, axis=1) * np.linalg.norm(b, axis=1), 1e-300
    )
    inner = top.strand_index[:-1] == top.strand_index[1:]
    out = np.full(top.vertex_count, np.nan)
    out[1:-1] = np.where(inner[:-1] & inner[1:], np.arccos(np.clip(cos, -1.0, 1.0)), np.nan)
    return out


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
    if spec.straightens:
        groom = kinked(groom)
    lo, hi = (b.astype(np.float64) for b in groom.bounds)
    extent = float(np.max(hi - lo))
    tool = BrushTool()
    tool.reset_radius(BRUSH_SHARE * extent)  # as the studio sizes the brush for a new groom
    tool.set_brush(name)
    pipe = FrozenPipeline(groom, FrozenParams(), surface)
    before, groomed, flags = pipe.result, pipe.aligned, painted(pipe)
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
    if spec.straightens:  # on the brushed guides: the clumping after them bends them its own way
        turned = turning(groom, groomed.points), turning(groom, pipe.aligned.points)
        kinks = near & ~np.isnan(turned[0])
        was, now = turned[0][kinks].mean(), turned[1][kinks].mean()
        assert now <= (1.0 - VISIBLE_STRAIGHTENING) * was, f"mean turn {was:.3f} -> {now:.3f} rad"
    elif spec.moves_points:
        moved = np.linalg.norm(after.points - before.points, axis=1)[np.repeat(under, top.counts)]
        assert moved.mean() >= VISIBLE_MOVE * extent, f"{moved.mean() / extent:.4f} of the groom's size"
    elif spec.starts_anew:  # a new selection: what it leaves set is judged over every strand
        change = np.abs(painted(pipe) - flags).max(axis=1)
        assert change.mean() >= VISIBLE_PAINT, f"{change.mean():.3f} on average over the groom"
        assert change[under].mean() <= 1.0 - VISIBLE_PAINT, f"{change[under].mean():.3f} under the stroke"
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
