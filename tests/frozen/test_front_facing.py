"""Front-facing brushes: a sample with the camera's viewing direction touches only the strands
whose root faces that camera (every brush, align and the mask); without one, nothing changes;
mirrored samples mirror the camera too; the kernel equals its numpy twin."""

from __future__ import annotations

import numpy as np
import pytest

from hairtool import samples
from hairtool.errors import ParameterError
from hairtool.frozen.brushes import (
    BrushSample,
    facing_away,
    facing_away_reference,
    falloff_lut,
    root_normals,
    scalp_centre,
)
from hairtool.frozen.pipeline import AlignSample, FrozenParams, FrozenPipeline
from hairtool.groom import Groom

VIEW = (0.0, 0.0, -1.0)  # an eye on +z looking toward −z: strands rooted at z < centre face away


@pytest.fixture(scope="module")
def head():
    return samples.scalp(240, 8, seed=5)


def pipe_of(groom):
    return FrozenPipeline(groom, FrozenParams(freeze=False, clump=False))


def sample(groom, brush, strength, view, direction=(0.0, -0.3, 0.2)):
    lut = tuple(falloff_lut("constant").tolist())
    c = groom.points.astype(np.float64).mean(axis=0)
    r = float(np.ptp(groom.points, axis=0).max())  # covers the whole groom
    return BrushSample(brush, tuple(c), direction, r, strength, lut, view)


def strand_moved(before: Groom, after: Groom) -> np.ndarray:
    diff = np.any(before.points != after.points, axis=1)
    return np.maximum.reduceat(diff, before.offsets[:-1]).astype(bool)


def away_of(groom):
    n = root_normals(groom)
    return n @ np.asarray(VIEW) > 0


def test_root_normals_point_out_of_the_head(head):
    n = root_normals(head)
    out = head.roots.astype(np.float64) - scalp_centre(head)
    np.testing.assert_allclose(np.linalg.norm(n, axis=1), 1.0, atol=1e-12)
    assert np.all(np.einsum("ij,ij->i", n, out) > 0)


def test_facing_away_kernel_equals_its_twin(head):
    n = root_normals(head)
    for view in [VIEW, (0.3, -0.5, 0.8), (1.0, 0.0, 0.0)]:
        np.testing.assert_array_equal(facing_away(n, view), facing_away_reference(n, view))
    away = facing_away(n, VIEW)
    assert 0.25 * len(n) < away.sum() < 0.75 * len(n)


@pytest.mark.parametrize("brush,strength", [("comb", 1.0), ("smooth", 1.0), ("length", 0.3), ("puff", 0.8)])
def test_a_stroke_touches_only_the_strands_facing_the_camera(head, brush, strength):
    away = away_of(head)
    everywhere = pipe_of(head).brush(sample(head, brush, strength, None))
    front = pipe_of(head).brush(sample(head, brush, strength, VIEW))
    hit_all, hit_front = strand_moved(head, everywhere), strand_moved(head, front)
    assert hit_all[away].sum() > 10  # without a view the far side moves too
    assert not hit_front[away].any()  # with it, bit for bit untouched
    assert hit_front[~away].sum() > 10
    keep = np.repeat(~away, head.counts)
    np.testing.assert_array_equal(front.points[keep], everywhere.points[keep])


def test_align_and_the_mask_are_front_facing_too(head):
    away = away_of(head)
    c = head.points.astype(np.float64).mean(axis=0)
    r = float(np.ptp(head.points, axis=0).max())
    p = pipe_of(head)
    out = p.apply_samples([AlignSample(tuple(c + np.array([0.0, -0.5, 0.0])), r, 0.8, "paper", VIEW)])
    assert not strand_moved(head, out)[away].any()
    assert strand_moved(head, out)[~away].sum() > 10
    p = pipe_of(head)
    by_method = p.align(c + np.array([0.0, -0.5, 0.0]), r, 0.8, view=VIEW)
    np.testing.assert_array_equal(by_method.points, out.points)
    p = pipe_of(head)
    p.brush(sample(head, "mask", 1.0, VIEW))
    np.testing.assert_array_equal(p.locked, ~away)  # the far side is not painted
    p = pipe_of(head)
    p.brush(sample(head, "clump", -1.0, VIEW))
    np.testing.assert_array_equal(p.clump_strength, np.where(away, 1.0, 0.0))


def test_without_a_view_nothing_changes(head):
    """view=None is the sample as it was before the field; a camera every strand faces (a flat
    groom seen from the side its strands grow to) gives the same bytes as none."""
    s = sample(head, "comb", 0.9, None)
    old_style = BrushSample(s.brush, s.cursor, s.direction, s.radius, s.strength, s.lut)
    assert s == old_style and AlignSample((0.0, 0.0, 0.0), 1.0, 0.5, "paper").view is None
    np.testing.assert_array_equal(pipe_of(head).brush(s).points, pipe_of(head).brush(old_style).points)
    flat = samples.comb(strands=36, vertices=8, seed=2)  # roots in y = 0, strands hang along −y
    np.testing.assert_allclose(root_normals(flat), np.tile([0.0, -1.0, 0.0], (36, 1)), atol=1e-9)
    below = pipe_of(flat).brush(sample(flat, "comb", 0.9, (0.0, 1.0, 0.0), (0.2, 0.0, 0.0)))
    none = pipe_of(flat).brush(sample(flat, "comb", 0.9, None, (0.2, 0.0, 0.0)))
    np.testing.assert_array_equal(below.points, none.points)
    above = pipe_of(flat).brush(sample(flat, "comb", 0.9, (0.0, -1.0, 0.0), (0.2, 0.0, 0.0)))
    np.testing.assert_array_equal(above.points, flat.points)  # seen from behind its scalp


