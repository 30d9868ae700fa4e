"""Render hair for guides planted and removed: the children of a binding after the add, delete
and density brushes changed its guides.

A :class:`~hairtool.guides.binding.ChildBinding` is bound to the rest guides; the frozen-hair
pipeline records, for each strand it now has, the rest strand it comes from (its ``origin``,
−1 for a planted one). :func:`follow_guides` gives the binding of the strands as they are now:

- a child whose nearest guide was removed goes with it; a child that keeps its nearest guide
  keeps its root, vertex count, length scale and offsets, and drops the removed guides among
  its k (the others' weights scaled back to sum 1): a child whose guides all remain has its
  weights unchanged and builds to the bytes it had before;
- each planted guide gets as many new children as the binding has per guide (round(N / G),
  at least one), rooted uniformly on a disc around its root (radius half the median spacing of
  the guide roots, on the head's tangent plane there and moved onto the head when there is one)
  and bound to their k nearest guides by root distance; they are the plain blend of their guides
  (no offsets, length scale 1, a dense groom's exact points none), so they depend on nothing
  but the guides' roots and shapes; their vertex count is the children's (where children differ
  in it, or carry their own attributes as a dense groom's do: those of the nearest child kept).
  The draws come from the seed and the planted root's bytes, so the same strokes give the same
  children.

The rest guides of the result are the kept guides' rest strands and the planted guides' shapes
as given (they have no rest: their root frames serve only their own children, which carry no
offsets in them). Everything is numpy over arrays of children: the children themselves are built
by :func:`hairtool.guides.children.build_points` as always.
"""

from __future__ import annotations

import numpy as np

from hairtool.errors import ParameterError
from hairtool.groom import Groom, Topology, vertex_ids_of
from hairtool.guides.binding import ChildBinding
from hairtool.guides.nearest import euclidean_nearest, weights

_SALT = 0xC41D  # the stream of planted children's roots


def guides_now(rest: Groom, current: Groom, origin: np.ndarray) -> Groom:
    """The guides ``current`` with each kept strand's rest shape (``origin[i]`` ≥ 0: strand
    ``origin[i]`` of ``rest``) and each planted strand's (``origin[i]`` < 0) shape in ``current``:
    the rest guides of :func:`follow_guides`' binding, with ``rest``'s metadata holding
    ``current``'s prims.

    Parameters
    ----------
    rest : Groom
        The guides at rest.
    current : Groom
        The guides now, strands kept, removed or planted.
    origin : ndarray
        ``(S,)`` each current strand's rest strand, −1 for a planted one.

    Returns
    -------
    Groom
        The rest guides of the following binding.
    """
    origin = np.asarray(origin, np.int64)
    if origin.shape != (current.strand_count,) or np.any(origin >= rest.strand_count):
        where = f"a rest strand (or −1) for each of {current.strand_count}"
        raise ParameterError("origin", f"{origin.shape} ids", where)
    kept = np.flatnonzero(origin >= 0)
    if np.any(rest.counts[origin[kept]] != current.counts[kept]):
        raise ParameterError("origin", "strands of other vertex counts", "each kept strand's own rest strand")
    mine = vertex_ids_of(current.topology, kept)
    theirs = vertex_ids_of(rest.topology, origin[kept])
    points = np.array(current.points, np.float32)
    points[mine] = rest.points[theirs]
    attrs = {}
    for name, a in current.attributes.items():
        r = rest.attributes.get(name)
        if a is None or r is None or np.shape(r)[1:] != np.shape(a)[1:]:
            attrs[name] = a if r is None else None
            continue
        both = np.array(a, np.float32)
        both[mine] = r[theirs]
        attrs[name] = both
    # rest's record holding the prims as they are now (a prim's strands planted and removed)
    meta = rest.metadata.with_(curves=current.metadata.for_strands(current.strand_count).curves)
    return Groom(points, current.counts.copy(), **attrs, metadata=meta.for_strands(current.strand_count))


def _spacing(roots: np.ndarray) -> float:
    """Median distance of a guide root to its nearest other root (0 for a single guide)."""
    if len(roots) < 2:
        return 0.0
    _, d = euclidean_nearest(roots, roots, 1)
    return float(np.median(d[:, 1]))


