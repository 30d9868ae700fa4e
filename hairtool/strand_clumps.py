"""Strand clumps: the default clump radius and clump membership (for "colour by clump").

The clump radius h defaults to 2× the median distance between neighbouring roots; clumps are
the connected components of strands linked by vertex pairs closer than h.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from hairtool.groom import Groom
from hairtool.spatial import neighbour_list, pairs_within_reference


def median_root_spacing(groom: Groom) -> float:
    """Median distance from each root to the nearest distinct root of another strand (0 if none)."""
    roots = groom.roots.astype(np.float64)
    s = len(roots)
    lo, hi = roots.min(axis=0), roots.max(axis=0)
    diag = float(np.linalg.norm(hi - lo))
    if s < 2 or diag == 0.0:
        return 0.0
    r = diag / np.sqrt(s)
    ids = np.arange(s)
    while True:
        i, j = pairs_within_reference(roots, ids, r)
        d = np.linalg.norm(roots[j] - roots[i], axis=1)
        keep = d > 1e-9 * diag
        nearest = np.full(s, np.inf)
        np.minimum.at(nearest, i[keep], d[keep])
        if np.count_nonzero(np.isinf(nearest)) < s // 2 or r > 2 * diag:
            m = float(np.median(nearest))
            return m if np.isfinite(m) else 0.0
        r *= 2.0


def auto_clump_radius(groom: Groom) -> float:
    """The default clump radius h: 2× the median distance between neighbouring roots.

    Falls back to 2× the median rest segment length when the roots give no spacing (one strand,
    or all roots in one place).
    """
    spacing = median_root_spacing(groom)
    if spacing > 0:
        return 2.0 * spacing
    seg = float(np.median(groom.segment_lengths))
    return 2.0 * seg if seg > 0 else 1.0


@njit(cache=True)
def _union_components(strand_sorted, nbr, cnt, strand_count):
    parent = np.arange(strand_count)
    for i in range(cnt.size):
        a = strand_sorted[i]
        for n in range(cnt[i]):
            b = strand_sorted[nbr[i, n]]
            while parent[a] != a:
                parent[a] = parent[parent[a]]
                a = parent[a]
            while parent[b] != b:
                parent[b] = parent[parent[b]]
                b = parent[b]
            if a < b:
                parent[b] = a
            elif b < a:
                parent[a] = b
                a = b
    labels = np.empty(strand_count, np.int64)
    next_id = 0
    ids = np.full(strand_count, -1, np.int64)
    for s in range(strand_count):
        r = s
        while parent[r] != r:
            r = parent[r]
        if ids[r] < 0:
            ids[r] = next_id
            next_id += 1
        labels[s] = ids[r]
    return labels


def strand_components(groom: Groom, radius: float) -> np.ndarray:
    """``(S,)`` clump ids: connected components of strands linked by vertex pairs closer than
    ``radius``, numbered 0, 1, … in order of each component's first strand."""
    nl = neighbour_list(groom.points, groom.topology.strand_index, radius)
    return _union_components(nl.strand, nl.nbr, nl.cnt, groom.strand_count)


def strand_components_reference(groom: Groom, radius: float) -> np.ndarray:
    """Numpy twin of :func:`strand_components` (min-label propagation)."""
    strand = groom.topology.strand_index
    i, j = pairs_within_reference(groom.points, strand, radius)
    a, b = strand[i], strand[j]
    label = np.arange(groom.strand_count)
    while True:
        new = label.copy()
        np.minimum.at(new, a, label[b])
        new = new[new]  # pointer jumping
        if np.array_equal(new, label):
            break
        label = new
    _, ids = np.unique(label, return_inverse=True)
    return ids.astype(np.int64)
