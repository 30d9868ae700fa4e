"""Seed 003's per-channel keys: every degree of freedom a curve with its own keys and its own
price tau_d per key (``hairtool keys --per-channel``), each channel solved exactly on its own."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from hairtool.errors import ParameterError
from hairtool.keys.costs import INTERPOLATIONS, cost_table
from hairtool.keys.dp import select_keys
from hairtool.keys.features import raw_features

I64 = NDArray[np.int64]


@dataclass
class ChannelKeys:
    """Per-channel keys (seed 003): ``keys[d]`` are channel d's knots, ``costs[d]`` its error."""

    keys: list[I64]
    costs: NDArray[np.float64]
    penalties: NDArray[np.float64]

    @property
    def key_counts(self) -> I64:
        return np.array([k.size for k in self.keys], dtype=np.int64)

    def union(self) -> I64:
        """Frames that are a key of at least one channel."""
        return np.unique(np.concatenate(self.keys))

    def to_dict(self) -> dict:
        return {
            "channels": [k.tolist() for k in self.keys],
            "costs": self.costs.tolist(),
            "penalties": self.penalties.tolist(),
            "union": self.union().tolist(),
        }


def per_channel_keys(
    x: ArrayLike,
    penalty: float | ArrayLike,
    *,
    interp: str = "hermite",
    curvature: float = 0.0,
    relative: bool = False,
) -> ChannelKeys:
    """Every column of ``(n_frames, D)`` features keyed on its own, at its own price tau_d per key
    (with ``relative``, tau_d is a share of that channel's two-key error).

    Parameters
    ----------
    x : array_like
        ``(n_frames, D)`` features, one channel a column.
    penalty : float or array_like
        tau per key: one for every channel, or ``(D,)``.
    interp : {"hermite", "linear", "hermite-fit"}, default "hermite"
        The curve between a channel's keys.
    curvature : float, default 0.0
        Weight of the curvature term in each segment's cost (≥ 0).
    relative : bool, default False
        tau is a share of each channel's two-key error instead of an absolute price.

    Returns
    -------
    ChannelKeys
        Each channel's keys, its error and the price it was keyed at.
    """
    x = raw_features(x)
    d = x.shape[1]
    if interp not in INTERPOLATIONS:
        raise ParameterError("interp", interp, " or ".join(INTERPOLATIONS))
    tau = np.broadcast_to(np.asarray(penalty, dtype=np.float64), (d,)) if np.ndim(penalty) == 0 else None
    if tau is None:
        tau = np.asarray(penalty, dtype=np.float64)
        if tau.shape != (d,):
            raise ParameterError("penalty", f"shape {tau.shape}", f"one number or one per channel ({d},)")
    if not np.all(np.isfinite(tau)) or np.any(tau < 0):
        raise ParameterError("penalty", tau.tolist() if tau.size < 8 else "array", "finite numbers >= 0")
    keys, costs, prices = [], np.zeros(d), np.zeros(d)
    for c in range(d):
        table = cost_table(x[:, c : c + 1], interp, curvature)
        # A constant channel's two-key error is 0 up to rounding, which may leave it a hair below.
        prices[c] = float(tau[c]) * max(float(table[0, -1]), 0.0) if relative else float(tau[c])
        sel = select_keys(table, penalty=prices[c], curve_keys=0)
        keys.append(sel.keys)
        costs[c] = sel.cost
    return ChannelKeys(keys=keys, costs=costs, penalties=prices)
