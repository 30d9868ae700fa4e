"""Hair frame features (seed 000 steps 1–5): batched resampling and each switchable step."""

from __future__ import annotations

import numpy as np
import pytest

from hairtool import samples
from hairtool.errors import GroomError, ParameterError
from hairtool.groom import Animation
from hairtool.keys.features import (
    FeatureOptions,
    frame_features,
    hair_features,
    raw_features,
    resample_frames,
)
from hairtool.resample import resample_points
from hairtool.simulate.sway import sway_animation


@pytest.fixture(scope="module")
def anim() -> Animation:
    return sway_animation(samples.scalp(40, 10, seed=3), 12, flick_frame=6)


def test_batched_resampling_matches_the_per_groom_resampler(anim):
    batched = resample_frames(anim.frames, anim.counts, 7)
    assert batched.dtype == np.float64
    for f in range(anim.n_frames):
        np.testing.assert_allclose(batched[f], resample_points(anim.frame(f), 7), atol=1e-6)


def test_resampling_kernel_matches_its_numpy_twin(anim):
    from hairtool.keys.features import resample_frames_reference

    fast = resample_frames(anim.frames, anim.counts, 9)
    expected = resample_frames_reference(anim.frames, anim.counts, 9)
    np.testing.assert_allclose(fast, expected, rtol=0, atol=1e-12)


def test_batched_resampling_handles_mixed_counts_and_zero_length_strands(monkeypatch):
    import hairtool.keys.features as feats

    g = samples.portrait(15, 9, seed=1)
    strands = [s.copy() for s in g.strands()]
    strands[2] = strands[2][:4]
    strands[5] = np.repeat(strands[5][:1], 6, axis=0)  # all vertices on the root
    frames = []
    for f in range(5):
        pts = [s + np.array([0.1 * f, 0.0, 0.0]) * np.linspace(0, 1, len(s))[:, None] for s in strands]
        frames.append(np.concatenate(pts).astype(np.float32))  # as an Animation holds them
    from hairtool.groom import Groom

    counts = [len(s) for s in strands]
    monkeypatch.setattr(feats, "_CHUNK_VERTICES", 40)  # several chunks of frames
    batched = resample_frames(np.stack(frames), counts, 5)
    twin = resample_frames(np.stack(frames), counts, 5, use_numba=False)
    np.testing.assert_allclose(batched, twin, atol=1e-12)
    for f in range(5):
        np.testing.assert_allclose(batched[f], resample_points(Groom(frames[f], counts), 5), atol=1e-6)


def test_center_removes_global_translation(anim):
    shifted = anim.with_frames(anim.frames + np.array([0.5, -2.0, 1.0], dtype=np.float32))
    o = FeatureOptions(relative=False)
    np.testing.assert_allclose(hair_features(shifted, o), hair_features(anim, o), atol=1e-5)
    off = FeatureOptions(relative=False, center=False)
    assert np.abs(hair_features(shifted, off) - hair_features(anim, off)).max() > 0.4


def test_relative_puts_every_root_at_the_origin(anim):
    x = hair_features(anim, FeatureOptions(samples=6, center=False, weighting=False))
    pts = x.reshape(anim.n_frames, anim.strand_count, 6, 3)
    assert np.abs(pts[:, :, 0]).max() == 0.0
    assert np.abs(pts[:, :, -1]).max() > 0.5


def test_tip_weighting_scales_by_the_profile(anim):
    plain = hair_features(anim, FeatureOptions(samples=5, weighting=False)).reshape(anim.n_frames, -1, 5, 3)
    o = FeatureOptions(samples=5, root_weight=0.5, tip_weight=3.0, exponent=2.0)
    w = hair_features(anim, o).reshape(plain.shape)
    u = np.linspace(0, 1, 5)
    expected = 0.5 + 2.5 * u**2
    np.testing.assert_allclose(w, plain * expected[None, None, :, None], rtol=1e-12, atol=1e-12)


def test_original_vertices_without_resampling(anim):
    x = hair_features(anim, FeatureOptions(samples=None, weighting=False, center=False))
    assert x.shape == (anim.n_frames, anim.vertex_count * 3)


@pytest.mark.parametrize(
    "kwargs",
    [
        {"samples": 1},
        {"samples": float("nan")},
        {"tip_weight": -1.0},
        {"exponent": 0.0},
        {"root_weight": float("nan")},
    ],
)
def test_bad_options_are_parameter_errors(anim, kwargs):
    with pytest.raises(ParameterError):
        hair_features(anim, FeatureOptions(**kwargs))


def test_raw_features_are_checked():
    x = np.arange(12.0).reshape(6, 2)
    np.testing.assert_array_equal(raw_features(x), x)
    bad = x.copy()
    bad[3, 1] = np.nan
    with pytest.raises(ParameterError, match="frame 3"):
        raw_features(bad)
    with pytest.raises(ParameterError):
        raw_features(np.zeros((1, 3)))
    with pytest.raises(ParameterError):
        raw_features(np.zeros((2, 2, 2)))


def test_one_frame_animation_is_rejected(anim):
    with pytest.raises(GroomError):
        frame_features(anim.with_frames(anim.frames[:1]))


@pytest.mark.parametrize("samples_", [16, None, 5])
def test_one_strands_features_are_its_columns_of_the_frame_vectors(samples_):
    from hairtool.keys.features import strand_features
    from hairtool.simulate.sway import sway_animation

    anim = sway_animation(samples.portrait(30, 10, seed=4), 12, flick_frame=6)
    o = FeatureOptions(samples=samples_, tip_weight=3.0)
    full = hair_features(anim, o)
    s_count = anim.topology.strand_count
    m = full.shape[1] // (s_count * 3)
    for s in (0, 7, s_count - 1):
        ref = full.reshape(anim.n_frames, s_count, m, 3)[:, s]
        np.testing.assert_array_equal(strand_features(anim, s, o), ref)
    with pytest.raises(ParameterError, match="strand"):
        strand_features(anim, s_count, o)
