"""Colour ramps and palettes."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from app.render.ramps import (
    RAMPS,
    categorical_colors,
    per_strand_random_colors,
    ramp_colors,
    sample_linear,
    sample_linear_reference,
    strand_to_vertex_colors,
)
from hairtool import samples
from hairtool.errors import ParameterError


def test_required_ramps_exist_with_rgb_stops():
    for name in ("root-tip", "viridis", "heat", "grey"):
        stops = RAMPS[name]
        assert stops.dtype == np.float32 and stops.ndim == 2 and stops.shape[1] == 3
        assert len(stops) >= 2 and stops.min() >= 0 and stops.max() <= 1


def test_root_tip_goes_from_dark_brown_to_light_blonde():
    root, tip = ramp_colors([0.0, 1.0], "root-tip")
    assert root.sum() < 0.6 and root[0] > root[2]  # dark, warm
    assert tip.sum() > 2.2 and tip[0] > tip[2]  # light, warm
    assert np.abs(tip - root).max() > 0.5


def test_ramp_interpolates_between_stops_and_clips():
    stops = RAMPS["grey"]
    mid = ramp_colors([0.5], "grey")[0]
    np.testing.assert_allclose(mid, (stops[0] + stops[-1]) / 2, atol=1e-6)
    out = ramp_colors([-3.0, 7.0], "heat")
    np.testing.assert_array_equal(out, RAMPS["heat"][[0, -1]])
    assert ramp_colors(np.zeros(0), "heat").shape == (0, 3)


def test_ramp_rejects_unknown_names_and_nan():
    with pytest.raises(ParameterError, match="ramp"):
        ramp_colors([0.5], "rainbow-unicorn")
    with pytest.raises(ParameterError, match="values"):
        ramp_colors([np.nan], "grey")


def test_per_strand_random_colors_are_seeded():
    a = per_strand_random_colors(50, seed=3)
    assert a.shape == (50, 3) and a.dtype == np.float32
    np.testing.assert_array_equal(a, per_strand_random_colors(50, seed=3))
    assert not np.array_equal(a, per_strand_random_colors(50, seed=4))
    assert len(np.unique(a, axis=0)) == 50


def test_categorical_colors_cycle_and_grey_negatives():
    c = categorical_colors([0, 1, 10, -1])
    np.testing.assert_array_equal(c[0], c[2])
    assert not np.array_equal(c[0], c[1])
    np.testing.assert_array_equal(c[3], [0.5, 0.5, 0.5])
    with pytest.raises(ParameterError):
        categorical_colors([0.5])


def test_strand_to_vertex_colors():
    g = samples.comb(strands=4, vertices=3)
    per_strand = per_strand_random_colors(4, seed=0)
    v = strand_to_vertex_colors(per_strand, g.topology)
    assert v.shape == (12, 3)
    np.testing.assert_array_equal(v[3:6], np.repeat(per_strand[1:2], 3, axis=0))


@settings(max_examples=60, deadline=None, derandomize=True)
@given(
    width=st.integers(1, 300),
    t=st.lists(st.floats(allow_nan=True, allow_infinity=True, width=64), min_size=0, max_size=40),
    seed=st.integers(0, 2**16),
)
def test_sampling_a_ramp_is_its_numpy_twin_bit_for_bit(width, t, seed):
    texels = np.random.default_rng(seed).random((width, 3))
    coords = np.array([*t, 0.0, 1.0, 0.5 / width, 1.0 - 0.5 / width, -1e300, 1e300])  # edges, centres
    with np.errstate(invalid="ignore"):  # the twin casts NaN to an index (clamped, as the kernel's)
        want = sample_linear_reference(texels, coords)
    got = sample_linear(texels, coords)
    assert got.dtype == np.float32 and np.array_equal(got.view(np.uint32), want.view(np.uint32))


def test_sampling_refuses_a_texture_without_three_channels():
    for bad in (np.zeros((0, 3)), np.zeros((4, 4)), np.zeros(3)):
        with pytest.raises(ParameterError, match="texels"):
            sample_linear(bad, [0.5])
