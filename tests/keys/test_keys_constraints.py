"""Pinned and excluded frames: the DP returns the exact optimum under them, for every mode and
both objectives (brute force on small inputs, an independent DP on larger ones), and refuses
constraints no key set can meet with one clear error."""

from __future__ import annotations

from itertools import combinations

import numpy as np
import pytest

from hairtool.errors import ParameterError
from hairtool.keys.constraints import KeyConstraints, parse_frames
from hairtool.keys.costs import cost_table
from hairtool.keys.dp import keys_cost, select_keys


def random_table(n: int, seed: int, objective: str = "total") -> np.ndarray:
    x = np.cumsum(np.random.default_rng(seed).normal(size=(n, 3)), axis=0)
    return cost_table(x, "linear", 0.0, objective)


def feasible_sets(n: int, cons: KeyConstraints):
    inner = [f for f in range(1, n - 1) if f not in cons.excludes]
    for r in range(len(inner) + 1):
        for chosen in combinations(inner, r):
            keys = (0, *chosen, n - 1)
            if cons.allows(keys):
                yield np.array(keys)


def brute(table, cons, objective, *, keys=None, penalty=None, budget=None, max_error=None):
    """The best (cost, count) by enumeration, in each mode's own order of preference."""
    n = table.shape[0]
    best = None
    for k in feasible_sets(n, cons):
        cost = keys_cost(table, k, objective)
        if keys is not None:
            if k.size == keys and (best is None or cost < best[0]):
                best = (cost, k.size)
        elif penalty is not None:
            score = cost + penalty * k.size
            if best is None or score < best[2]:
                best = (cost, k.size, score)
        else:
            bound = budget if budget is not None else max_error
            if cost <= bound and (best is None or (k.size, cost) < (best[1], best[0])):
                best = (cost, k.size)
    return best


CASES = [
    KeyConstraints(pins=(3,)),
    KeyConstraints(excludes=(4, 5)),
    KeyConstraints(pins=(2, 7), excludes=(5,)),
    KeyConstraints(pins=(1, 8), excludes=(3, 4, 6)),
]


@pytest.mark.parametrize("cons", CASES, ids=str)
@pytest.mark.parametrize("objective", ["total", "worst"])
@pytest.mark.parametrize("seed", [0, 1, 2])
def test_constrained_optimum_equals_brute_force(cons, objective, seed):
    n = 10
    table = random_table(n, seed, objective)
    lo, hi = cons.key_range(n)
    for k in range(lo, hi + 1):
        sel = select_keys(table, keys=k, objective=objective, constraints=cons)
        assert cons.allows(sel.keys) and sel.keys.size == k
        assert sel.cost == pytest.approx(brute(table, cons, objective, keys=k)[0], rel=1e-12, abs=1e-12)
    top = float(np.max(table[np.triu_indices(n, 1)]))
    for frac in (0.02, 0.1, 0.5):
        bound = frac * top
        mode = {"budget": bound} if objective == "total" else {"max_error": bound}
        want = brute(table, cons, objective, **mode)
        if want is None:
            with pytest.raises(ParameterError, match="pins and exclusions"):
                select_keys(table, objective=objective, constraints=cons, **mode)
            continue
        sel = select_keys(table, objective=objective, constraints=cons, **mode)
        assert cons.allows(sel.keys) and sel.keys.size == want[1]
        assert sel.cost == pytest.approx(want[0], rel=1e-12, abs=1e-12)
    if objective == "total":
        for tau in (0.0, 0.1 * top, 2.0 * top):
            sel = select_keys(table, penalty=tau, constraints=cons)
            want = brute(table, cons, objective, penalty=tau)
            assert cons.allows(sel.keys)
            assert sel.cost + tau * sel.keys.size == pytest.approx(want[2], rel=1e-12, abs=1e-12)


def allowed_by_definition(cons: KeyConstraints):
    pins, excl = set(cons.pins), set(cons.excludes)
    return lambda i, j: i not in excl and j not in excl and not any(i < p < j for p in pins)


def independent_layers(table: np.ndarray, cons: KeyConstraints, kmax: int, objective: str) -> np.ndarray:
    """E[K] for K = 0..kmax over the allowed segments, written from the definition of the
    constraints (no masked table)."""
    n = table.shape[0]
    allowed = allowed_by_definition(cons)
    e = np.full((kmax + 1, n), np.inf)
    e[1, 0] = 0.0
    for kk in range(2, kmax + 1):
        for j in range(1, n):
            for i in range(j):
                if allowed(i, j) and np.isfinite(e[kk - 1, i]):
                    v = max(e[kk - 1, i], table[i, j]) if objective == "worst" else e[kk - 1, i] + table[i, j]
                    e[kk, j] = min(e[kk, j], v)
    return e[:, n - 1]


def independent_priced(table: np.ndarray, cons: KeyConstraints, tau: float) -> float:
    """min over allowed key sets of Σ C + tau · K (seed 003), from the definition."""
    n = table.shape[0]
    allowed = allowed_by_definition(cons)
    e = np.full(n, np.inf)
    e[0] = tau
    for j in range(1, n):
        e[j] = min((e[i] + table[i, j] + tau for i in range(j) if allowed(i, j)), default=np.inf)
    return float(e[n - 1])


LONG = KeyConstraints(pins=(7, 20, 21, 40), excludes=(10, 11, 12, 33))


