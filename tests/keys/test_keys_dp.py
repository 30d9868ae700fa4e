"""The exact DP: brute force over all key sets, numba/numpy twins, every mode, generic tables."""

from __future__ import annotations

from itertools import combinations

import numpy as np
import pytest

from hairtool.errors import ParameterError
from hairtool.keys.channels import per_channel_keys
from hairtool.keys.costs import cost_table
from hairtool.keys.dp import (
    _layers_in_blocks,
    _penalty_kernel,
    brute_force_keys,
    keys_cost,
    layers_reference,
    penalty_reference,
    select_keys,
    uniform_keys,
)
from hairtool.keys.session import find_keys


def walk(n: int, d: int, seed: int = 0) -> np.ndarray:
    return np.cumsum(np.random.default_rng(seed).normal(size=(n, d)), axis=0)


def all_key_sets(n: int):
    for k in range(2, n + 1):
        for inner in combinations(range(1, n - 1), k - 2):
            yield np.array((0, *inner, n - 1))


@pytest.mark.parametrize("objective", ["total", "worst"])
@pytest.mark.parametrize("interp", ["linear", "hermite"])
def test_exact_k_matches_brute_force(objective, interp):
    x = walk(11, 3, seed=7)
    table = cost_table(x, interp, 0.3, objective)
    sel = select_keys(table, keys=2, objective=objective, curve_keys=11)
    for k, cost in sel.curve:
        best, _ = brute_force_keys(table, int(k), objective)
        assert cost == pytest.approx(best, rel=1e-12, abs=1e-12)
    for k in range(2, 12):
        s = select_keys(table, keys=k, objective=objective)
        assert s.keys.size == k and s.keys[0] == 0 and s.keys[-1] == 10
        assert s.cost == pytest.approx(brute_force_keys(table, k, objective)[0], rel=1e-12, abs=1e-12)


def test_kernels_and_numpy_twins_are_bit_identical():
    rng = np.random.default_rng(8)
    for n in (2, 3, 17, 64):
        table = np.triu(rng.random((n, n)) ** 3, 1)
        table[0, n - 1] = table[0, n - 1]  # keep dtype float64
        for use_max in (False, True):
            a = _layers_in_blocks(np.ascontiguousarray(table.T), n, use_max, -np.inf)
            b = layers_reference(table, n, use_max)
            for u, v in zip(a, b, strict=True):
                np.testing.assert_array_equal(u, v)
        for tau in (0.0, 0.1, 3.0):
            a = _penalty_kernel(np.ascontiguousarray(table.T), tau)
            b = penalty_reference(table, tau)
            np.testing.assert_array_equal(a[0], b[0])
            np.testing.assert_array_equal(a[1], b[1])


def test_ties_are_broken_the_same_way():
    table = np.triu(np.ones((9, 9)), 1)  # every key set of a given size costs the same
    for use_numba in (True, False):
        assert select_keys(table, keys=4, use_numba=use_numba).keys.tolist() == [0, 1, 2, 8]


@pytest.mark.parametrize("tau", [0.0, 0.5, 4.0, 1e6])
def test_penalty_matches_brute_force(tau):
    x = walk(10, 2, seed=9)
    table = cost_table(x)
    best = min(keys_cost(table, k) + tau * k.size for k in all_key_sets(10))
    sel = select_keys(table, penalty=tau)
    assert sel.cost + tau * sel.n_keys == pytest.approx(best, rel=1e-12)
    if tau == 1e6:
        assert sel.keys.tolist() == [0, 9]


def test_budget_and_max_error_give_the_fewest_keys():
    x = walk(10, 2, seed=10)
    total = cost_table(x)
    worst = cost_table(x, objective="worst")
    sets = list(all_key_sets(10))
    for budget in (0.0, 1.0, 5.0, 40.0):
        fewest = min(k.size for k in sets if keys_cost(total, k) <= budget)
        sel = select_keys(total, budget=budget)
        assert sel.n_keys == fewest and sel.cost <= budget
    for bound in (0.0, 0.5, 2.0, 10.0):
        fewest = min(k.size for k in sets if keys_cost(worst, k, "worst") <= bound)
        sel = select_keys(worst, max_error=bound, objective="worst")
        assert sel.n_keys == fewest and sel.cost <= bound and sel.objective == "worst"


def test_true_knots_of_a_piecewise_linear_signal_are_found_exactly():
    rng = np.random.default_rng(11)
    n = 200
    knots = np.sort(rng.choice(np.arange(5, n - 5), size=6, replace=False))
    knots = np.concatenate([[0], knots, [n - 1]])
    values = rng.normal(size=(knots.size, 4)) * 5
    x = np.stack([np.interp(np.arange(n), knots, values[:, c]) for c in range(4)], axis=1)
    sel = find_keys(x, keys=knots.size)
    assert sel.keys.tolist() == knots.tolist()
    assert sel.cost < 1e-9
    assert find_keys(x, budget=1e-9).keys.tolist() == knots.tolist()
    assert sel.uniform_cost > 1.0


def test_curve_is_monotone_and_matches_single_solves():
    table = cost_table(walk(60, 4, seed=12))
    sel = select_keys(table, keys=5, curve_keys=30)
    ks, costs = sel.curve[:, 0], sel.curve[:, 1]
    assert ks.tolist() == list(range(2, 31))
    assert np.all(np.diff(costs) <= 1e-12)
    for k in (3, 17, 30):
        assert select_keys(table, keys=k).cost == pytest.approx(costs[k - 2], rel=1e-12)
    d = sel.to_dict()
    assert d["uniform"]["keys"] == uniform_keys(60, 5).tolist()
    assert d["uniform"]["cost"] >= d["cost"]


