"""ClumpWithGaps with lengths kept: segments back to their lengths, directions kept, the same
bytes in a region update as in a full run, and the printed form left as the default."""

from __future__ import annotations

import numba
import numpy as np
import pytest

from hairtool import io, samples
from hairtool.cli import main
from hairtool.frozen.clump import clump, clump_reference
from hairtool.frozen.lengths import restore_lengths, restore_lengths_reference
from hairtool.frozen.pipeline import FrozenParams, FrozenPipeline
from hairtool.frozen.strand_clumps import auto_clump_radius


@pytest.fixture
def threads():
    before = numba.get_num_threads()
    yield lambda n: numba.set_num_threads(min(n, numba.config.NUMBA_NUM_THREADS))
    numba.set_num_threads(before)


def _ratios(before, after):
    return after.segment_lengths / before.segment_lengths


def test_the_pass_matches_its_numpy_twin_and_handles_a_collapsed_segment():
    g = samples.scalp(60, 9, seed=2)
    rng = np.random.default_rng(0)
    moved = g.points + rng.normal(scale=0.05, size=g.points.shape).astype(np.float32)
    moved[g.topology.root_indices] = g.roots
    moved[5] = moved[4]  # a collapsed segment keeps its direction from before
    got = restore_lengths(g.points, moved, g.topology)
    want = restore_lengths_reference(g.points, moved, g.topology)
    np.testing.assert_allclose(got, want, rtol=0, atol=1e-5)
    out = g.with_points(got)
    np.testing.assert_allclose(out.segment_lengths, g.segment_lengths, rtol=1e-5)
    np.testing.assert_array_equal(out.roots, g.roots)
    seg_before = g.points[5] - g.points[4]
    seg_after = got[5] - got[4]
    assert np.dot(seg_before, seg_after) > 0.999 * np.dot(seg_before, seg_before)


def test_clumping_keeps_lengths_and_directions_when_asked(grooms_dir):
    g = io.read_groom(grooms_dir / "ponytail_back.tfx")
    h = auto_clump_radius(g)
    printed = clump(g, h, 3)
    kept = clump(g, h, 3, keep_lengths=True)
    r = _ratios(g, printed)
    assert r.min() < 0.5 and r.max() > 2.0  # the printed form: rubber hair
    np.testing.assert_allclose(_ratios(g, kept), 1.0, atol=1e-4)
    np.testing.assert_array_equal(kept.roots, g.roots)
    a, b = printed.segment_vectors.astype(np.float64), kept.segment_vectors.astype(np.float64)
    cos = np.einsum("ij,ij->i", a, b) / (np.linalg.norm(a, axis=1) * np.linalg.norm(b, axis=1))
    assert cos.min() > 1 - 1e-5
    ref = clump_reference(g, h, 3, keep_lengths=True)
    np.testing.assert_allclose(ref.segment_lengths, g.segment_lengths, rtol=1e-4)
    assert clump(g, h, 3).points.tobytes() == printed.points.tobytes()  # the default stays printed


@pytest.mark.parametrize("n_threads", [1, 2])
def test_a_drag_with_lengths_kept_keeps_them_move_after_move(n_threads, threads):
    threads(n_threads)
    g = samples.scalp(strands=400, vertices=12, seed=3)
    pipe = FrozenPipeline(g, FrozenParams(keep_lengths=True, seed=5))
    lo, hi = g.bounds
    extent = float(np.max(hi - lo))
    tip = g.tips[np.argmin(np.linalg.norm(g.tips - (lo + hi) / 2, axis=1))].astype(np.float64)
    local = 0
    for k in range(6):
        a = 2 * np.pi * k / 6
        got = pipe.align(tip + 0.1 * extent * np.array([np.cos(a), np.sin(a), 0.0]), 0.2 * extent, 0.8)
        np.testing.assert_allclose(got.segment_lengths, pipe.aligned.segment_lengths, rtol=1e-4)
        local += pipe.clump_redone < 1.0
    assert local == 6  # each move brush-local (hairtool.frozen.local)


def test_the_pipeline_and_the_cli_take_keep_lengths(tmp_path):
    g = samples.scalp(200, 12, seed=1)
    pipe = FrozenPipeline(g, FrozenParams(keep_lengths=True))
    pipe.align((2.0, 1.0, 0.0), 3.0, 0.8)
    np.testing.assert_allclose(pipe.result.segment_lengths, pipe.aligned.segment_lengths, rtol=1e-4)
    src, out = tmp_path / "in.npz", tmp_path / "out.npz"
    io.write(src, g)
    assert main(["freeze", str(src), str(out), "--keep-lengths", "--no-freeze"]) == 0
    np.testing.assert_allclose(io.read_groom(out).segment_lengths, g.segment_lengths, rtol=1e-4)
