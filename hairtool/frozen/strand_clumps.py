"""Strand clumps: the default clump radius and clump membership (for "colour by clump").

The clump radius h defaults to 2× the median distance between neighbouring roots.

Clump membership (:func:`strand_clumps`) is a density-basin clustering of the strands at the
scale h (quick shift on the strand graph): w(s, s') counts the pairs of non-root vertices of
strands s and s' closer than h (each pair both ways), ρ(s) = Σ w(s, ·) is how much adhesion
strand s feels, and every strand points to its *strong* neighbour (w at least
:data:`STRONG_LINK` of its largest w) of highest ρ (ties: the lower index) if that is higher
than itself; a clump is a strand of locally highest ρ with all strands that lead to it.
Connected components of the same graph (:func:`strand_components`) are of no use for this: near
the roots every strand is within h of its neighbours, so on real grooms one component holds
(almost) the whole groom.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from hairtool.frozen.spatial import neighbour_list, pairs_within_reference
from hairtool.groom import Groom


def median_root_spacing(groom: Groom) -> float:
    """Median distance from each root to the nearest distinct root of another strand (0 if none).

    The numba neighbour list over the roots (100,000 children's roots: ~10 ms, where
    :func:`median_root_spacing_reference` takes most of a second, a pause when Clump children
    is switched on); the search radius doubles until most roots have a neighbour.

    Parameters
    ----------
    groom : Groom
        The strands.

    Returns
    -------
    float
        The median spacing, in the groom's units.
    """
    return _median_root_spacing(groom, _nearest_roots)


def median_root_spacing_reference(groom: Groom) -> float:
    """Numpy twin of :func:`median_root_spacing`.

    Parameters
    ----------
    groom : Groom
        The strands.

    Returns
    -------
    float
        As :func:`median_root_spacing` gives it.
    """
    return _median_root_spacing(groom, _nearest_roots_reference)


def _median_root_spacing(groom: Groom, nearest_roots) -> float:
    roots32 = groom.roots
    roots = roots32.astype(np.float64)
    s = len(roots)
    lo, hi = roots.min(axis=0), roots.max(axis=0)
    diag = float(np.linalg.norm(hi - lo))
    if s < 2 or diag == 0.0:
        return 0.0
    r = diag / np.sqrt(s)
    while True:
        nearest = nearest_roots(roots32, r, 1e-9 * diag)
        if np.count_nonzero(np.isinf(nearest)) < s // 2 or r > 2 * diag:
            m = float(np.median(nearest))
            return m if np.isfinite(m) else 0.0
        r *= 2.0


def _nearest_roots_reference(roots32: np.ndarray, r: float, tiny: float) -> np.ndarray:
    """``(S,)`` each root's distance to the nearest other root within ``r`` and beyond ``tiny``
    (inf: none), from the groom's float32 roots ``roots32``, in float64."""
    roots = roots32.astype(np.float64)
    i, j = pairs_within_reference(roots, np.arange(len(roots)), r)
    e = roots[j] - roots[i]
    d = np.sqrt(e[:, 0] * e[:, 0] + e[:, 1] * e[:, 1] + e[:, 2] * e[:, 2])
    keep = d > tiny
    nearest = np.full(len(roots), np.inf)
    np.minimum.at(nearest, i[keep], d[keep])
    return nearest


def _nearest_roots(roots32: np.ndarray, r: float, tiny: float) -> np.ndarray:
    """The list from the float32 roots and read-only arrays, the types the clump's own list is
    built from: its kernels compile once for both (the list sorts float64 copies of the
    coordinates either way, so the distances are the same)."""
    points = np.array(roots32, np.float32)
    ids = np.arange(len(points))
    points.flags.writeable = ids.flags.writeable = False
    nl = neighbour_list(points, ids, r)
    nearest = np.empty(len(points))
    lists = (nl.aflat, nl.aoff, nl.acnt, nl.bflat, nl.bstart)
    _nearest_kernel(nl.x, nl.y, nl.z, nl.order, *lists, tiny, nearest)
    return nearest


