"""Cut ends the strands under the brush where they first enter it: on a comb of straight strands
the cut ones end on the brush's sphere, shorter, with every kept vertex outside it, and the
others (and those rooted inside it) stay whole; strength 0 cuts nothing; undo brings the ends
back; the stroke log names the brush ``cut`` and replays to the same bytes. (Its kernel, twin,
lock, symmetry and round trips are the brush contract's: test_brush_contract.)"""

from __future__ import annotations

import json

import numpy as np

from hairtool import samples
from hairtool.frozen.brushes import BrushSample, falloff_lut
from hairtool.frozen.pipeline import FrozenParams, FrozenPipeline
from hairtool.frozen.strokes import read_strokes, strokes_from_log, write_strokes

LUT = tuple(falloff_lut("smooth").tolist())
PLAIN = FrozenParams(freeze=False, clump=False)  # the result is the stroked state itself
COMB = samples.comb(strands=36, vertices=11, spacing=0.1)


def cut(cursor, radius, strength=1.0):
    return BrushSample("cut", tuple(map(float, cursor)), (0.0, 0.0, 0.0), float(radius), strength, LUT)


def strand(g, s):
    return g.points[g.offsets[s] : g.offsets[s + 1]].astype(np.float64)


def test_the_strands_under_the_brush_end_on_its_surface_and_the_others_stay_whole():
    roots, tips = COMB.roots.astype(np.float64), COMB.tips.astype(np.float64)
    c = np.array([roots[:, 0].mean(), 0.6 * tips[:, 1].min(), roots[:, 2].mean()])
    r = 0.17
    out = FrozenPipeline(COMB, PLAIN).brush(cut(c, r))
    under = np.linalg.norm((roots - c)[:, [0, 2]], axis=1) < r  # straight strands along −y
    assert under.sum() >= 4 and (~under).sum() >= 4
    np.testing.assert_array_equal(out.counts[~under], COMB.counts[~under])
    assert np.all(out.counts[under] < COMB.counts[under])
    for s in range(COMB.strand_count):
        now, was = strand(out, s), strand(COMB, s)
        if not under[s]:
            assert now.tobytes() == was.tobytes()
            continue
        np.testing.assert_allclose(np.linalg.norm(now[-1] - c), r, rtol=1e-5)
        assert np.all(np.linalg.norm(now[:-1] - c, axis=1) >= r)
        np.testing.assert_array_equal(now[:-1], was[: len(now) - 1])


def test_a_root_inside_the_brush_and_strength_zero_leave_every_strand_whole():
    root = COMB.roots[7].astype(np.float64)
    out = FrozenPipeline(COMB, PLAIN).brush(cut(root, 0.05))
    assert out.points.tobytes() == COMB.points.tobytes()
    c = COMB.points[COMB.offsets[7] + 5]
    zero = FrozenPipeline(COMB, PLAIN).brush(cut(c, 0.2, strength=0.0))
    assert zero.points.tobytes() == COMB.points.tobytes()


def test_undo_brings_the_ends_back_and_the_log_names_cut_and_replays(tmp_path):
    pipe = FrozenPipeline(COMB, FrozenParams(seed=3, clump_iterations=1))
    start, snap = pipe.result, pipe.snapshot()
    c = COMB.points[COMB.offsets[14] + 6]
    done = pipe.apply_samples([cut(c, 0.15), cut(c + np.float32([0.1, 0.0, 0.0]), 0.15)])
    assert done.vertex_count < COMB.vertex_count
    write_strokes(tmp_path / "cut.json", strokes_from_log(pipe.strokes))
    assert {s["brush"] for s in json.loads((tmp_path / "cut.json").read_text())} == {"cut"}
    replay = FrozenPipeline(COMB, FrozenParams(seed=3, clump_iterations=1))
    replay.apply_samples([x for s in read_strokes(tmp_path / "cut.json") for x in s.pipeline_samples(0.0)])
    assert replay.result.points.tobytes() == done.points.tobytes()
    pipe.restore(snap)
    assert pipe.result.points.tobytes() == start.points.tobytes()
    np.testing.assert_array_equal(pipe.result.counts, COMB.counts)
