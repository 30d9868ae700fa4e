"""Widths, colour and transparency of render hair, from its guides.

A child of n vertices takes, at its vertex i (parameter t = i/(n − 1), root to tip), each of its
k guides' value at the same t (linearly between the guide's own vertices, as its points are
resampled in :func:`hairtool.guides.frames.resampled`), blended by the binding's weights:

    a_ci = Σⱼ wⱼ · A_{gⱼ}(t_i)

so a tapered guide gives tapered children and a blonde-to-brown guide gives blonde-to-brown
children. A child bound from a dense strand keeps that strand's own values. Attributes the
guides do not have stay None here; a writer gives the defaults (80 µm widths, in scene units).
"""

from __future__ import annotations

from typing import Protocol

import numpy as np

from hairtool.groom import Groom, Topology, vertex_ids_of
from hairtool.metadata import ATTRIBUTES


class ChildBinding(Protocol):
    """What blending reads of a :class:`hairtool.guides.binding.ChildBinding` (which imports
    this module, so this one names the interface instead of importing the class)."""

    rest_guides: Groom
    counts: np.ndarray
    guide_ids: np.ndarray
    weights: np.ndarray
    topology: Topology
    vertex_counts: list[int]
    exact_attributes: dict | None

    @property
    def child_count(self) -> int: ...
    @property
    def vertex_count(self) -> int: ...


_CHUNK = 8192  # children blended at a time (bounds the (chunk, k, n, 3) temporary)


def resampled_values(values: np.ndarray, guides: Groom, n: int) -> np.ndarray:
    """``(G, n, …)`` float64: every guide's per-vertex ``values`` at n evenly spaced vertex
    parameters (i/(n − 1) of its vertices, linearly between them).

    Parameters
    ----------
    values : ndarray
        One per guide vertex.
    guides : Groom
        The guides.
    n : int
        Samples per guide.

    Returns
    -------
    ndarray
        ``(G, n, …)`` float64.
    """
    v = np.asarray(values, np.float64)
    out = np.empty((guides.strand_count, n, *v.shape[1:]))
    for m in np.unique(guides.counts):
        ids = np.flatnonzero(guides.counts == m)
        starts = guides.offsets[ids]
        u = np.arange(n) * ((m - 1) / (n - 1))
        i0 = np.minimum(np.floor(u).astype(np.int64), m - 2)
        f = u - i0
        a = v[starts[:, None] + i0]
        b = v[starts[:, None] + i0 + 1]
        if v.ndim > 1:
            f = f[:, None]
        out[ids] = a + f * (b - a)
    return out


def blend(values: np.ndarray, binding: ChildBinding) -> np.ndarray:
    """``(V_children, …)`` float32: the guides' ``values`` (one per rest-guide vertex) at every
    child vertex, blended by the binding's weights.

    Parameters
    ----------
    values : ndarray
        One per rest-guide vertex.
    binding : ChildBinding
        The children.

    Returns
    -------
    ndarray
        ``(V_children, …)`` float32.
    """
    v = np.asarray(values)
    out = np.empty((binding.vertex_count, *v.shape[1:]), np.float64)
    for n in binding.vertex_counts:
        table = resampled_values(v, binding.rest_guides, n)  # (G, n, …)
        group = np.flatnonzero(binding.counts == n)
        for lo in range(0, group.size, _CHUNK):
            ids = group[lo : lo + _CHUNK]
            w = binding.weights[ids]  # (c, k)
            picked = table[binding.guide_ids[ids]]  # (c, k, n, …)
            mixed = np.einsum("ck,ckn...->cn...", w, picked)
            out[vertex_ids_of(binding.topology, ids)] = mixed.reshape(-1, *v.shape[1:])
    return out.astype(np.float32)


def blend_reference(values: np.ndarray, binding: ChildBinding) -> np.ndarray:
    """Child-by-child twin of :func:`blend`, with ``np.interp`` along each guide, for tests.

    Parameters
    ----------
    values : ndarray
        One per rest-guide vertex.
    binding : ChildBinding
        The children.

    Returns
    -------
    ndarray
        As :func:`blend` gives it.
    """
    v = np.asarray(values, np.float64)
    guides = binding.rest_guides
    rows = []
    for c in range(binding.child_count):
        n = int(binding.counts[c])
        t = np.arange(n) / (n - 1)
        acc = np.zeros((n, *v.shape[1:]))
        for g, w in zip(binding.guide_ids[c], binding.weights[c], strict=True):
            seg = v[guides.offsets[g] : guides.offsets[g + 1]].reshape(int(guides.counts[g]), -1)
            tg = np.arange(seg.shape[0]) / (seg.shape[0] - 1)
            col = np.column_stack([np.interp(t, tg, seg[:, j]) for j in range(seg.shape[1])])
            acc += w * col.reshape(acc.shape)
        rows.append(acc)
    return np.concatenate(rows).astype(np.float32)


def child_attributes(binding: ChildBinding) -> dict[str, np.ndarray | None]:
    """Thickness, transparency and colours of every child vertex: a dense strand's own where
    the binding keeps them (``exact_attributes``), else the guides' blended (:func:`blend`);
    None where neither has one.

    Parameters
    ----------
    binding : ChildBinding
        The children.

    Returns
    -------
    dict
        ``thickness``, ``transparency`` and ``colors``, each an array or None.
    """
    own = binding.exact_attributes or {}
    out: dict[str, np.ndarray | None] = {}
    for name in ATTRIBUTES:
        mine = own.get(name)
        guide = getattr(binding.rest_guides, name)
        if mine is not None:
            out[name] = np.asarray(mine, np.float32)
        elif guide is not None:
            out[name] = blend(guide, binding)
        else:
            out[name] = None
    return out
