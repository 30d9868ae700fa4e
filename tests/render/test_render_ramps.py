"""Colour ramps and palettes."""

from __future__ import annotations

import numpy as np
import pytest

from app.render.ramps import (
    RAMPS,
    categorical_colors,
    per_strand_random_colors,
    ramp_colors,
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
