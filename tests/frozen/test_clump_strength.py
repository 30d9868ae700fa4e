"""The clump brush's per-strand clump strength s in ClumpWithGaps: all ones gives the printed
bytes, a strand at 0 stays where it is, s scales the step, the kernels equal their numpy twin,
region updates after painting give a full run's bytes, and the pipeline paints, undoes and
replays it."""

from __future__ import annotations

import hashlib

import numba
import numpy as np
import pytest

from hairtool import samples
from hairtool.errors import ParameterError
from hairtool.frozen.brushes import BrushSample, falloff_lut
from hairtool.frozen.clump import clump, clump_reference
from hairtool.frozen.freeze import freeze
from hairtool.frozen.pipeline import FrozenParams, FrozenPipeline
from hairtool.frozen.strand_clumps import auto_clump_radius

# sha256 (first 16 hex digits) of the float32 points ClumpWithGaps gave before the clump
# strength existed, on the groom of ``frozen_groom`` (h automatic, k = 3, seed 5).
PRINTED = {
    ("printed", False): "6a34b74bec41cb05",
    ("printed", True): "db00a1cf7d2cd3c3",
    ("text", False): "e5aa11dc9f37b0a1",
    ("text", True): "524d6ec0b6a07164",
    ("off", False): "518eaa178c96def7",
    ("off", True): "2e5543f3381a3cad",
}


@pytest.fixture(scope="module")
def frozen_groom():
    return freeze(samples.scalp(300, 12, seed=1), 7.0, 7.0, float(np.radians(30)), 3)


@pytest.fixture
def threads():
    before = numba.get_num_threads()
    yield lambda n: numba.set_num_threads(min(n, numba.config.NUMBA_NUM_THREADS))
    numba.set_num_threads(before)


def digest(points: np.ndarray) -> str:
    return hashlib.sha256(np.ascontiguousarray(points).tobytes()).hexdigest()[:16]


def same_bytes(a: np.ndarray, b: np.ndarray) -> bool:
    return np.array_equal(a.view(np.uint32), b.view(np.uint32))


@pytest.mark.parametrize(("gap_mode", "keep_lengths"), list(PRINTED))
def test_strength_one_everywhere_gives_the_printed_bytes(frozen_groom, gap_mode, keep_lengths):
    g = frozen_groom
    h = auto_clump_radius(g)
    ones = clump(g, h, 3, None, gap_mode, 5, None, keep_lengths, np.ones(g.strand_count))
    assert digest(ones.points) == PRINTED[gap_mode, keep_lengths]
    default = clump(g, h, 3, None, gap_mode, 5, None, keep_lengths)
    assert digest(default.points) == PRINTED[gap_mode, keep_lengths]


@pytest.mark.parametrize("gap_mode", ["printed", "text", "off"])
@pytest.mark.parametrize("keep_lengths", [False, True])
def test_a_strand_at_strength_zero_is_left_as_it_is(frozen_groom, gap_mode, keep_lengths):
    g = frozen_groom
    h = auto_clump_radius(g)
    s = np.ones(g.strand_count)
    s[::3] = 0.0
    out = clump(g, h, 3, None, gap_mode, 5, None, keep_lengths, s)
    still = np.repeat(s == 0, g.counts)
    assert same_bytes(out.points[still], g.points[still])
    full = clump(g, h, 3, None, gap_mode, 5, None, keep_lengths)
    moved = np.any(out.points != g.points, axis=1)
    assert moved[~still].sum() > 0.3 * (~still).sum()  # the others clump, toward them too
    assert not np.array_equal(out.points[~still], full.points[~still])


