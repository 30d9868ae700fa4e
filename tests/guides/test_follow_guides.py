"""Render hair after add, delete and density strokes on its guides (Sintel's hair on her head):
a removed guide's children go and the others build to their bytes; a planted guide gets the
binding's children per guide, rooted on the head around it and following it; the same strokes
give the same children; `hairtool freeze --count --strokes` writes them."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from hairtool import io
from hairtool.cli import main
from hairtool.frozen.brushes import BrushSample, falloff_lut
from hairtool.frozen.pipeline import FrozenParams, FrozenPipeline
from hairtool.frozen.strokes import strokes_from_log, write_strokes
from hairtool.guides.binding import bind_scalp
from hairtool.guides.follow import follow_guides, guides_now
from hairtool.guides.planting import HeadSurface
from hairtool.io.obj import read_mesh

DATA = Path(__file__).resolve().parents[1] / "data" / "grooms"
PLAIN = FrozenParams(freeze=False, clump=False)
LUT = tuple(falloff_lut("smooth").tolist())


@pytest.fixture(scope="module")
def sintel():
    mesh = read_mesh(DATA / "sintel_head.obj")
    groom = io.read_groom(DATA / "sintel_hair.tfx")
    return groom, mesh, HeadSurface(mesh), bind_scalp(groom, mesh, 3000, seed=1)


def sample(brush, cursor, radius, **kw):
    return BrushSample(brush, tuple(map(float, cursor)), (0.0, 0.0, 0.0), float(radius), 1.0, LUT, **kw)


def followed(pipe, binding):
    origin = pipe.origin
    return follow_guides(binding, guides_now(binding.rest_guides, pipe.aligned, origin), origin, pipe.surface)


def test_a_removed_guides_children_go_and_the_others_keep_their_bytes(sintel):
    groom, _, surface, b = sintel
    pipe = FrozenPipeline(groom, PLAIN, surface)
    before = b.build(pipe.result).points.reshape(b.child_count, -1, 3)
    pipe.brush(sample("delete", groom.roots[40], 3.0))
    gone = np.setdiff1d(np.arange(groom.strand_count), pipe.origin)
    assert 3 <= len(gone) < 40
    f = followed(pipe, b)
    lost_nearest = np.isin(b.guide_ids[:, 0], gone)
    assert f.child_count == b.child_count - lost_nearest.sum() and lost_nearest.any()
    after = f.build(pipe.result).points.reshape(f.child_count, -1, 3)
    kept = np.flatnonzero(~lost_nearest)
    untouched = ~np.isin(b.guide_ids[kept], gone).any(axis=1)  # none of their guides removed
    assert untouched.sum() > 0.8 * len(kept) and (~untouched).any()
    np.testing.assert_array_equal(after[untouched], before[kept[untouched]])
    assert np.all(np.isfinite(after)) and np.allclose(f.weights.sum(axis=1), 1.0)
    # the guides all back (an undo): the binding's own children, to the bit
    pipe.restore(FrozenPipeline(groom, PLAIN, surface).snapshot())
    again = followed(pipe, b)
    np.testing.assert_array_equal(again.build(pipe.result).points, b.build(pipe.result).points)


def test_a_planted_guide_gets_children_on_the_head_that_follow_it(sintel):
    groom, _, surface, b = sintel
    pipe = FrozenPipeline(groom, PLAIN, surface)
    pipe.brush(sample("add", groom.roots[100], 1.0, count=4, seed=3))
    assert np.array_equal(pipe.origin[-4:], [-1] * 4) and len(pipe.origin) == groom.strand_count + 4
    f = followed(pipe, b)
    per = round(b.child_count / groom.strand_count)
    assert f.child_count == b.child_count + 4 * per
    new = slice(b.child_count, f.child_count)
    on, _ = surface.project(f.roots[new])
    np.testing.assert_allclose(f.roots[new], on, atol=1e-5)  # rooted on the head
    planted = np.arange(groom.strand_count, groom.strand_count + 4)
    assert np.isin(f.guide_ids[new, 0], planted).mean() > 0.7  # mostly nearest to their planted guide
    hair = f.build(pipe.result)
    lengths = hair.strand_lengths
    near = np.median(hair.strand_lengths[: b.child_count][np.isin(f.guide_ids[: b.child_count, 0], [100])])
    assert np.all(np.isfinite(hair.points)) and abs(np.median(lengths[new]) / near - 1.0) < 0.35
    # the same strokes, the same children
    twin = FrozenPipeline(groom, PLAIN, surface)
    twin.apply_samples(pipe.strokes)
    np.testing.assert_array_equal(followed(twin, b).build(twin.result).points, hair.points)


def test_freeze_with_render_hair_replays_add_and_delete_strokes(sintel, tmp_path):
    groom, _, surface, _ = sintel
    io.write(tmp_path / "guides.npz", groom)
    pipe = FrozenPipeline(groom, PLAIN, surface)
    pipe.brush(sample("delete", groom.roots[40], 3.0))
    pipe.brush(sample("add", groom.roots[100], 1.0, count=3, seed=2))
    write_strokes(tmp_path / "log.json", strokes_from_log(pipe.strokes))
    args = [
        "freeze", str(tmp_path / "guides.npz"), str(tmp_path / "hair.npz"), "--no-freeze", "--no-clump",
        "--count", "3000", "--seed", "1", "--scalp", str(DATA / "sintel_head.obj"),
        "--strokes", str(tmp_path / "log.json"), "--no-clump-children",
    ]  # fmt: skip
    assert main(args) == 0
    hair = io.read_groom(tmp_path / "hair.npz")
    mesh = read_mesh(DATA / "sintel_head.obj")
    f = followed(pipe, bind_scalp(groom, mesh, 3000, seed=1))
    assert hair.strand_count == f.child_count
    np.testing.assert_array_equal(hair.points, f.build(pipe.result).points)


def test_density_with_render_hair_thins_and_plants_guides_and_their_children_follow(sintel):
    groom, _, surface, b = sintel
    pipe = FrozenPipeline(groom, PLAIN, surface)
    pipe.brush(sample("density", groom.roots[100], 4.0, spacing=2.5, seed=1))
    origin = pipe.origin
    gone = np.setdiff1d(np.arange(groom.strand_count), origin)
    planted = int((origin < 0).sum())
    assert gone.size and planted
    f = followed(pipe, b)
    per = round(b.child_count / groom.strand_count)
    assert f.child_count == b.child_count - int(np.isin(b.guide_ids[:, 0], gone).sum()) + planted * per
    assert np.all(np.isfinite(f.build(pipe.result).points))