def mirror(g: Groom) -> Groom:
    p = g.points.copy()
    p[:, 0] = -p[:, 0]
    return g.with_points(p)


def test_a_mirrored_sample_mirrors_its_camera(head):
    s = sample(head, "comb", 1.0, (0.6, 0.0, -0.8), (0.3, -0.2, 0.0))
    m = s.mirrored(0.0)
    assert m.view == (-0.6, 0.0, -0.8) and m.direction == (-0.3, -0.2, 0.0)
    assert BrushSample("comb", (1.0, 0.0, 0.0), (0, 0, 0), 1.0, 1.0, s.lut).mirrored(0.0).view is None
    # A stroke on the mirrored groom with the mirrored sample gives the mirrored result.
    sym = Groom(np.concatenate([head.points, mirror(head).points]), np.concatenate([head.counts] * 2))
    msym = mirror(sym)
    a = pipe_of(sym).brush(s)
    b = pipe_of(msym).brush(m)
    np.testing.assert_allclose(mirror(b).points, a.points, atol=1e-6)
    moved = strand_moved(sym, a)
    assert 10 < moved.sum() < sym.strand_count - 10  # a front and a back


def test_a_bad_view_is_refused(head):
    p = pipe_of(head)
    for bad in [(0.0, 0.0, 0.0), (np.nan, 1.0, 0.0), (1.0, 2.0)]:
        with pytest.raises(ParameterError, match="view"):
            p.brush(sample(head, "comb", 0.5, bad))
    for bad in ["up", (1.0, "a", 0.0), [[1.0, 0.0, 0.0]]]:
        with pytest.raises(ParameterError, match="view"):
            p.align((0.0, 0.0, 0.0), 1.0, 0.5, view=bad)
    assert p.strokes == ()


@pytest.mark.parametrize("strength", [0.7, -0.6, 1.0, -1.0])
def test_clump_painting_equals_its_twin_and_stays_in_range(head, strength):
    from hairtool.frozen.brushes import paint_clump, paint_clump_reference

    c = head.points[head.topology.tip_indices[7]].astype(np.float64)
    lut = tuple(falloff_lut("linear").tolist())
    s = BrushSample("clump", tuple(c), (0.0, 0.0, 0.0), 0.8, strength, lut)
    start = np.random.default_rng(1).uniform(0.0, 1.0, head.strand_count)
    locked = np.zeros(head.strand_count, bool)
    locked[::5] = True
    a, b = paint_clump(head, s, start, locked), paint_clump_reference(head, s, start, locked)
    np.testing.assert_allclose(a, b, rtol=0, atol=1e-12)
    changed = a != start
    assert changed.sum() > 3 and not changed[locked].any()
    assert np.all((a >= 0) & (a <= 1))
    assert np.all(np.sign(a - start)[changed] == np.sign(strength))
    if abs(strength) == 1.0:  # full strength at the brush centre: all the way
        assert np.isclose(a[changed], 1.0 if strength > 0 else 0.0).any()


def test_roots_on_a_line_never_face_away():
    line = Groom.from_strands([np.linspace([x, 0.0, 0.0], [x, -1.0, 0.0], 6) for x in np.linspace(0, 1, 8)])
    np.testing.assert_array_equal(root_normals(line), 0.0)
    for view in [(0.0, 1.0, 0.0), (0.0, -1.0, 0.0), (0.0, 0.0, 1.0)]:
        assert not facing_away(root_normals(line), view).any()


def test_a_session_without_views_gives_the_bytes_of_before_the_view():
    """sha256 (first 16 hex digits) of this session's result, taken before samples had a view
    and ClumpWithGaps a clump strength."""
    import hashlib

    groom = samples.scalp(150, 12, seed=2)
    pipe = FrozenPipeline(groom, FrozenParams(seed=4, keep_lengths=True))
    tips = groom.points[groom.topology.tip_indices].astype(np.float64)
    c, r = tips[len(tips) // 2], 0.5 * float(np.ptp(groom.points, axis=0).max())
    lut = {name: tuple(falloff_lut(name).tolist()) for name in ("smooth", "linear", "constant")}
    curve = tuple(falloff_lut([[0, 1], [0.3, 0.9], [1, 0]]).tolist())
    pipe.align(c + np.array([0.2, 0.3, 0.0]), r, 0.7)
    for k in range(3):
        pipe.brush(BrushSample("comb", tuple(c + k * 0.05), (0.05, 0.02, 0.0), r, 0.9, curve))
    pipe.brush(BrushSample("mask", tuple(tips[3]), (0, 0, 0), 0.3 * r, 1.0, lut["constant"]))
    pipe.brush(BrushSample("smooth", tuple(c), (0, 0, 0), r, 0.6, lut["linear"]))
    pipe.brush(BrushSample("length", tuple(c), (0, 0, 0), r, -0.2, lut["smooth"]))
    pipe.brush(BrushSample("puff", tuple(c), (0, 0, 0), r, 0.5, lut["smooth"]))
    pipe.settle()  # (brush-local moves: the whole groom clumped once more, as before them)
    assert hashlib.sha256(pipe.result.points.tobytes()).hexdigest()[:16] == "d0490470c2fa36d9"