def _tangent_basis(n: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    a = np.eye(3)[int(np.argmin(np.abs(n)))]
    u = np.cross(n, a)
    u /= np.linalg.norm(u)
    return u, np.cross(n, u)


def planted_roots(root: np.ndarray, normal: np.ndarray, count: int, radius: float, seed: int) -> np.ndarray:
    """``(count, 3)`` roots uniform on the disc of ``radius`` around ``root`` perpendicular to
    ``normal``, drawn from ``seed`` and the root's bytes.

    Parameters
    ----------
    root : ndarray
        ``(3,)`` the planted guide's root.
    normal : ndarray
        ``(3,)`` the head's normal there.
    count : int
        Roots.
    radius : float
        The disc's radius.
    seed : int
        The draws' seed.

    Returns
    -------
    ndarray
        ``(count, 3)`` float64.
    """
    bits = np.asarray(root, np.float64).view(np.uint32)
    rng = np.random.default_rng([int(seed) & 0xFFFFFFFF, *(int(b) for b in bits), _SALT])
    n = np.asarray(normal, np.float64)
    norm = float(np.linalg.norm(n))
    n = n / norm if norm > 0 else np.array([0.0, 1.0, 0.0])
    u, v = _tangent_basis(n)
    r = radius * np.sqrt(rng.random(count))
    t = 2.0 * np.pi * rng.random(count)
    return np.asarray(root, np.float64) + r[:, None] * (np.cos(t)[:, None] * u + np.sin(t)[:, None] * v)


def follow_guides(
    binding: ChildBinding, guides: Groom, origin: np.ndarray, surface=None, seed: int = 0
) -> ChildBinding:
    """The children of ``binding`` for the strands ``guides`` (their rest shapes, as
    :func:`guides_now` gives them) whose rest strands are ``origin`` (module docstring).
    ``surface``: the head (anything with ``project(points) -> (points, normals)``), or None.

    Parameters
    ----------
    binding : ChildBinding
        The children as they were bound.
    guides : Groom
        The guides now.
    origin : ndarray
        ``(S,)`` each guide's rest strand, −1 for a planted one.
    surface : object, optional
        The head, for the children of planted guides.
    seed : int, default 0
        The planted children's seed.

    Returns
    -------
    ChildBinding
        The children of the guides now.
    """
    origin = np.asarray(origin, np.int64)
    g0 = binding.rest_guides.strand_count
    if origin.shape != (guides.strand_count,) or np.any(origin >= g0):
        raise ParameterError("origin", f"{origin.shape} ids", "a guide of the binding (or −1) per strand")
    now = np.full(g0, -1, np.int64)  # each rest guide's index among the guides now, −1: removed
    kept_guides = np.flatnonzero(origin >= 0)
    now[origin[kept_guides]] = kept_guides
    ids = now[binding.guide_ids]
    stay = np.flatnonzero(ids[:, 0] >= 0)
    ids, w = ids[stay], binding.weights[stay]
    gone = ids < 0
    if gone.any():
        lost = gone.any(axis=1)
        w = w.copy()
        w[gone] = 0.0
        total = w[lost].sum(axis=1, keepdims=True)
        first = np.zeros_like(w[lost])
        first[:, 0] = 1.0  # (no weight left: the nearest alone)
        w[lost] = np.where(total > 0, w[lost] / np.where(total > 0, total, 1.0), first)
        ids = np.where(gone, ids[:, :1], ids)  # (weight 0: the nearest again, as weights() does)
    vids = vertex_ids_of(binding.topology, stay)

    def rows(a):
        return None if a is None else a[vids]

    planted = np.flatnonzero(origin < 0)
    counts, roots, scale = binding.counts[stay], binding.roots[stay], binding.scale[stay]
    local, exact_x, exact_y = rows(binding.local), rows(binding.exact_points), rows(binding.exact_blend)
    own = binding.exact_attributes
    own = None if own is None else {k: rows(v) for k, v in own.items()}
    faces = None if binding.faces is None or len(planted) else binding.faces[stay]
    if len(planted):
        per = max(1, round(binding.child_count / max(g0, 1)))
        radius = 0.5 * _spacing(binding.rest_guides.roots.astype(np.float64))
        at = guides.roots[planted].astype(np.float64)
        # the disc's plane: the head's tangent plane, or without a head across the first segment
        normals = guides.points[guides.offsets[planted] + 1].astype(np.float64) - at
        if surface is not None:  # (one query of the head for all of them: each costs a kernel launch)
            normals = surface.project(at)[1]
        new_roots = np.concatenate(
            [planted_roots(p, n, per, radius, seed) for p, n in zip(at, normals, strict=True)]
        )
        if surface is not None:
            new_roots = surface.project(new_roots)[0]
        k = min(binding.guides_per_child, guides.strand_count)
        new_ids, new_w = weights(*euclidean_nearest(guides.roots.astype(np.float64), new_roots, k), k)
        if k < binding.guides_per_child:  # fewer guides than a child follows: the nearest, weight 0
            pad = binding.guides_per_child - k
            new_ids = np.hstack([new_ids, np.repeat(new_ids[:, :1], pad, axis=1)])
            new_w = np.hstack([new_w, np.zeros((len(new_w), pad))])
        like = None  # the nearest child kept, where children differ in vertex count or attributes
        if len(stay) and (len(binding.vertex_counts) > 1 or own is not None):
            like = euclidean_nearest(roots, new_roots, 1)[0][:, 0]
        n_new = binding.counts[:1].repeat(len(new_roots)) if like is None else counts[like]
        ids = np.vstack([ids, new_ids])
        w = np.vstack([w, new_w])
        counts = np.concatenate([counts, n_new])
        roots = np.vstack([roots, new_roots])
        scale = np.concatenate([scale, np.ones(len(new_roots))])
        nv = int(n_new.sum())
        if local is not None:
            local = np.vstack([local, np.zeros((nv, 3), local.dtype)])
        if exact_x is not None:  # x + (y − 0) is y to the bit: the plain blend
            exact_x = np.vstack([exact_x, np.zeros((nv, 3), exact_x.dtype)])
            exact_y = np.vstack([exact_y, np.zeros((nv, 3), exact_y.dtype)])
        if own is not None and like is not None:
            like_vids = vertex_ids_of(Topology(binding.counts[stay]), like)
            own = {k: None if v is None else np.concatenate([v, v[like_vids]]) for k, v in own.items()}
        elif own is not None:
            own = None
    out = ChildBinding(
        guides, counts.astype(np.int64), roots, ids.astype(np.int64), w, scale, local, faces,
        exact_x, exact_y, binding.frizz,
    )  # fmt: skip
    if binding.frizz_phase is not None and not len(planted):
        out.frizz_phase, out.frizz_turns = binding.frizz_phase[stay], binding.frizz_turns[stay]
    out.exact_attributes = own
    out.hair_prims = binding.hair_prims if out.child_count == binding.child_count else ()
    return out
