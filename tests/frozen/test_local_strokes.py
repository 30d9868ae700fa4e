"""Brush-local moves against full runs, stroke by stroke: every brush the pipeline runs locally
(with masks, hidden and selected strands, front-facing views and mirrored pairs) moves the same
strands to the same bytes as on the whole groom; no vertex outside a move's region changes; and
after the release (settle) the result is the one the log replays, through the CLI too."""

from __future__ import annotations

import numpy as np
import pytest

from hairtool import io, samples
from hairtool.cli import main
from hairtool.frozen.brushes import BrushSample, falloff_lut
from hairtool.frozen.pipeline import AlignSample, FrozenParams, FrozenPipeline
from hairtool.frozen.selection import SelectionSample
from hairtool.frozen.strokes import strokes_from_log, write_strokes
from hairtool.groom import vertex_ids_of

LUT = tuple(falloff_lut("smooth").tolist())


def same_bytes(a: np.ndarray, b: np.ndarray) -> bool:
    return a.shape == b.shape and a.tobytes() == b.tobytes()


def moves(groom):
    """A session's mouse moves (each a list of samples: a stroke's sample and its mirror)."""
    lo, hi = (b.astype(np.float64) for b in groom.bounds)
    ext = float(np.max(hi - lo))
    tips = groom.tips.astype(np.float64)
    at = [tips[k] for k in (10, 60, 120, 200, 260)]
    r = 0.08 * ext
    view = (0.0, 0.0, -1.0)

    def b(kind, c, d=(0.0, 0.0, 0.0), s=0.6, **kw):
        return BrushSample(kind, tuple(map(float, c)), tuple(map(float, d)), r, s, LUT, **kw)

    out = []
    for k in range(3):  # a comb stroke with its mirror, then one seen from a camera
        c = at[0] + 0.02 * k * ext
        s = b("comb", c, (0.03 * ext, 0.01 * ext, 0.0), 0.8)
        out.append([s, s.mirrored(0.0)])
    out.append([b("comb", at[1], (0.0, 0.03 * ext, 0.0), 0.8, view=view)])
    out.append([b("mask", at[2], s=1.0)])  # lock some strands, then brush over them
    out.append([b("smooth", at[2], s=0.9)])
    out.append([b("length", at[2], s=-0.3)])
    out.append([b("puff", at[3], s=0.5)])
    out.append([b("pinch", at[3], s=0.5)])
    out.append([b("clump", at[4], s=-0.7)])
    out.append([AlignSample(tuple(map(float, at[4] + 0.05 * ext)), r, 0.8, "paper")])
    out.append([SelectionSample("none")])
    out.append([b("select", at[1], s=1.0)])
    out.append([b("comb", at[1], (0.02 * ext, 0.0, 0.0), 0.8, only_selected=True)])
    out.append([SelectionSample("hide_selected")])
    out.append([b("comb", at[1], (0.02 * ext, 0.0, 0.0), 0.8)])  # the hidden ones stay
    out.append([SelectionSample("reveal"), SelectionSample("all")])
    anew = b("select", at[3], s=1.0, new_selection=True)  # a plain stroke: a new selection,
    out.append([anew, anew.mirrored(0.0)])  # which reaches the strands away from the brush too
    out.append([b("comb", at[3], (0.02 * ext, 0.0, 0.0), 0.8, only_selected=True)])
    out.append([SelectionSample("all")])
    out.append([b("mask", at[2], s=-1.0)])
    out.append([b("smooth", at[2], s=0.9)])
    return out


def state(pipe):
    return (pipe.locked, pipe.clump_strength, pipe.selected, pipe.hidden)


@pytest.mark.parametrize("keep_lengths", [False, True])
def test_every_local_brush_moves_what_a_full_run_moves_and_settles_to_a_replay(keep_lengths, tmp_path):
    groom = samples.scalp(300, 10, seed=6)
    params = FrozenParams(seed=2, keep_lengths=keep_lengths)
    local, full = FrozenPipeline(groom, params), FrozenPipeline(groom, params)
    went_local = 0
    for batch in moves(groom):
        shown = local.result.points.copy()
        out = local.apply_samples(batch)
        full.apply_samples(batch, local=False)
        assert same_bytes(local.aligned.points, full.aligned.points), batch[0]
        for a, b in zip(state(local), state(full), strict=True):
            assert same_bytes(a, b), batch[0]
        region = local.changed
        if region is None:
            continue
        went_local += 1
        outside = np.ones(groom.vertex_count, bool)
        outside[vertex_ids_of(groom.topology, region)] = False
        assert same_bytes(out.points[outside], shown[outside]), batch[0]  # the rest: untouched
    assert went_local >= 15
    assert local.unsettled
    settled = local.settle().points
    assert not local.unsettled and same_bytes(settled, full.result.points)
    # the log through the CLI: the same bytes
    io.write(tmp_path / "g.npz", groom)
    write_strokes(tmp_path / "s.json", strokes_from_log(local.strokes))
    argv = ["freeze", str(tmp_path / "g.npz"), str(tmp_path / "o.npz"), "--seed", "2"]
    argv += ["--keep-lengths"] if keep_lengths else []
    assert main([*argv, "--strokes", str(tmp_path / "s.json")]) == 0
    assert same_bytes(io.read(tmp_path / "o.npz").points, settled)


def test_a_refused_sample_in_a_local_batch_leaves_no_trace():
    groom = samples.scalp(200, 8, seed=1)
    pipe = FrozenPipeline(groom)
    tip = tuple(map(float, groom.tips[5]))
    pipe.brush(BrushSample("comb", tip, (0.1, 0.0, 0.0), 0.3, 0.8, LUT))
    assert pipe.changed is not None
    before = (pipe.result.points.copy(), state(pipe), len(pipe.strokes))
    bad = BrushSample("comb", tip, (0.1, 0.0, 0.0), -1.0, 0.8, LUT)
    with pytest.raises(ValueError):
        pipe.apply_samples([SelectionSample("none"), BrushSample("mask", tip, (0, 0, 0), 0.3, 1.0, LUT), bad])
    assert same_bytes(pipe.result.points, before[0]) and len(pipe.strokes) == before[2]
    for a, b in zip(state(pipe), before[1], strict=True):
        assert same_bytes(a, b)
