"""Arc-length resampling: every strand to the same number of evenly spaced points."""

from __future__ import annotations

import numpy as np

from hairtool.errors import ParameterError
from hairtool.groom import Groom


def resample_points(groom: Groom, m: int) -> np.ndarray:
    """``(S, m, 3)`` float64 points at arc-length fractions 0, 1/(m−1), …, 1 of every strand.

    Strands of zero length (all vertices on the root) map to m copies of the root.
    """
    if int(m) != m or m < 2:
        raise ParameterError("samples", m, "a whole number of at least 2")
    m = int(m)
    top = groom.topology
    s_count = top.strand_count
    # One monotone key over the whole groom: strand s occupies [2s, 2s + 1].
    key = 2.0 * top.strand_index + groom.arc_param
    q = np.linspace(0.0, 1.0, m)
    target = (2.0 * np.arange(s_count)[:, None] + q[None, :]).reshape(-1)
    seg = np.searchsorted(key, target, side="right") - 1
    first = np.repeat(top.root_indices, m)
    last = np.repeat(top.tip_indices - 1, m)
    seg = np.clip(seg, first, last)
    k0, k1 = key[seg], key[seg + 1]
    span = k1 - k0
    with np.errstate(invalid="ignore", divide="ignore"):
        frac = np.where(span > 0, (target - k0) / span, 0.0)
    frac = np.clip(frac, 0.0, 1.0)[:, None]
    p = groom.points.astype(np.float64)
    out = p[seg] * (1.0 - frac) + p[seg + 1] * frac
    return out.reshape(s_count, m, 3)


def resample(groom: Groom, m: int) -> Groom:
    """The groom with every strand resampled to ``m`` points by arc length (attributes dropped,
    the scene and prims kept)."""
    pts = resample_points(groom, m)
    return Groom(pts.reshape(-1, 3), np.full(groom.strand_count, m), metadata=groom.metadata)
