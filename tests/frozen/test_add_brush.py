"""The add brush: planted strands root on the mesh under the brush, shaped and as long as their
neighbours (a flat comb on a plane; Sintel's head); seeded, so a stroke log replays with
--scalp to the same bytes; undo takes them away bit for bit; without a head it is refused."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from hairtool import io, samples
from hairtool.cli import main
from hairtool.errors import ParameterError
from hairtool.frozen.brushes import BrushSample, falloff_lut
from hairtool.frozen.pipeline import FrozenParams, FrozenPipeline
from hairtool.frozen.strokes import strokes_from_log, write_strokes
from hairtool.guides.planting import HeadSurface
from hairtool.io.obj import read_mesh

DATA = Path(__file__).resolve().parents[1] / "data" / "grooms"
PLAIN = FrozenParams(freeze=False, clump=False)
LUT = tuple(falloff_lut("smooth").tolist())


@pytest.fixture(scope="module")
def sintel():
    return io.read_groom(DATA / "sintel_hair.tfx"), HeadSurface(read_mesh(DATA / "sintel_head.obj"))


def add(cursor, radius, count, seed=0, view=None):
    v = None if view is None else tuple(map(float, view))
    c = tuple(map(float, cursor))
    return BrushSample("add", c, (0.0, 0.0, 0.0), radius, 1.0, LUT, v, count=count, seed=seed)


def test_on_a_plane_planted_strands_hang_like_their_neighbours(plane, tmp_path):
    comb = samples.comb(36, 12)
    pipe = FrozenPipeline(comb, PLAIN, HeadSurface(plane))
    out = pipe.brush(add((0.125, -0.2, 0.125), 0.1, 6))
    assert out.strand_count == 42
    new = out.subset(np.arange(36, 42))
    np.testing.assert_allclose(new.roots[:, 1], 0.0, atol=1e-6)  # on the plane
    assert np.all(np.linalg.norm(new.roots[:, [0, 2]] - 0.125, axis=1) <= 0.1 + 1e-6)  # under the brush
    np.testing.assert_allclose(new.strand_lengths, 0.5, rtol=1e-4)  # as long as the neighbours
    d = (new.tips - new.roots).astype(np.float64)
    np.testing.assert_allclose(d / np.linalg.norm(d, axis=1, keepdims=True), [[0, -1, 0]] * 6, atol=1e-5)
    np.testing.assert_array_equal(pipe.origin[36:], -1)
    assert not pipe.locked[36:].any() and np.all(pipe.clump_strength[36:] == 1)


def test_on_sintel_roots_lie_on_the_head_lengths_are_the_neighbours_and_undo_removes_them(sintel):
    groom, surface = sintel
    pipe = FrozenPipeline(groom, PLAIN, surface)
    before = pipe.snapshot()
    c = groom.roots[40].astype(np.float64)
    out = pipe.brush(add(c, 2.0, 8, seed=5))
    assert out.strand_count == groom.strand_count + 8
    new = out.subset(np.arange(groom.strand_count, out.strand_count))
    on, _ = surface.project(new.roots.astype(np.float64))
    np.testing.assert_allclose(new.roots, on, atol=1e-4)
    for s in range(8):  # between the lengths of its three nearest strands
        near = np.argsort(np.linalg.norm(groom.roots - new.roots[s], axis=1))[:3]
        lo, hi = groom.strand_lengths[near].min(), groom.strand_lengths[near].max()
        assert lo * 0.97 <= new.strand_lengths[s] <= hi * 1.03
    again = FrozenPipeline(groom, PLAIN, surface).brush(add(c, 2.0, 8, seed=5))
    np.testing.assert_array_equal(again.points, out.points)  # seeded
    other = FrozenPipeline(groom, PLAIN, surface).brush(add(c, 2.0, 8, seed=6))
    assert not np.array_equal(other.points, out.points)
    after = pipe.snapshot()
    np.testing.assert_array_equal(pipe.restore(before).points, groom.points)
    np.testing.assert_array_equal(pipe.restore(after).points, out.points)
    # facing away from the camera: nothing planted; without a head: refused
    away = (c - pipe.scalp_centre) / np.linalg.norm(c)
    assert pipe.brush(add(c, 2.0, 3, view=away)).strand_count == out.strand_count
    with pytest.raises(ParameterError, match="scalp"):
        FrozenPipeline(groom, PLAIN).brush(add(c, 2.0, 3))
    with pytest.raises(ParameterError, match="count"):
        pipe.brush(add(c, 2.0, 0))


def test_an_add_log_replays_with_scalp_to_the_same_bytes(sintel, tmp_path):
    groom, surface = sintel
    io.write(tmp_path / "g.npz", groom)
    pipe = FrozenPipeline(groom, FrozenParams(seed=2, clump_iterations=1), surface)
    c = groom.roots[40].astype(np.float64)
    for k in range(3):
        pipe.brush(add(c + np.array([0.4 * k, 0.0, 0.0]), 1.5, 2, seed=9))
    pipe.brush(BrushSample("comb", tuple(c), (0.5, 0.0, 0.0), 4.0, 0.5, LUT))
    strokes = strokes_from_log(pipe.strokes)
    assert strokes[0].brush == "add" and strokes[0].params == {"count": 2, "seed": 9}
    write_strokes(tmp_path / "s.json", strokes)
    args = ["freeze", str(tmp_path / "g.npz"), str(tmp_path / "o.npz"), "--seed", "2"]
    args += ["--clump-iterations", "1", "--strokes", str(tmp_path / "s.json")]
    assert main(args) == 2  # no head: refused
    assert main([*args, "--scalp", str(DATA / "sintel_head.obj")]) == 0
    replayed = io.read(tmp_path / "o.npz")
    assert replayed.strand_count == groom.strand_count + 6
    np.testing.assert_array_equal(replayed.points, pipe.result.points)


def test_a_project_keeps_add_strokes(sintel, tmp_path):
    from hairtool import project

    groom, surface = sintel
    pipe = FrozenPipeline(groom, PLAIN, surface)
    pipe.brush(add(groom.roots[40], 1.5, 3, seed=4))
    project.save(tmp_path / "p.hairproj", project.Project.from_pipeline(pipe))
    back = project.load(tmp_path / "p.hairproj")
    assert back.strokes == pipe.strokes
    replay = FrozenPipeline(back.rest, back.params, surface)
    replay.restore(back.stroke_snapshot(replay))
    np.testing.assert_array_equal(replay.result.points, pipe.result.points)
