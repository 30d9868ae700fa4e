"""The notes on a tau, budget or bound that gave an extreme tell the truth under pins and
exclusions: the keys on every allowed frame, and what dropping one of them really costs."""

from __future__ import annotations

import numpy as np
import pytest

from hairtool.keys.constraints import KeyConstraints
from hairtool.keys.costs import cost_table
from hairtool.keys.dp import keys_cost, select_keys
from hairtool.keys.notes import dropped_costs
from hairtool.keys.session import KeySession


def explain(table, cons, objective, sel):
    return KeySession(table, objective=objective, constraints=cons).explain(sel)


def random_table(n: int, seed: int, objective: str = "total") -> np.ndarray:
    x = np.cumsum(np.random.default_rng(seed).normal(size=(n, 3)), axis=0)
    return cost_table(x, "linear", 0.0, objective)


CASES = [KeyConstraints(), KeyConstraints(excludes=(5, 6, 7, 8)), KeyConstraints((2, 12), (4, 9, 10))]


@pytest.mark.parametrize("cons", CASES, ids=str)
@pytest.mark.parametrize("objective", ["total", "worst"])
def test_dropped_costs_equal_dropping_each_key_by_hand(cons, objective):
    n = 16
    table = random_table(n, 3, objective)
    every = [f for f in range(n) if f not in cons.excludes]
    droppable = [f for f in every[1:-1] if f not in cons.pins]
    want = [keys_cost(table, [k for k in every if k != f], objective) for f in droppable]
    np.testing.assert_allclose(dropped_costs(table, cons, objective), want, rtol=1e-12)


@pytest.mark.parametrize("cons", CASES[1:], ids=str)
def test_a_key_on_every_allowed_frame_quotes_the_constrained_costs(cons):
    n = 16
    every = [f for f in range(n) if f not in cons.excludes]
    # a table where tau = 0 keys every allowed frame (not always so: across an excluded stretch
    # a longer segment can cost less than two shorter ones)
    table, sel = next(
        (t, sel)
        for t in (random_table(n, seed) for seed in range(4, 200))
        if (sel := select_keys(t, penalty=0.0, constraints=cons)).keys.tolist() == every
    )
    least = min(keys_cost(table, [k for k in every if k != f]) for f in every[1:-1] if f not in cons.pins)
    note = explain(table, cons, "total", sel)
    assert note.startswith("a key on every frame not excluded:")
    assert f"the least is {least - sel.cost:.6g}" in note


def test_a_worst_frame_bound_met_only_by_every_allowed_frame_quotes_the_constrained_costs():
    n, cons = 16, CASES[2]
    every = [f for f in range(n) if f not in cons.excludes]
    # a worst-frame table where dropping any key raises the worst error (not always so: a longer
    # segment can rebuild a frame beside an excluded stretch better)
    worst, bound = next(
        (t, keys_cost(t, every, "worst"))
        for t in (random_table(n, seed, "worst") for seed in range(4, 200))
        if keys_cost(t, every, "worst") < dropped_costs(t, cons, "worst").min()
    )
    sel = select_keys(worst, max_error=bound, constraints=cons)
    assert sel.keys.tolist() == every
    note = explain(worst, cons, "worst", sel)
    assert note.startswith("a key on every frame not excluded: the worst-frame bound")
    assert f"(the least is {dropped_costs(worst, cons, 'worst').min():.6g})" in note


def test_the_fewest_keys_under_pins_quote_their_own_error():
    table = random_table(16, 5)
    cons = KeyConstraints(pins=(4, 11), excludes=(7,))
    sel = select_keys(table, penalty=1e9, constraints=cons)
    assert sel.keys.tolist() == [0, 4, 11, 15]
    note = explain(table, cons, "total", sel)
    assert note.startswith("only the first, last and pinned frames: no key saves more than its price")
    assert f"keying only those costs {keys_cost(table, [0, 4, 11, 15]):.6g}" in note
    assert explain(table, KeyConstraints(excludes=tuple(range(1, 15))), "total", sel) is None
