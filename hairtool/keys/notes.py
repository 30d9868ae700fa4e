"""Why a price per key, an error budget or a worst-frame bound gave one of the two extremes,
in words a user can act on.

The extremes are the keys on every frame the constraints allow and the fewest keys they allow
(the ends and the pins). The numbers quoted are those of the constrained problem: the keys one
could drop are the unpinned ones, and dropping one joins the segments beside it across the
excluded frames, never across a forbidden segment.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from hairtool.keys.constraints import KeyConstraints
from hairtool.keys.dp import Selection

F64 = NDArray[np.float64]

WHAT = {"penalty": "the price per key", "budget": "the error budget", "max_error": "the worst-frame bound"}


def dropped_costs(table: F64, constraints: KeyConstraints, objective: str = "total") -> F64:
    """The error of the keys on every allowed frame with one unpinned inner key dropped, for
    each such key in frame order (total: the sum over segments; worst: their maximum).

    Parameters
    ----------
    table : ndarray
        ``(n, n)`` segment costs.
    constraints : KeyConstraints
        Pins and exclusions.
    objective : str, default "total"
        Sum or maximum.

    Returns
    -------
    ndarray
        float64, one per droppable key.
    """
    n = table.shape[0]
    keys = np.setdiff1d(np.arange(n), np.asarray(constraints.excludes, dtype=np.int64))
    seg = table[keys[:-1], keys[1:]]  # between neighbouring keys
    joined = table[keys[:-2], keys[2:]]  # across key i + 1, once it is dropped
    free = ~np.isin(keys[1:-1], np.asarray(constraints.pins, dtype=np.int64))
    if objective == "worst":
        low = np.full(1, -np.inf)
        before = np.concatenate([low, np.maximum.accumulate(seg)[:-2]])  # segments left of the pair
        after = np.concatenate([np.maximum.accumulate(seg[::-1])[::-1][2:], low])
        cost = np.maximum(np.maximum(before, after), joined)
    else:
        cost = float(np.sum(seg)) + joined - seg[:-1] - seg[1:]
    return cost[free]


def explain(table: F64, constraints: KeyConstraints, objective: str, sel: Selection) -> str | None:
    """A note for a tau, budget or bound that gave the most or the fewest keys the constraints
    allow (None otherwise, and for an exact count).

    Parameters
    ----------
    table : ndarray
        ``(n, n)`` segment costs.
    constraints : KeyConstraints
        Pins and exclusions.
    objective : str
        Sum or maximum.
    sel : Selection
        The selection.

    Returns
    -------
    str or None
        The note.
    """
    if sel.mode == "keys":
        return None
    n = table.shape[0]
    lo, hi = constraints.key_range(n)
    if hi == lo:
        return None
    value = float(sel.params[sel.mode])
    if sel.n_keys == hi:
        every = "a key on every frame not excluded" if constraints.excludes else "a key on every frame"
        least = float(dropped_costs(table, constraints, objective).min())
        if sel.mode == "penalty":
            return (
                f"{every}: the price per key ({value:.6g}) is below what dropping any one of them "
                f"costs (the least is {least - sel.cost:.6g})"
            )
        return (
            f"{every}: {WHAT[sel.mode]} ({value:.6g}) is below the error with any one of them dropped "
            f"(the least is {least:.6g})"
        )
    if sel.n_keys == lo:
        ends = "two keys" if lo == 2 else "only the first, last and pinned frames"
        if sel.mode == "penalty":
            alone = "the ends alone" if lo == 2 else "only those"
            price = f"its price ({value:.6g}; keying {alone} costs {sel.cost:.6g})"
            return f"{ends}: no key saves more than {price}"
        return f"{ends}: they already meet {WHAT[sel.mode]} ({value:.6g}; their error is {sel.cost:.6g})"
    return None