@pytest.mark.parametrize("objective", ["total", "worst"])
def test_constrained_optimum_equals_an_independent_dp_on_a_longer_animation(objective):
    n = 48
    table = random_table(n, 5, objective)
    cons = LONG
    energy = independent_layers(table, cons, 15, objective)
    for k in (6, 9, 15):
        sel = select_keys(table, keys=k, objective=objective, constraints=cons)
        assert cons.allows(sel.keys)
        assert sel.cost == pytest.approx(energy[k], rel=1e-12)
        assert sel.params["pins"] == [7, 20, 21, 40] and sel.params["excludes"] == [10, 11, 12, 33]
    free = select_keys(table, keys=9, objective=objective)
    assert select_keys(table, keys=9, objective=objective, constraints=cons).cost >= free.cost


@pytest.mark.parametrize("objective", ["total", "worst"])
def test_the_fewest_keys_within_a_bound_equal_an_independent_dp_on_a_longer_animation(objective):
    """The budget (total) and the worst-frame bound: the first K whose independent optimum fits."""
    n, cons = 48, LONG
    table = random_table(n, 6, objective)
    lo, hi = cons.key_range(n)
    energy = independent_layers(table, cons, hi, objective)
    mode = "budget" if objective == "total" else "max_error"
    for bound in np.quantile(energy[lo : hi + 1], [0.05, 0.3, 0.7]):
        want = lo + int(np.flatnonzero(energy[lo : hi + 1] <= bound)[0])
        sel = select_keys(table, objective=objective, constraints=cons, **{mode: float(bound)})
        assert cons.allows(sel.keys) and sel.n_keys == want
        assert sel.cost == pytest.approx(energy[want], rel=1e-12) and sel.cost <= bound
    with pytest.raises(ParameterError, match="pins and exclusions can meet"):
        select_keys(table, objective=objective, constraints=cons, **{mode: float(energy[lo:].min()) * 0.5})


def test_a_price_per_key_equals_an_independent_dp_on_a_longer_animation():
    n, cons = 48, LONG
    table = random_table(n, 7)
    top = float(table[0, n - 1])
    for tau in (0.0, 1e-3 * top, 0.02 * top, 0.3 * top):
        sel = select_keys(table, penalty=tau, constraints=cons)
        assert cons.allows(sel.keys)
        priced = sel.cost + tau * sel.n_keys
        assert priced == pytest.approx(independent_priced(table, cons, tau), rel=1e-12, abs=1e-12)


def test_the_numpy_twins_agree_under_constraints():
    table = random_table(30, 3)
    cons = KeyConstraints(pins=(5, 17), excludes=(9, 10))
    for mode in ({"keys": 7}, {"penalty": 0.5}, {"budget": 5.0}):
        a = select_keys(table, constraints=cons, **mode)
        b = select_keys(table, constraints=cons, use_numba=False, **mode)
        np.testing.assert_array_equal(a.keys, b.keys)


def test_no_constraints_change_nothing():
    table = random_table(25, 4)
    a = select_keys(table, keys=6)
    b = select_keys(table, keys=6, constraints=KeyConstraints())
    np.testing.assert_array_equal(a.keys, b.keys)
    assert a.to_dict() == b.to_dict()


def test_impossible_constraints_are_one_clear_error():
    table = random_table(12, 0)
    with pytest.raises(ParameterError, match=r"exclude.*first \(0\) and the last \(11\)"):
        select_keys(table, keys=4, constraints=KeyConstraints(excludes=(0, 5)))
    with pytest.raises(ParameterError, match="exclude"):
        select_keys(table, keys=4, constraints=KeyConstraints(excludes=(11,)))
    with pytest.raises(ParameterError, match="at least one frame left"):
        select_keys(table, keys=4, constraints=KeyConstraints(pins=tuple(range(1, 11))))
    with pytest.raises(ParameterError, match=r"keys=3 .*\[4, 12\] with these pins"):
        select_keys(table, keys=3, constraints=KeyConstraints(pins=(3, 6)))
    with pytest.raises(ParameterError, match=r"\[2, 10\]"):
        select_keys(table, keys=11, constraints=KeyConstraints(excludes=(3, 4)))
    with pytest.raises(ParameterError, match="pin"):
        KeyConstraints(pins=(3,), excludes=(3,))
    with pytest.raises(ParameterError, match="pin"):
        select_keys(table, keys=4, constraints=KeyConstraints(pins=(12,)))


@pytest.mark.parametrize("objective", ["total", "worst"])
def test_excluding_every_inner_frame_leaves_the_two_ends_in_every_mode(objective):
    table = random_table(12, 1, objective)
    cons = KeyConstraints(pins=(), excludes=tuple(range(1, 11)))
    assert cons.check(12).key_range(12) == (2, 2)
    bound = float(table[0, 11])
    modes = [{"keys": 2}, {"max_error": bound}]
    modes += [{"penalty": 0.0}, {"budget": bound}] if objective == "total" else []
    for mode in modes:
        assert select_keys(table, objective=objective, constraints=cons, **mode).keys.tolist() == [0, 11]
    with pytest.raises(ParameterError, match=r"keys=3 .*2, the only count with these pins"):
        select_keys(table, keys=3, objective=objective, constraints=cons)
    mixed = KeyConstraints(pins=(4,), excludes=(*range(1, 4), *range(5, 11)))  # no frame left free
    assert select_keys(table, keys=3, objective=objective, constraints=mixed).keys.tolist() == [0, 4, 11]


def test_frame_lists_parse_like_the_command_line():
    assert parse_frames("pin", "10,55") == (10, 55)
    assert parse_frames("exclude", "30-34, 40") == (30, 31, 32, 33, 34, 40)
    assert parse_frames("pin", "") == ()
    for bad in ("a", "5-3", "-2", "1.5"):
        with pytest.raises(ParameterError):
            parse_frames("pin", bad)
