"""Globally optimal keyframes by dynamic programming over a segment cost table (seeds 000, 003).

One engine, any ``(n, n)`` table C (C[i, j] the cost of keys i < j with nothing between;
entries i >= j are ignored): the Gram tables of :mod:`hairtool.keys.costs` or the rotation
table of :mod:`hairtool.mocap.costs`. Keys always include the first and last frame.

- exactly K keys, for every K up to a limit in one solve (the error-versus-key-count curve):
  E_K(j) = min_{i<j} E_{K−1}(i) ⊕ C[i, j], with ⊕ = + (total) or max (worst frame);
- a price tau per key (seed 003): E(j) = min_{i<j} E(i) + C[i, j] + tau;
- the fewest keys whose total error is <= a budget, or whose worst frame is <= a bound
  (Salient Poses, Roberts et al. 2019): the layers above, stopped at the first K that fits.
Ties go to the smallest i, so the numba kernels and their numpy twins return the same keys.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
from numba import njit
from numpy.typing import ArrayLike, NDArray

from hairtool.errors import ParameterError
from hairtool.keys.constraints import KeyConstraints

F64 = NDArray[np.float64]
I64 = NDArray[np.int64]

DEFAULT_CURVE_KEYS = 100


# -- kernels and their twins -----------------------------------------------------------------
_LAYER_BLOCK = 16


# fastmath: only "no NaN" (tables are checked finite) and reassociation of the min-reduction,
# which is exact, so the inner loops vectorise and the result stays bit-identical. Layers are
# swept in blocks of 16, row j outermost, so each table row is read once per block from cache
# instead of once per layer (the table is larger than L2 from n ≈ 600). Serial: a parallel
# loop over j must synchronise per layer and lost 3x on the shared 2 cores.
@njit(cache=True, nogil=True, fastmath={"nnan", "nsz", "reassoc"})
def _layer_block(ct, e, back, k0, k1, use_max):  # pragma: no cover - compiled
    """Layers K = k0 … k1 − 1 of E and back (rows of ``e``, ``back``), layers below k0 done."""
    n = ct.shape[0]
    for j in range(k0 - 1, n):
        row = ct[j]
        for kk in range(k0, min(k1, j + 2)):  # layer kk reaches frame j when j >= kk − 1
            prev = e[kk - 1]
            best = np.inf
            if use_max:
                for i in range(kk - 2, j):
                    best = min(best, max(prev[i], row[i]))
                for i in range(kk - 2, j):
                    if max(prev[i], row[i]) == best:
                        back[kk, j] = i
                        break
            else:
                for i in range(kk - 2, j):
                    best = min(best, prev[i] + row[i])
                for i in range(kk - 2, j):  # the first i that reaches the minimum
                    if prev[i] + row[i] == best:
                        back[kk, j] = i
                        break
            e[kk, j] = best


def _layers_in_blocks(
    ct: F64, kmax: int, use_max: bool, stop: float, progress: Callable[[float], None] | None = None
):
    """E[K, j], back[K, j] for K = 1..kmax from the transposed table ct[j, i] = C[i, j], one
    :func:`_layer_block` per call, saying after each what share of the DP is done (every layer
    costs about the same). Stops after the block holding the first K with E[K, n−1] <= stop;
    returns that K (or kmax) too."""
    n = ct.shape[0]
    e = np.full((kmax + 1, n), np.inf)
    back = np.full((kmax + 1, n), -1, dtype=np.int64)
    e[1, 0] = 0.0
    for k0 in range(2, kmax + 1, _LAYER_BLOCK):
        k1 = min(kmax + 1, k0 + _LAYER_BLOCK)
        _layer_block(ct, e, back, k0, k1, use_max)
        for kk in range(k0, k1):
            if e[kk, n - 1] <= stop:
                return e, back, kk
        if progress is not None:
            progress((k1 - 2) / max(kmax - 1, 1))
    return e, back, kmax


def layers_reference(c: F64, kmax: int, use_max: bool = False, stop: float = -np.inf):
    """Numpy twin of the layered DP (same sums, same first-minimum tie-break).

    Parameters
    ----------
    c : ndarray
        ``(n, n)`` segment costs.
    kmax : int
        The most keys.
    use_max : bool, default False
        Worst-frame objective (maximum instead of sum).
    stop : float, default -inf
        Stop once a layer's best error is at most this.

    Returns
    -------
    tuple
        As the kernel gives them: energies, back-pointers and the last K computed.
    """
    n = c.shape[0]
    e = np.full((kmax + 1, n), np.inf)
    back = np.full((kmax + 1, n), -1, dtype=np.int64)
    e[1, 0] = 0.0
    upper = np.triu(np.ones((n, n), dtype=bool), 1)
    last = kmax
    for kk in range(2, kmax + 1):
        prev = e[kk - 1][:, None]
        v = np.maximum(prev, c) if use_max else prev + c
        v = np.where(upper, v, np.inf)
        v[: kk - 2] = np.inf
        arg = np.argmin(v, axis=0)
        best = v[arg, np.arange(n)]
        cols = np.arange(kk - 1, n)
        e[kk, cols] = best[cols]
        back[kk, cols] = arg[cols]
        if e[kk, n - 1] <= stop:
            last = kk
            break
    return e, back, last


@njit(cache=True, nogil=True)
def _penalty_kernel(ct, tau):  # pragma: no cover - compiled
    n = ct.shape[0]
    e = np.full(n, np.inf)
    back = np.full(n, -1, dtype=np.int64)
    e[0] = tau
    for j in range(1, n):
        best = np.inf
        arg = -1
        for i in range(j):
            v = e[i] + ct[j, i] + tau
            if v < best:
                best = v
                arg = i
        e[j] = best
        back[j] = arg
    return e, back


def penalty_reference(c: F64, tau: float):
    """Numpy twin of the per-key-price DP.

    Parameters
    ----------
    c : ndarray
        ``(n, n)`` segment costs.
    tau : float
        The price of a key.

    Returns
    -------
    tuple of (ndarray, ndarray)
        ``(n,)`` best errors and back-pointers, as the kernel gives them.
    """
    n = c.shape[0]
    e = np.full(n, np.inf)
    back = np.full(n, -1, dtype=np.int64)
    e[0] = tau
    for j in range(1, n):
        v = e[:j] + c[:j, j] + tau
        back[j] = int(np.argmin(v))
        e[j] = v[back[j]]
    return e, back


def _trace(back_row_of, n: int) -> I64:
    keys = [n - 1]
    while keys[-1] != 0:
        keys.append(int(back_row_of(len(keys), keys[-1])))
    return np.array(keys[::-1], dtype=np.int64)


# -- public ------------------------------------------------------------------------------------
def uniform_keys(n: int, k: int) -> I64:
    """K keys spread evenly over n frames (rounded; first and last included).

    Parameters
    ----------
    n : int
        Frames.
    k : int
        Keys wanted (≥ 2; past n, rounding merges some).

    Returns
    -------
    ndarray
        ``(k,)`` int64 frame numbers, ascending (fewer where k > n).
    """
    return np.unique(np.round(np.linspace(0, n - 1, k)).astype(np.int64))


def keys_cost(table: F64, keys: ArrayLike, objective: str = "total") -> float:
    """The table's cost of a key set: sum (total) or maximum (worst) over its segments.

    Parameters
    ----------
    table : ndarray
        ``(n, n)`` segment costs.
    keys : array_like
        Key frames.
    objective : {"total", "worst"}, default "total"
        Sum or maximum.

    Returns
    -------
    float
        The cost.
    """
    k = np.asarray(keys, dtype=np.int64)
    seg = np.asarray(table)[k[:-1], k[1:]]
    if seg.size == 0:
        return 0.0
    # summed first key to last, in the DP's order, so a solve's cost is bit-identical to its E
    return float(seg.max() if objective == "worst" else np.cumsum(seg)[-1])


@dataclass
class Selection:
    """Keys from one solve, the uniform keys of the same count, and the cost-versus-K curve."""

    keys: I64
    cost: float  # Σ (total) or max (worst) of the table over the key segments; tau not included
    objective: str
    mode: str
    uniform_keys: I64
    uniform_cost: float
    curve: F64  # (m, 2): rows (K, optimal cost with K keys) for K = 2..
    params: dict = field(default_factory=dict)

    @property
    def n_keys(self) -> int:
        return int(self.keys.size)

    def to_dict(self) -> dict:
        pins, excludes = self.params.get("pins", ()), self.params.get("excludes", ())
        return {
            "keys": self.keys.tolist(),
            "cost": self.cost,
            "objective": self.objective,
            "mode": self.mode,
            "uniform": {"keys": self.uniform_keys.tolist(), "cost": self.uniform_cost}
            | uniform_constraints(pins, excludes),
            "curve": [[int(k), float(c)] for k, c in self.curve],
            "params": self.params,
        }


def uniform_constraints(pins: ArrayLike, excludes: ArrayLike) -> dict:
    """What the uniform baseline does not honour, for its record: ``{}`` without constraints,
    else the counts it ignores and a note. The baseline stays the papers' (evenly spread keys),
    so under pins a DP cost above it compares two different problems, not a worse solve.

    Parameters
    ----------
    pins : array_like
        Pinned frames.
    excludes : array_like
        Excluded frames.

    Returns
    -------
    dict
        What the baseline ignores.
    """
    n_pins, n_excl = len(pins), len(excludes)
    if not (n_pins or n_excl):
        return {}
    pins_s = f"{n_pins} pin{'' if n_pins == 1 else 's'}"
    excl_s = f"{n_excl} exclusion{'' if n_excl == 1 else 's'}"
    return {
        "ignores": {"pins": n_pins, "excludes": n_excl},
        "note": f"the DP keys honour {pins_s} and {excl_s}, the uniform keys do not",
    }


def check_table(table: ArrayLike) -> F64:
    """``table`` as float64, or a ParameterError: not square, fewer than 2 frames, or a
    non-finite cost above the diagonal.

    Parameters
    ----------
    table : array_like
        ``(n, n)`` segment costs.

    Returns
    -------
    ndarray
        ``(n, n)`` float64.
    """
    c = np.asarray(table, dtype=np.float64)
    if c.ndim != 2 or c.shape[0] != c.shape[1]:
        raise ParameterError("table", f"shape {c.shape}", "a square (n, n) segment cost table")
    if c.shape[0] < 2:
        raise ParameterError("frames", c.shape[0], "at least 2 frames")
    upper = c[np.triu_indices(c.shape[0], 1)]
    if not np.all(np.isfinite(upper)):
        raise ParameterError("table", "non-finite segment costs", "finite numbers")
    return c


def solve_layers(
    table: ArrayLike,
    kmax: int,
    objective: str = "total",
    stop: float = -np.inf,
    use_numba: bool = True,
    constraints: KeyConstraints | None = None,
    progress: Callable[[float], None] | None = None,
):
    """Layered DP: ``(E (kmax+1, n), back, last K computed)``; E[K, n−1] is the curve (+inf for
    a count no key set under the constraints reaches). ``progress(share)`` after each block of
    layers, for a long animation's progress bar.

    Parameters
    ----------
    table : array_like
        ``(n, n)`` segment costs.
    kmax : int
        The most keys.
    objective : {"total", "worst"}, default "total"
        Sum or maximum.
    stop : float, default -inf
        Stop once a layer's best error is at most this.
    use_numba : bool, default True
        False runs the numpy twin.
    constraints : KeyConstraints, optional
        Pinned and excluded frames.
    progress : callable, optional
        ``progress(share)``.

    Returns
    -------
    tuple
        ``(E, back, last K computed)``.
    """
    c = check_table(table)
    if constraints:
        c = constraints.apply(c)
    return _layers(c, kmax, objective, stop, use_numba, progress)


def _layers(c: F64, kmax: int, objective: str, stop: float, use_numba: bool, progress=None):
    kmax = int(min(kmax, c.shape[0]))
    use_max = objective == "worst"
    if not use_numba:
        return layers_reference(c, kmax, use_max, float(stop))
    return _layers_in_blocks(np.ascontiguousarray(c.T), kmax, use_max, float(stop), progress)


def select_keys(
    table: ArrayLike,
    *,
    keys: int | None = None,
    penalty: float | None = None,
    budget: float | None = None,
    max_error: float | None = None,
    objective: str = "total",
    curve_keys: int = DEFAULT_CURVE_KEYS,
    constraints: KeyConstraints | None = None,
    use_numba: bool = True,
    progress: Callable[[float], None] | None = None,
) -> Selection:
    """Exact keys for one of: ``keys`` = K, ``penalty`` = tau per key, ``budget`` on the total
    error (fewest keys), ``max_error`` on the worst frame (fewest keys). ``max_error`` implies
    the worst-frame objective (then the table must hold each segment's worst frame cost, as
    ``cost_table(..., objective="worst")`` builds it); the others sum the table's entries.
    ``curve_keys``: the curve covers K = 2..min(n, curve_keys) (and at least the chosen K), the
    counts no key set under the constraints reaches left out. ``constraints``: pinned frames are
    keys and excluded frames are not, in an exact optimum (:mod:`hairtool.keys.constraints`).
    ``progress(share)`` after each block of the DP's layers.

    Parameters
    ----------
    table : array_like
        ``(n, n)`` segment costs (:func:`~hairtool.keys.costs.cost_table`).
    keys, penalty, budget, max_error : optional
        Exactly one: the key count K, the price tau per key, the total error allowed, or the
        worst frame's error allowed.
    objective : {"total", "worst"}, default "total"
        What the table's entries are.
    curve_keys : int, default DEFAULT_CURVE_KEYS
        The error curve covers K = 2 … this.
    constraints : KeyConstraints, optional
        Pinned and excluded frames.
    use_numba : bool, default True
        False runs the numpy twin.
    progress : callable, optional
        ``progress(share)`` with share in [0, 1].

    Returns
    -------
    Selection
        The keys, their cost, uniform keys of the same count and theirs, and the error curve.
    """
    c = check_table(table)
    n = c.shape[0]
    cons = (constraints or KeyConstraints()).check(n)
    lo_k, hi_k = cons.key_range(n)
    given = {
        k: v
        for k, v in dict(keys=keys, penalty=penalty, budget=budget, max_error=max_error).items()
        if v is not None
    }
    if len(given) != 1:
        raise ParameterError("mode", sorted(given), "exactly one of keys, penalty, budget, max_error")
    ((mode, value),) = given.items()
    if objective not in ("total", "worst"):
        raise ParameterError("objective", objective, "total or worst")
    if mode == "max_error":
        objective = "worst"
    if mode == "budget" and objective != "total":
        raise ParameterError("budget", value, "a total-error objective (use max_error for the worst frame)")
    if mode == "penalty" and objective != "total":
        raise ParameterError("penalty", value, "a total-error objective")
    if mode == "keys":
        if not np.isfinite(value) or int(value) != value or not lo_k <= value <= hi_k:
            why = "" if (lo_k, hi_k) == (2, n) else " with these pins and exclusions"
            counts = f"{lo_k}, the only count" if lo_k == hi_k else f"a whole number in [{lo_k}, {hi_k}]"
            raise ParameterError("keys", value, f"{counts}{why}")
    elif not np.isfinite(value) or value < 0:
        raise ParameterError(mode, value, "a finite number >= 0")
    elif mode == "penalty" and not np.isfinite(float(value) * 2.0 * n):
        # n keys' prices and the errors beside them must sum to a number: past that every
        # choice costs inf, no comparison decides, and the search runs without end
        raise ParameterError("penalty", value, f"a price at most {np.finfo(np.float64).max / (2.0 * n):.3g}")
    if not np.isfinite(curve_keys) or int(curve_keys) != curve_keys or curve_keys < 0:
        raise ParameterError("curve_keys", curve_keys, "a whole number >= 0 (0: no curve)")

    dp_table = cons.apply(c)
    kmax = max(2, min(n, int(curve_keys)))
    if mode == "keys":
        kmax = max(kmax, int(value))
    if mode == "penalty":
        _, pb = (
            _penalty_kernel(np.ascontiguousarray(dp_table.T), float(value))
            if use_numba
            else penalty_reference(dp_table, float(value))
        )
        chosen = _trace(lambda _, j: pb[j], n)
        if curve_keys > 0:
            kmax = max(kmax, chosen.size)
    stop = value if mode in ("budget", "max_error") else -np.inf
    layers = n if mode in ("budget", "max_error") else kmax
    e, back, last = _layers(dp_table, layers, objective, stop, use_numba, progress)
    if mode in ("budget", "max_error"):
        if e[last, n - 1] > value:  # only under constraints: unconstrained, n keys cost 0
            best = float(np.min(e[1:, n - 1]))
            raise ParameterError(mode, value, f"a bound these pins and exclusions can meet (>= {best:.6g})")
        if last < kmax:  # extend the curve to the usual length for the slider
            e, back, _ = _layers(dp_table, kmax, objective, -np.inf, use_numba)
        k_best = last
    elif mode == "keys":
        k_best = int(value)
    else:
        k_best = chosen.size
    if mode != "penalty":
        chosen = _trace(lambda depth, j: back[k_best - depth + 1, j], n)
    top = max(last, kmax) if mode in ("budget", "max_error") else kmax
    ks = np.arange(2, min(top, e.shape[0] - 1) + 1)
    ks = ks[np.isfinite(e[ks, n - 1])]  # counts the constraints cannot reach
    curve = np.column_stack([ks, e[ks, n - 1]]) if ks.size else np.zeros((0, 2))
    uni = uniform_keys(n, chosen.size)
    return Selection(
        keys=chosen,
        cost=keys_cost(c, chosen, objective),
        objective=objective,
        mode=mode,
        uniform_keys=uni,
        uniform_cost=keys_cost(c, uni, objective),
        curve=curve,
        params={mode: value, "objective": objective, **(cons.to_dict() if cons else {})},
    )


def brute_force_keys(table: ArrayLike, k: int, objective: str = "total") -> tuple[float, I64]:
    """Best cost and keys over all C(n−2, K−2) key sets (the exactness oracle for small n).

    Parameters
    ----------
    table : array_like
        ``(n, n)`` segment costs.
    k : int
        Keys.
    objective : {"total", "worst"}, default "total"
        Sum or maximum.

    Returns
    -------
    tuple of (float, ndarray)
        The best cost and its keys.
    """
    from itertools import combinations

    c = check_table(table)
    n = c.shape[0]
    best, best_keys = np.inf, None
    for inner in combinations(range(1, n - 1), k - 2):
        keys = np.array((0, *inner, n - 1))
        v = keys_cost(c, keys, objective)
        if v < best:
            best, best_keys = v, keys
    return best, best_keys