def test_a_generic_table_is_accepted():
    rng = np.random.default_rng(13)
    table = rng.random((9, 9))
    table = table + table.T  # a symmetric table, like the quaternion one
    best, keys = brute_force_keys(table, 4)
    sel = select_keys(table, keys=4)
    assert sel.cost == pytest.approx(best) and sel.keys.tolist() == keys.tolist()


@pytest.mark.parametrize(
    "kwargs",
    [
        {"keys": 1},
        {"keys": 11},
        {"keys": 2.5},
        {"keys": float("nan")},
        {"keys": 3, "curve_keys": -1},
        {"penalty": -1.0},
        {"budget": float("nan")},
        {"max_error": -0.1},
        {},
        {"keys": 3, "penalty": 1.0},
        {"keys": 3, "objective": "median"},
        {"budget": 1.0, "objective": "worst"},
    ],
)
def test_bad_modes_are_parameter_errors(kwargs):
    with pytest.raises(ParameterError):
        select_keys(cost_table(walk(10, 2)), **kwargs)


def test_bad_tables_are_parameter_errors():
    with pytest.raises(ParameterError):
        select_keys(np.zeros((1, 1)), keys=2)
    with pytest.raises(ParameterError):
        select_keys(np.zeros((3, 4)), keys=2)
    t = np.zeros((4, 4))
    t[0, 3] = np.nan
    with pytest.raises(ParameterError):
        select_keys(t, keys=2)


def test_per_channel_keys_each_channel_on_its_own():
    n = 80
    t = np.arange(n)
    x = np.column_stack([np.interp(t, [0, 30, 79], [0, 5, 0]), np.sin(t / 6.0) * 3, np.zeros(n)])
    res = per_channel_keys(x, [0.01, 0.01, 0.01], interp="linear")
    assert res.keys[0].tolist() == [0, 30, 79]
    assert res.keys[2].tolist() == [0, 79]
    assert res.keys[1].size > 5
    for c in range(3):
        single = select_keys(cost_table(x[:, c : c + 1]), penalty=0.01)
        assert res.keys[c].tolist() == single.keys.tolist()
    assert set(res.union().tolist()) >= {0, 30, 79}
    with pytest.raises(ParameterError):
        per_channel_keys(x, [1.0, 2.0])
    with pytest.raises(ParameterError):
        per_channel_keys(x, -1.0)


def test_a_constant_channel_takes_two_keys_at_a_relative_price():
    """Its two-key error is 0 up to rounding, a hair below 0 for a constant -1.636 (a finger
    channel of the bundled mixamo capture): a share of it is a price of 0, not a negative one."""
    x = np.column_stack([np.full(69, -1.636), np.full(69, -23.5577), np.sin(np.arange(69) / 5.0)])
    assert cost_table(x[:, 1:2], "hermite")[0, -1] < 0
    res = per_channel_keys(x, 0.01, interp="hermite", relative=True)
    assert res.keys[0].tolist() == [0, 68] and res.keys[1].tolist() == [0, 68]
    assert np.all(res.penalties >= 0)


@pytest.mark.parametrize("objective", ["total", "worst"])
def test_bounds_that_need_more_keys_than_one_layer_block(objective):
    table = cost_table(walk(90, 3, seed=14), objective=objective)
    full = select_keys(table, keys=2, objective=objective, curve_keys=90).curve
    for k in (17, 33, 40):  # inside and just past the kernel's blocks of 16 layers
        bound = full[k - 2, 1]
        fewest = int(full[np.argmax(full[:, 1] <= bound), 0])
        mode = {"budget": bound} if objective == "total" else {"max_error": bound}
        sel = select_keys(table, objective=objective, **mode)
        twin = select_keys(table, objective=objective, use_numba=False, **mode)
        assert sel.n_keys == fewest and sel.keys.tolist() == twin.keys.tolist()
        assert sel.curve.shape[0] >= 99 - 10 and sel.cost <= bound


def test_the_dp_in_blocks_reports_progress_and_gives_the_same_bits():
    """A long animation's progress bar moves through the DP's blocks of layers; the numbers are
    the single kernel's, stop included."""
    from hairtool.keys.dp import solve_layers

    table = cost_table(walk(90, 5, seed=4))
    for objective, stop in (("total", -np.inf), ("worst", -np.inf), ("total", 1.0)):
        shares = []
        a = solve_layers(table, 60, objective, stop=stop)
        b = solve_layers(table, 60, objective, stop=stop, progress=shares.append)
        for u, v in zip(a, b, strict=True):
            np.testing.assert_array_equal(u, v)
        if stop == -np.inf:
            assert len(shares) == 4 and shares == sorted(shares) and shares[-1] == 1.0


def test_a_solve_reports_progress_in_proportion_to_the_work():
    from hairtool.keys.session import KeySettings, solve

    seen = []
    session = solve(walk(300, 12), KeySettings(count=8), lambda f, stage="": seen.append((f, stage)))
    fractions = [f for f, _ in seen]
    assert fractions == sorted(fractions) and fractions[0] == 0.0 and fractions[-1] == 1.0
    dp = [f for f, stage in seen if stage == "dynamic programming"]
    assert len(dp) >= 7 and dp[0] < 0.9  # every block of layers, the DP being most of the work
    assert session.keys_for_count(8).size == 8