@njit(cache=True, nogil=True)
def _nearest_kernel(x, y, z, order, aflat, aoff, acnt, bflat, bstart, tiny, nearest):
    """``nearest[order[k]]``: the distance from sorted position k to its nearest listed
    neighbour beyond ``tiny`` (inf: none)."""
    for k in range(x.size):
        best = np.inf
        for run in range(2):
            lo, hi = (aoff[k], aoff[k] + acnt[k]) if run == 0 else (bstart[k], bstart[k + 1])
            for n in range(lo, hi):
                j = aflat[n] if run == 0 else bflat[n]
                ex, ey, ez = x[j] - x[k], y[j] - y[k], z[j] - z[k]
                d = np.sqrt(ex * ex + ey * ey + ez * ez)
                if tiny < d < best:
                    best = d
        nearest[order[k]] = best


def auto_clump_radius(groom: Groom) -> float:
    """The default clump radius h: 2× the median distance between neighbouring roots.

    Falls back to 2× the median rest segment length when the roots give no spacing (one strand,
    or all roots in one place).

    Parameters
    ----------
    groom : Groom
        The groom whose roots set the spacing.

    Returns
    -------
    float
        The radius h in the groom's units, > 0.
    """
    spacing = median_root_spacing(groom)
    if spacing > 0:
        return 2.0 * spacing
    seg = float(np.median(groom.segment_lengths))
    return 2.0 * seg if seg > 0 else 1.0


@njit(cache=True, nogil=True)
def _union_components(strand_sorted, aflat, aoff, acnt, strand_count):
    # The forward runs hold every pair once: enough for an undirected union.
    parent = np.arange(strand_count)
    for i in range(acnt.size):
        a = strand_sorted[i]
        for n in range(aoff[i], aoff[i] + acnt[i]):
            b = strand_sorted[aflat[n]]
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


STRONG_LINK = 0.5  # a neighbour leads only with at least this share of a strand's strongest link


@njit(cache=True, nogil=True)
def _strand_members(sstrand, strand_count):
    """Sorted positions of each strand's vertices: ``start`` (S+1,), ``members`` (V,)."""
    start = np.zeros(strand_count + 1, np.int64)
    for k in range(sstrand.size):
        start[sstrand[k] + 1] += 1
    for s in range(strand_count):
        start[s + 1] += start[s]
    fill = start[:-1].copy()
    members = np.empty(sstrand.size, np.int64)
    for k in range(sstrand.size):
        members[fill[sstrand[k]]] = k
        fill[sstrand[k]] += 1
    return start, members


@njit(cache=True, nogil=True, inline="always")
def _count_links(flat, a, b, sroot, sstrand, acc, touched, m):
    for n in range(a, b):
        j = flat[n]
        if sroot[j]:
            continue
        s = sstrand[j]
        if acc[s] == 0:
            touched[m] = s
            m += 1
        acc[s] += 1
    return m


@njit(cache=True, nogil=True)
def _basins(sstrand, sroot, lists, strand_count, strong):
    aflat, aoff, acnt, bflat, bstart = lists
    start, members = _strand_members(sstrand, strand_count)
    acc = np.zeros(strand_count, np.int64)
    touched = np.empty(strand_count, np.int64)
    rho = np.zeros(strand_count, np.int64)
    parent = np.arange(strand_count)
    for sweep in range(2):  # 1: ρ of every strand; 2: where each strand leads
        for s in range(strand_count):
            m = 0
            for q in range(start[s], start[s + 1]):
                i = members[q]
                if sroot[i]:
                    continue
                m = _count_links(aflat, aoff[i], aoff[i] + acnt[i], sroot, sstrand, acc, touched, m)
                m = _count_links(bflat, bstart[i], bstart[i + 1], sroot, sstrand, acc, touched, m)
            total = 0
            wmax = 0
            for t in range(m):
                total += acc[touched[t]]
                wmax = max(wmax, acc[touched[t]])
            if sweep == 0:
                rho[s] = total
            else:
                best = s
                for t in range(m):
                    b = touched[t]
                    if acc[b] >= strong * wmax and (rho[b] > rho[best] or (rho[b] == rho[best] and b < best)):
                        best = b
                parent[s] = best
            for t in range(m):
                acc[touched[t]] = 0
    labels = np.empty(strand_count, np.int64)
    ids = np.full(strand_count, -1, np.int64)
    next_id = 0
    for s in range(strand_count):
        r = s
        while parent[r] != r:
            r = parent[r]
        if ids[r] < 0:
            ids[r] = next_id
            next_id += 1
        labels[s] = ids[r]
    return labels


