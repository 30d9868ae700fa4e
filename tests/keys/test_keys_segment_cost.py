"""Gram + prefix-sum cost tables against the direct O(n³D) oracle and their numpy twins."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from hairtool.errors import ParameterError
from hairtool.keys.costs import cost_table, total_table
from hairtool.keys.gram import centered_gram, frame_curvature
from hairtool.keys.segment_direct import direct_cost_table
from hairtool.keys.segment_worst import worst_table


def walk(n: int, d: int, seed: int = 0, offset: float = 0.0) -> np.ndarray:
    return np.cumsum(np.random.default_rng(seed).normal(size=(n, d)), axis=0) + offset


@pytest.mark.parametrize("interp", ["linear", "hermite"])
@pytest.mark.parametrize("objective", ["total", "worst"])
@pytest.mark.parametrize("lam", [0.0, 0.5])
def test_kernel_twin_and_oracle_agree(interp, objective, lam):
    x = walk(37, 5, seed=1)
    direct = direct_cost_table(x, interp, lam, objective)
    fast = cost_table(x, interp, lam, objective)
    twin = cost_table(x, interp, lam, objective, use_numba=False)
    scale = np.abs(direct).max()
    assert np.abs(fast - direct).max() <= 1e-11 * scale
    assert np.abs(twin - direct).max() <= 1e-11 * scale
    assert fast.shape == (37, 37)
    assert np.all(fast[np.tril_indices(37, 1)] == 0.0)


@pytest.mark.parametrize("offset", [0.0, 1e4])
def test_linear_table_agrees_to_1e9_relative_despite_a_large_offset(offset):
    x = walk(150, 20, seed=2, offset=offset)
    direct = direct_cost_table(x)
    fast = cost_table(x)
    i, j = np.triu_indices(150, 2)
    assert np.abs(fast - direct).max() <= 1e-9 * np.abs(direct).max()
    # entry by entry, relative to the entry plus the skipped frames' own spread
    spread = np.array([np.sum((x[a + 1 : b] - x[a + 1 : b].mean(0)) ** 2) for a, b in zip(i, j, strict=True)])
    assert np.all(np.abs(fast[i, j] - direct[i, j]) <= 1e-9 * (direct[i, j] + spread) + 1e-300)


def test_piecewise_linear_segments_cost_nothing():
    knots = np.array([0, 7, 19, 30])
    rng = np.random.default_rng(4)
    values = rng.normal(size=(4, 3))
    x = np.stack([np.interp(np.arange(31), knots, values[:, c]) for c in range(3)], axis=1)
    t = cost_table(x)
    for a, b in itertools.pairwise(knots):
        assert abs(t[a, b]) < 1e-12
    assert t[0, 19] > 1e-3


def test_hermite_reproduces_straight_lines_exactly():
    x = np.outer(np.arange(25.0), [1.0, -2.0, 0.5])  # constant velocity: tangents are exact
    assert np.abs(cost_table(x, "hermite")).max() < 1e-9
    assert np.abs(cost_table(x, "linear")).max() < 1e-9


def test_curvature_adds_the_second_differences_of_skipped_frames():
    x = walk(20, 3, seed=5)
    c = frame_curvature(x)
    assert c[0] == c[-1] == 0.0
    base, curved = cost_table(x), cost_table(x, curvature=2.0)
    assert np.isclose(curved[3, 11] - base[3, 11], 2.0 * c[4:11].sum(), rtol=1e-9)


def test_gram_is_centred_and_chunked():
    x = walk(30, 50, seed=6, offset=3.0)
    xc = x - x.mean(0)
    np.testing.assert_allclose(centered_gram(x, chunk_columns=7), xc @ xc.T, rtol=1e-12, atol=1e-9)


def test_bad_parameters():
    x = walk(10, 2)
    with pytest.raises(ParameterError):
        cost_table(x, interp="cubic")
    with pytest.raises(ParameterError):
        cost_table(x, objective="mean")
    with pytest.raises(ParameterError):
        cost_table(x, curvature=-1.0)
    with pytest.raises(ParameterError):
        total_table(np.zeros((3, 4)), np.zeros(3))
    with pytest.raises(ParameterError):
        worst_table(np.zeros((3, 3)), np.zeros(4))
