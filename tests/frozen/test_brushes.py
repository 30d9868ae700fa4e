"""The grooming brushes do what they say on a known groom: comb moves tips along the drag with
lengths kept, smooth lowers curvature with roots still, length changes lengths by the stated
amount, puff lifts tips away from the scalp, the mask locks strands bit for bit; falloff presets
order the displacement; X symmetry mirrors; each kernel equals its numpy twin."""

from __future__ import annotations

import numpy as np
import pytest

from hairtool import samples
from hairtool.errors import ParameterError
from hairtool.frozen.brushes import (
    BrushSample,
    any_within,
    any_within_reference,
    apply_brush,
    apply_brush_reference,
    falloff_lut,
    paint_mask,
    scalp_centre,
)
from hairtool.frozen.pipeline import FrozenParams, FrozenPipeline


@pytest.fixture(scope="module")
def groom():
    return samples.scalp(80, 12, seed=3)


def sample(brush, cursor, radius, strength, direction=(0.0, 0.0, 0.0), falloff="smooth"):
    lut = tuple(falloff_lut(falloff).tolist())
    return BrushSample(brush, tuple(map(float, cursor)), tuple(map(float, direction)), radius, strength, lut)


def free(g):
    return np.zeros(g.strand_count, bool)


def lengths(g):
    d = np.diff(g.points.astype(np.float64), axis=0)
    seg = np.linalg.norm(d, axis=1)
    inner = np.ones(len(seg), bool)
    inner[g.offsets[1:-1] - 1] = False  # not across strands
    return seg[inner]


def strand_lengths(g):
    p = g.points.astype(np.float64)
    ends = zip(g.offsets[:-1], g.offsets[1:], strict=True)
    return np.array([np.linalg.norm(np.diff(p[o:e], axis=0), axis=1).sum() for o, e in ends])


