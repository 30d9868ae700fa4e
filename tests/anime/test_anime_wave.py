"""Eq. (1) of Furukawa & Nakata: values worked by hand, periodicity, and parameter checks."""

from __future__ import annotations

import math

import numpy as np
import pytest

from hairtool.anime.wave import WaveParams, node_rotations, segment_angles, wave
from hairtool.errors import ParameterError
from hairtool.groom import Groom

PAPER = WaveParams(amplitude=0.8, wavelength=1.0, gravity=1.2, profile=1.0, period=0.45)


def test_values_by_hand():
    # x = π, t = 0: −(0.8/1.2)·1·(cos π + 1/1.2) = −(2/3)(−1 + 5/6) = 1/9
    assert wave(math.pi, 0.0, PAPER) == pytest.approx(1 / 9, abs=1e-15)
    # the root does not move for p > 0
    assert wave(0.0, 0.1, PAPER) == 0.0
    # p = 0: x^0 = 1 everywhere; x = 0, t = 0: −(2/3)(1 + 5/6) = −11/9
    flat = WaveParams(0.8, 1.0, 1.2, 0.0, 0.45)
    assert wave(0.0, 0.0, flat) == pytest.approx(-11 / 9, abs=1e-15)
    # a quarter period later at x = π/2, k = 1: cos(π/2 − π/2) = 1 -> −(2/3)(1/2)(1 + 5/6)
    assert wave(math.pi / 2, 0.45 / 4, PAPER) == pytest.approx(-(2 / 3) * 0.5 * (11 / 6), abs=1e-15)
    # p = 2 at x = π/2 weights by 1/4; k = 0.5 doubles the spatial frequency
    p2 = WaveParams(1.0, 0.5, 2.0, 2.0, 1.0)
    assert wave(math.pi / 2, 0.0, p2) == pytest.approx(-(1 / 2) * 0.25 * (math.cos(math.pi) + 0.5))


def test_broadcasts_and_is_periodic_in_t():
    x = np.linspace(0, np.pi, 9)
    t = np.linspace(0, 1, 5)[:, None]
    y = wave(x, t, PAPER)
    assert y.shape == (5, 9) and y.dtype == np.float64
    np.testing.assert_allclose(wave(x, t + PAPER.period, PAPER), y, atol=1e-12)
    np.testing.assert_allclose(wave(x, t + 3 * PAPER.period, PAPER), y, atol=1e-12)


def test_gravity_sags_the_line_on_average():
    x = np.linspace(0, np.pi, 33)
    t = np.linspace(0, PAPER.period, 400, endpoint=False)[:, None]
    mean = wave(x, t, PAPER).mean(axis=0)
    # the cosine averages out over a period: −(a/s²)(x/π)^p remains
    np.testing.assert_allclose(mean, -(0.8 / 1.44) * x / np.pi, atol=1e-12)


def test_amplitude_scales_linearly():
    x = np.linspace(0, np.pi, 7)
    twice = WaveParams(1.6, 1.0, 1.2, 1.0, 0.45)
    np.testing.assert_allclose(wave(x, 0.2, twice), 2 * wave(x, 0.2, PAPER), rtol=1e-14)


@pytest.mark.parametrize(
    ("kwargs", "name"),
    [
        ({"gravity": 0.0}, "gravity"),
        ({"wavelength": 0.0}, "wavelength"),
        ({"wavelength": -1.0}, "wavelength"),
        ({"period": 0.0}, "period"),
        ({"period": -0.5}, "period"),
        ({"profile": -0.1}, "profile"),
        ({"amplitude": float("nan")}, "amplitude"),
        ({"gravity": float("inf")}, "gravity"),
        ({"profile": "two"}, "profile"),
    ],
)
def test_invalid_parameters_name_themselves(kwargs, name):
    with pytest.raises(ParameterError) as e:
        WaveParams(**kwargs)
    assert e.value.name == name


def test_negative_gravity_and_amplitude_are_allowed():
    p = WaveParams(amplitude=-0.5, gravity=-1.0)
    assert np.isfinite(wave(np.pi, 0.0, p))


def test_x_outside_the_chain_is_refused():
    for bad in (-0.1, 3.2, float("nan")):
        with pytest.raises(ParameterError) as e:
            wave(bad, 0.0, PAPER)
        assert e.value.name == "x"
    with pytest.raises(ParameterError):
        wave(1.0, float("inf"), PAPER)


def test_relative_node_rotations_sum_to_segment_angles():
    chains = Groom.from_strands([np.column_stack([np.linspace(0, 2, 6), np.zeros(6)])] * 2)
    y = np.random.default_rng(3).normal(size=(4, chains.vertex_count))
    theta = segment_angles(chains, y)
    rel = node_rotations(chains, y)
    for s in range(2):
        seg = slice(5 * s, 5 * s + 5)
        np.testing.assert_allclose(np.cumsum(rel[:, seg], axis=1), theta[:, seg], atol=1e-14)
    # each segment's angle is atan2(Δy, Δx) of the sampled curve (x spaced π/5 here)
    np.testing.assert_allclose(theta[:, 0], np.arctan2(y[:, 1] - y[:, 0], np.pi / 5))