def test_strength_scales_the_step():
    a = np.linspace([0, 0, 0], [0, -1, 0], 11)
    pair = np.vstack([a, a + np.array([0.05, 0.0, 0.0])]).astype(np.float32)
    g = samples.comb(strands=2, vertices=11).with_points(pair)
    full = clump(g, 0.1, 1, 0.05, "off").points.astype(np.float64) - g.points
    half = clump(g, 0.1, 1, 0.05, "off", strength=[0.5, 0.25]).points.astype(np.float64) - g.points
    np.testing.assert_allclose(half[:11], 0.5 * full[:11], atol=1e-7)
    np.testing.assert_allclose(half[11:], 0.25 * full[11:], atol=1e-7)


@pytest.mark.parametrize("gap_mode", ["printed", "text", "off"])
def test_the_kernels_equal_their_numpy_twin_with_painted_strength(frozen_groom, gap_mode):
    g = frozen_groom
    h = auto_clump_radius(g)
    s = np.random.default_rng(3).uniform(0.0, 1.0, g.strand_count)
    s[::5] = 0.0
    s[1::5] = 1.0
    a = clump(g, h, 3, None, gap_mode, 5, None, False, s)
    b = clump_reference(g, h, 3, None, gap_mode, 5, False, s)
    np.testing.assert_allclose(a.points, b.points, rtol=0, atol=2e-5)


def test_a_bad_strength_is_refused(frozen_groom):
    g = frozen_groom
    for bad in (np.ones(3), np.full(g.strand_count, 1.5), np.full(g.strand_count, np.nan)):
        with pytest.raises(ParameterError, match="clump_strength"):
            clump(g, 0.1, 2, strength=bad)
        with pytest.raises(ParameterError, match="clump_strength"):
            clump_reference(g, 0.1, 2, strength=bad)


def clump_sample(groom, cursor, strength, radius):
    lut = tuple(falloff_lut("constant").tolist())
    return BrushSample("clump", tuple(map(float, cursor)), (0.0, 0.0, 0.0), radius, strength, lut)


def test_the_pipeline_paints_undoes_and_replays_clump_strength():
    g = samples.scalp(200, 10, seed=4)
    pipe = FrozenPipeline(g, FrozenParams(seed=2))
    before, snap = pipe.result.points.copy(), pipe.snapshot()
    tips = g.tips.astype(np.float64)
    r = 0.3 * float(np.ptp(g.points, axis=0).max())
    pipe.brush(clump_sample(g, tips[9], -1.0, r))  # clumping off around one tip
    off = pipe.clump_strength == 0.0
    assert 3 < off.sum() < g.strand_count - 3 and np.all(pipe.clump_strength[~off] == 1.0)
    still = np.repeat(off, g.counts)
    assert same_bytes(pipe.result.points[still], pipe.aligned.points[still])  # not clumped
    assert not np.array_equal(pipe.result.points[still], before[still])
    painted, painted_snap = pipe.result.points.copy(), pipe.snapshot()
    # a full pipeline on the same log: the same bytes (the region update was exact)
    fresh = FrozenPipeline(g, FrozenParams(seed=2))
    fresh.apply_samples(pipe.strokes)
    assert same_bytes(fresh.result.points, painted)
    pipe.restore(snap)  # undo
    assert same_bytes(pipe.result.points, before) and np.all(pipe.clump_strength == 1.0)
    pipe.restore(painted_snap)  # redo
    assert same_bytes(pipe.result.points, painted)
    pipe.brush(clump_sample(g, tips[9], 0.5, r))  # half way back on
    np.testing.assert_allclose(pipe.clump_strength[off], 0.5)
    stiffer = FrozenParams(seed=2, stretch_stiffness=5.0)
    pipe.set_params(stiffer)  # a new frozen groom: the strokes replayed on it
    other = FrozenPipeline(g, stiffer)
    other.apply_samples(pipe.strokes, local=False)  # a replay runs on the whole groom
    np.testing.assert_array_equal(pipe.clump_strength, other.clump_strength)
    assert same_bytes(pipe.result.points, other.result.points)
    assert np.mean(pipe.clump_strength[off] == 0.5) > 0.8  # (the brush sees the new frozen groom)
    pipe.reset_strokes()
    assert np.all(pipe.clump_strength == 1.0)