def centre_and_radius(g):
    tips = g.points[g.topology.tip_indices].astype(np.float64)
    return tips[len(tips) // 2], 0.6 * float(np.ptp(g.points, axis=0).max())


@pytest.mark.parametrize(
    "brush,strength", [("comb", 0.9), ("smooth", 0.8), ("length", -0.5), ("length", 0.4), ("puff", 0.7)]
)
@pytest.mark.parametrize("falloff", ["smooth", "linear", "constant", [[0, 1], [0.5, 0.2], [1, 0]]])
def test_kernels_equal_their_numpy_twin(groom, brush, strength, falloff):
    c, r = centre_and_radius(groom)
    s = sample(brush, c, r, strength, (0.4, -0.3, 0.2), falloff)
    locked = np.zeros(groom.strand_count, bool)
    locked[::7] = True
    centre = scalp_centre(groom)
    a, b = apply_brush(groom, s, locked, centre), apply_brush_reference(groom, s, locked, centre)
    np.testing.assert_allclose(a.points, b.points, rtol=0, atol=2e-6)
    assert not np.array_equal(a.points, groom.points)


def test_comb_moves_tips_along_the_drag_and_keeps_lengths(groom):
    c, r = centre_and_radius(groom)
    drag = np.array([0.5, 0.0, 0.0])
    out = apply_brush(groom, sample("comb", c, r, 1.0, drag), free(groom), scalp_centre(groom))
    tips = groom.topology.tip_indices
    moved = (out.points[tips] - groom.points[tips]).astype(np.float64)
    hit = np.linalg.norm(moved, axis=1) > 1e-6
    assert hit.sum() > 5
    assert np.all(moved[hit] @ drag > 0)  # along the drag
    np.testing.assert_allclose(lengths(out), lengths(groom), atol=1e-4)
    np.testing.assert_array_equal(out.roots, groom.roots)


def curvature(g):
    p = g.points.astype(np.float64)
    total = 0.0
    for o, e in zip(g.offsets[:-1], g.offsets[1:], strict=True):
        q = p[o:e]
        total += float(np.sum(np.linalg.norm(q[2:] - 2 * q[1:-1] + q[:-2], axis=1)))
    return total


def test_smooth_lowers_curvature_with_roots_still():
    wavy = samples.comb(strands=12, vertices=16)
    p = wavy.points.astype(np.float64).copy()
    p[:, 0] += 0.01 * np.sin(np.arange(len(p)) * 1.2)  # a gentle wave: 0.3 of a segment
    wavy = wavy.with_points(p.astype(np.float32))
    c = p.mean(axis=0)
    r = 2.0 * float(np.ptp(p, axis=0).max())
    out = wavy
    for _ in range(5):
        out = apply_brush(out, sample("smooth", c, r, 1.0), free(wavy), scalp_centre(wavy))
    assert curvature(out) < 0.5 * curvature(wavy)
    np.testing.assert_array_equal(out.roots, wavy.roots)
    np.testing.assert_allclose(lengths(out), lengths(wavy), atol=1e-4)


@pytest.mark.parametrize("strength", [-0.3, 0.25])
def test_length_changes_by_the_stated_fraction_at_the_centre(groom, strength):
    c, r = centre_and_radius(groom)
    s = sample("length", c, r, strength, falloff="constant")
    out = apply_brush(groom, s, free(groom), scalp_centre(groom))
    before, after = strand_lengths(groom), strand_lengths(out)
    # every strand with a vertex in the brush changes by exactly the stated fraction (constant falloff)
    changed = ~np.isclose(after, before, rtol=1e-6)
    assert changed.sum() > 5
    np.testing.assert_allclose(after[changed] / before[changed], 1 + strength, rtol=1e-5)


def test_puff_lifts_tips_away_from_the_scalp(groom):
    centre = scalp_centre(groom)
    c, r = centre_and_radius(groom)
    c = groom.roots[len(groom.roots) // 2]
    out = apply_brush(groom, sample("puff", c, r, 0.8), free(groom), centre)
    tips = groom.topology.tip_indices
    before = np.linalg.norm(groom.points[tips] - centre, axis=1)
    after = np.linalg.norm(out.points[tips] - centre, axis=1)
    moved = np.abs(after - before) > 1e-6
    assert moved.sum() > 5 and np.all(after[moved] > before[moved])
    np.testing.assert_allclose(lengths(out), lengths(groom), atol=1e-4)


def test_falloff_presets_order_the_displacement_at_mid_radius(groom):
    c, r = centre_and_radius(groom)
    moves = {}
    for name in ("constant", "linear", "smooth"):
        s = sample("comb", c, r, 1.0, (0.3, 0, 0), name)
        out = apply_brush(groom, s, free(groom), scalp_centre(groom))
        moves[name] = np.abs(out.points - groom.points).sum()
    assert moves["constant"] >= moves["linear"] >= moves["smooth"] > 0
    lut = {n: falloff_lut(n) for n in ("constant", "linear", "smooth")}
    mid = len(lut["linear"]) // 2
    assert lut["constant"][mid] == 1.0 and lut["linear"][mid] == 0.5 and lut["smooth"][mid] == 0.5
    assert lut["linear"][mid // 2] < lut["smooth"][mid // 2]


def test_the_mask_locks_strands_bit_for_bit_for_every_brush(groom):
    c, r = centre_and_radius(groom)
    pipe = FrozenPipeline(groom, FrozenParams(clump=False))
    pipe.brush(sample("mask", c, 0.5 * r, 1.0))
    locked = pipe.locked
    assert 0 < locked.sum() < groom.strand_count
    before = pipe.result.points.copy()
    pipe.brush(sample("comb", c, r, 1.0, (0.4, 0.1, 0)))
    pipe.brush(sample("length", c, r, 0.3))
    pipe.align(c + np.array([0.5, 0.5, 0.0]), r, 0.8)
    after = pipe.result
    from hairtool.groom import vertex_ids_of

    ids = vertex_ids_of(groom.topology, np.flatnonzero(locked))
    np.testing.assert_array_equal(after.points[ids], before[ids])
    assert not np.array_equal(after.points, before)
    freed = paint_mask(groom, sample("mask", c, 2 * r, -1.0), locked)
    assert not freed.any()


def test_symmetry_gives_mirrored_results():
    from hairtool.frozen.strokes import Stroke, StrokeSample
    from hairtool.groom import Groom

    g = samples.scalp(120, 10, seed=0)
    plane = float(np.median(g.roots[:, 0]))
    half = g.subset(np.flatnonzero(g.roots[:, 0] < plane))  # the left half and its reflection
    reflection = half.points.astype(np.float64)
    reflection[:, 0] = 2 * plane - reflection[:, 0]
    counts = half.topology.counts
    both = Groom(np.concatenate([half.points, reflection.astype(np.float32)]), np.r_[counts, counts])
    c = both.points[both.topology.tip_indices[3]].astype(float)
    drag = StrokeSample(tuple(c), 0.8, 1.0, (0.2, 0.1, 0.0))
    stroke = Stroke("comb", (drag,), symmetry="x", mirror_x=plane)
    pipe = FrozenPipeline(both, FrozenParams(freeze=False, clump=False))
    pipe.apply_samples(stroke.pipeline_samples(0.0))
    out = pipe.result.points.astype(np.float64)
    n = half.vertex_count
    left, right = out[:n], out[n:].copy()
    right[:, 0] = 2 * plane - right[:, 0]
    np.testing.assert_allclose(left, right, atol=1e-5)
    assert np.abs(out - both.points).max() > 1e-3


def test_bad_samples_are_one_clear_error(groom):
    with pytest.raises(ParameterError, match="strength"):
        apply_brush(groom, sample("comb", (0, 0, 0), 1.0, 2.0), free(groom), (0, 0, 0))
    with pytest.raises(ParameterError, match="radius"):
        apply_brush(groom, sample("puff", (0, 0, 0), 0.0, 0.5), free(groom), (0, 0, 0))
    with pytest.raises(ParameterError, match="falloff"):
        falloff_lut([[0, 1], [0.4, 2], [1, 0]])
    with pytest.raises(ParameterError, match="falloff"):
        falloff_lut("bumpy")


def test_a_refused_sample_leaves_the_pipeline_as_it_was(groom):
    c, r = centre_and_radius(groom)
    pipe = FrozenPipeline(groom, FrozenParams(clump=False))
    pipe.brush(sample("comb", c, r, 0.5, (0.1, 0, 0)))
    log, points, locked = pipe.strokes, pipe.result.points.copy(), pipe.locked
    with pytest.raises(ParameterError, match="strength"):
        bad = sample("comb", c, r, 7.0)
        pipe.apply_samples([sample("mask", c, r, 1.0), sample("smooth", c, r, 0.5), bad])
    assert pipe.strokes == log
    np.testing.assert_array_equal(pipe.result.points, points)
    np.testing.assert_array_equal(pipe.locked, locked)
    pipe.update()
    np.testing.assert_array_equal(pipe.result.points, points)


def test_whether_a_brush_reaches_the_groom_is_the_numpy_twins(groom):
    pts = groom.points
    rng = np.random.default_rng(5)
    lo, hi = groom.bounds
    answers = []
    for _ in range(40):
        c = rng.uniform(lo.astype(np.float64) - 0.3, hi.astype(np.float64) + 0.3)
        r = float(rng.choice([1e-3, 0.02, 0.2]))
        answers.append(any_within(pts, c, r))
        assert answers[-1] == any_within_reference(pts, c, r)
    assert any(answers) and not all(answers)
    assert any_within(pts, pts[7].astype(np.float64) + np.array([0.5, 0.0, 0.0]), 0.5)  # on the circle