def strand_clumps(groom: Groom, radius: float) -> np.ndarray:
    """``(S,)`` clump of each strand at the scale ``radius`` (see the module doc), numbered
    0, 1, … in order of each clump's first strand. Deterministic (integer counts, index ties).

    Parameters
    ----------
    groom : Groom
        The strands.
    radius : float
        The clump scale, in the groom's units.

    Returns
    -------
    ndarray
        ``(S,)`` clump ids.
    """
    top = groom.topology
    is_root = np.zeros(groom.vertex_count, bool)
    is_root[top.root_indices] = True
    nl = neighbour_list(groom.points, top.strand_index, radius, skip=is_root)
    lists = (nl.aflat, nl.aoff, nl.acnt, nl.bflat, nl.bstart)
    return _basins(nl.strand, nl.skip, lists, groom.strand_count, STRONG_LINK)


def strand_clumps_reference(groom: Groom, radius: float) -> np.ndarray:
    """Numpy twin of :func:`strand_clumps`.

    Parameters
    ----------
    groom : Groom
        The strands.
    radius : float
        The clump scale.

    Returns
    -------
    ndarray
        ``(S,)``, as :func:`strand_clumps` gives it.
    """
    top = groom.topology
    strand, n = top.strand_index, groom.strand_count
    i, j = pairs_within_reference(groom.points, strand, radius)
    moving = top.index_in_strand > 0
    keep = moving[i] & moving[j]
    key, w = np.unique(strand[i[keep]] * n + strand[j[keep]], return_counts=True)
    a, b = key // n, key % n
    rho = np.bincount(a, weights=w, minlength=n).astype(np.int64)
    wmax = np.zeros(n, np.int64)
    np.maximum.at(wmax, a, w)
    strong = w >= STRONG_LINK * wmax[a]
    a, b = a[strong], b[strong]
    # Per strand the candidate of highest ρ, then lowest index; itself if that is not higher.
    first = np.lexsort((b, -rho[b], a))
    a, b = a[first], b[first]
    head = np.r_[True, a[1:] != a[:-1]]
    parent = np.arange(n)
    a, b = a[head], b[head]
    up = (rho[b] > rho[a]) | ((rho[b] == rho[a]) & (b < a))
    parent[a[up]] = b[up]
    while True:
        jumped = parent[parent]
        if np.array_equal(jumped, parent):
            break
        parent = jumped
    _, first_seen, inverse = np.unique(parent, return_index=True, return_inverse=True)
    rank = np.empty(len(first_seen), np.int64)
    rank[np.argsort(first_seen)] = np.arange(len(first_seen))
    return rank[inverse]


def strand_components(groom: Groom, radius: float) -> np.ndarray:
    """``(S,)`` clump ids: connected components of strands linked by vertex pairs closer than
    ``radius``, numbered 0, 1, … in order of each component's first strand.

    Parameters
    ----------
    groom : Groom
        The strands.
    radius : float
        The linking distance, in the groom's units.

    Returns
    -------
    ndarray
        ``(S,)`` component ids.
    """
    nl = neighbour_list(groom.points, groom.topology.strand_index, radius)
    return _union_components(nl.strand, nl.aflat, nl.aoff, nl.acnt, groom.strand_count)


def strand_components_reference(groom: Groom, radius: float) -> np.ndarray:
    """Numpy twin of :func:`strand_components` (min-label propagation).

    Parameters
    ----------
    groom : Groom
        The strands.
    radius : float
        The linking distance.

    Returns
    -------
    ndarray
        ``(S,)``, as :func:`strand_components` gives it.
    """
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
