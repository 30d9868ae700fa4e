"""Which guides a child follows, and how much: the k nearest guide roots and their weights,
and the guides chosen from a dense groom by farthest-point sampling of its roots.

Weights (the guides sorted by distance d₁ ≤ … ≤ d_k, and d_{k+1} the next guide's):
wⱼ ∝ (1 − dⱼ/R)² with R = d_{k+1}, normalised to sum 1. A guide's weight falls to 0 just as
it stops being among the k nearest, so children change smoothly across the scalp. With no
(k+1)-th guide R = 2·d_k (the farthest reached); where every dⱼ equals R the weights are
equal. Where fewer than k guides can be reached (a mesh in pieces) the missing ones are the
nearest again, with weight 0.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from hairtool.frozen.root_grid import nearest_roots


def euclidean_nearest(
    guide_roots: np.ndarray, child_roots: np.ndarray, k: int
) -> tuple[np.ndarray, np.ndarray]:
    """``(N, k+1)`` nearest guides of each child root in space and their distances, sorted by
    (distance, guide); −1 / inf past the last guide (looked up through a grid of the guide
    roots, :mod:`hairtool.frozen.root_grid`).

    Parameters
    ----------
    guide_roots : ndarray
        ``(G, 3)``.
    child_roots : ndarray
        ``(N, 3)``.
    k : int
        Guides per child.

    Returns
    -------
    tuple of (ndarray, ndarray)
        ``(N, k+1)`` guides and distances.
    """
    return nearest_roots(guide_roots, child_roots, k + 1)


def euclidean_nearest_reference(
    guide_roots: np.ndarray, child_roots: np.ndarray, k: int
) -> tuple[np.ndarray, np.ndarray]:
    """Numpy twin of :func:`euclidean_nearest`: all distances, then a stable sort.

    Parameters
    ----------
    guide_roots, child_roots, k
        As :func:`euclidean_nearest` takes them.

    Returns
    -------
    tuple of (ndarray, ndarray)
        As :func:`euclidean_nearest` gives them.
    """
    g = np.asarray(guide_roots, np.float64)
    c = np.asarray(child_roots, np.float64)
    d = np.sqrt(((g[None, :, :] - c[:, None, :]) ** 2).sum(axis=2))
    order = np.argsort(d, axis=1, kind="stable")[:, : k + 1]
    dist = np.take_along_axis(d, order, axis=1)
    pad = k + 1 - order.shape[1]
    if pad > 0:
        order = np.pad(order, ((0, 0), (0, pad)), constant_values=-1)
        dist = np.pad(dist, ((0, 0), (0, pad)), constant_values=np.inf)
    return order, dist


def weights(guide_ids: np.ndarray, dist: np.ndarray, k: int) -> tuple[np.ndarray, np.ndarray]:
    """``(N, k)`` guides and float64 weights (sum 1) from the k+1 nearest (see the module).

    Parameters
    ----------
    guide_ids : ndarray
        ``(N, k+1)`` nearest guides.
    dist : ndarray
        ``(N, k+1)`` their distances.
    k : int
        Guides each child blends.

    Returns
    -------
    tuple of (ndarray, ndarray)
        ``(N, k)`` guides and weights.
    """
    d = dist[:, :k]
    r = dist[:, k] if dist.shape[1] > k else np.full(len(d), np.inf)
    reached = np.where(np.isfinite(d), d, 0.0).max(axis=1)
    r = np.where(np.isfinite(r), r, 2.0 * reached)
    with np.errstate(invalid="ignore", divide="ignore"):
        w = np.clip(1.0 - d / r[:, None], 0.0, 1.0) ** 2
    w = np.where(np.isfinite(w), w, 0.0)
    ids = guide_ids[:, :k]
    missing = ids < 0  # fewer than k guides reachable (a mesh in pieces): the nearest, weight 0
    w = np.where(missing, 0.0, w)
    total = w.sum(axis=1, keepdims=True)
    w = np.where(total > 0, w / np.where(total > 0, total, 1.0), np.where(missing, 0.0, 1.0))
    w /= w.sum(axis=1, keepdims=True)
    return np.where(missing, ids[:, :1], ids), w


@njit(cache=True, nogil=True, parallel=True)
def _fps_update(roots, p, mind):
    for s in prange(roots.shape[0]):
        d = (roots[s, 0] - p[0]) ** 2 + (roots[s, 1] - p[1]) ** 2 + (roots[s, 2] - p[2]) ** 2
        if d < mind[s]:
            mind[s] = d


@njit(cache=True, nogil=True)
def _fps_kernel(roots, first, count, out):
    mind = np.full(roots.shape[0], np.inf)
    out[0] = first
    for m in range(1, count):
        _fps_update(roots, roots[out[m - 1]], mind)
        best = 0
        for s in range(1, roots.shape[0]):  # serial argmax: the first of the farthest
            if mind[s] > mind[best]:
                best = s
        out[m] = best


def farthest_point_sampling(roots: np.ndarray, count: int, first: int) -> np.ndarray:
    """``count`` strand indices: ``first``, then each time the root farthest from those chosen
    (ties: the lower index), in the order chosen.

    Parameters
    ----------
    roots : ndarray
        ``(S, 3)``.
    count : int
        Strands to choose.
    first : int
        The first one.

    Returns
    -------
    ndarray
        ``(count,)`` int64.
    """
    out = np.empty(count, np.int64)
    _fps_kernel(np.ascontiguousarray(roots, np.float64), int(first), int(count), out)
    return out


def farthest_point_sampling_reference(roots: np.ndarray, count: int, first: int) -> np.ndarray:
    """Numpy twin of :func:`farthest_point_sampling`.

    Parameters
    ----------
    roots, count, first
        As :func:`farthest_point_sampling` takes them.

    Returns
    -------
    ndarray
        As :func:`farthest_point_sampling` gives it.
    """
    r = np.asarray(roots, np.float64)
    out = [int(first)]
    mind = np.full(len(r), np.inf)
    for _ in range(1, count):
        mind = np.minimum(mind, ((r - r[out[-1]]) ** 2).sum(axis=1))
        out.append(int(np.argmax(mind)))
    return np.array(out, np.int64)
