"""Rebuilding every vertex from key poses, position errors, DP versus uniform keys, key distribution."""

from __future__ import annotations

import importlib

import numpy as np
import pytest

from hairtool import samples
from hairtool.errors import ParameterError
from hairtool.keys.reconstruct import (
    compare_with_uniform,
    interpolate_at,
    interpolate_keys,
    key_curve_errors,
    key_curve_errors_reference,
    key_distribution,
    key_poses,
    position_errors,
    reconstruct,
)
from hairtool.keys.segment_direct import difference_tangents, interpolate_segment
from hairtool.keys.session import find_keys
from hairtool.simulate.sway import sway_animation


@pytest.fixture(scope="module")
def anim():
    return sway_animation(samples.scalp(60, 12, seed=2), 72, flick_frame=50)


@pytest.mark.parametrize("interp", ["linear", "hermite"])
def test_reconstruction_is_exact_at_keys_and_matches_the_oracle(anim, interp):
    keys = np.array([0, 10, 31, 50, 71])
    rebuilt = reconstruct(anim, keys, interp)
    np.testing.assert_array_equal(rebuilt.frames[keys], anim.frames[keys])
    x = anim.frames.reshape(anim.n_frames, -1).astype(np.float64)
    m = difference_tangents(x) if interp == "hermite" else None
    expect = interpolate_segment(x, m, 10, 31, np.arange(11, 31))
    np.testing.assert_allclose(rebuilt.frames[11:31].reshape(20, -1), expect, atol=1e-5)


def test_linear_motion_is_rebuilt_exactly_from_two_keys():
    g = samples.comb(10, 6)
    frames = np.stack([g.points.astype(np.float64) + 0.01 * f for f in range(9)])
    x = frames.reshape(9, -1)
    kp = key_poses(x, [0, 8])
    np.testing.assert_allclose(interpolate_keys(kp), x, atol=1e-12)
    np.testing.assert_allclose(interpolate_keys(key_poses(x, [0, 8], "hermite")), x, atol=1e-12)


@pytest.mark.parametrize("interp", ["linear", "hermite"])
def test_key_curve_at_a_few_frames_is_those_rows_of_the_whole(anim, interp):
    kp = key_poses(anim.frames, [0, 10, 31, 50, 71], interp)
    whole = interpolate_keys(kp)
    frames = [71, 0, 20, 20, 50]
    np.testing.assert_array_equal(interpolate_at(kp, frames), whole[frames])
    assert interpolate_at(kp, [5], np.float32).dtype == np.float32
    with pytest.raises(ParameterError, match="frames"):
        interpolate_at(kp, [72])


@pytest.mark.parametrize("interp", ["linear", "hermite", "hermite-fit"])
def test_key_curve_errors_kernel_equals_its_numpy_twin_and_the_rebuilt_animation(anim, interp, monkeypatch):
    rc = importlib.import_module("hairtool.keys.reconstruct")  # the package exports a function of that name
    keys = np.array([0, 7, 19, 33, 50, 71])
    kp = key_poses(anim.frames, keys, interp)
    monkeypatch.setattr(rc, "_CHUNK_VALUES", 3 * anim.vertex_count * 5)  # 5 frames a chunk
    got, ref = key_curve_errors(anim, kp), key_curve_errors_reference(anim, kp)
    for name in ("per_frame_mean", "per_frame_max", "per_frame_tip", "per_vertex_mean", "per_vertex_max"):
        np.testing.assert_allclose(getattr(got, name), getattr(ref, name), rtol=1e-13, atol=1e-15)
    whole = position_errors(anim, interpolate_keys(kp))
    np.testing.assert_allclose(got.per_frame_mean, whole.per_frame_mean, rtol=1e-12, atol=1e-15)
    assert np.all(got.per_frame_max[keys] == 0.0) and got.per_frame_max.max() > 0


def test_position_errors_in_scene_units(anim):
    moved = anim.frames.copy()
    moved[3, anim.topology.tip_indices] += np.array([0.0, 0.3, 0.4], dtype=np.float32)
    err = position_errors(anim, moved)
    assert err.per_frame_max[3] == pytest.approx(0.5, rel=1e-6)
    assert err.per_frame_tip[3] == pytest.approx(0.5, rel=1e-6)
    assert err.per_frame_mean[3] == pytest.approx(0.5 * anim.strand_count / anim.vertex_count, rel=1e-6)
    assert err.per_frame_max[2] == 0.0
    assert err.per_vertex_max.shape == (anim.vertex_count,)
    assert err.summary()["max"] == pytest.approx(0.5, rel=1e-6)


def test_dp_keys_beat_uniform_keys_on_a_flick(anim):
    for k in (8, 12):
        sel = find_keys(anim, keys=k)
        assert sel.cost <= sel.uniform_cost
        cmp = compare_with_uniform(anim, sel.keys)
        assert cmp["keys"]["tip_max_frame"] < cmp["uniform"]["tip_max_frame"]
        assert any(48 <= f <= 52 for f in sel.keys)  # a key on the flick


def test_key_distribution_follows_speed(anim):
    sel = find_keys(anim, keys=12)
    d = key_distribution(anim.frames, sel.keys, anim.fps)
    assert len(d["speed"]) == len(d["motion"]) == len(d["density"]) == anim.n_frames
    assert d["motion"][0] == 0.0 and d["motion"][-1] == pytest.approx(1.0)
    assert np.all(np.diff(d["motion"]) >= 0)
    assert d["speed_at_keys"] > 1.0
    assert len(d["key_motion"]) == 12


@pytest.mark.parametrize("keys", [[1, 5, 71], [0, 5, 70], [0, 5, 5, 71], [0], [0, 2.5, 71]])
def test_bad_keys_are_parameter_errors(anim, keys):
    with pytest.raises(ParameterError):
        reconstruct(anim, keys)
