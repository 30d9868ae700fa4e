"""Render strands rebuilt from the guides' current shapes.

A child of n vertices with guides j₁ … j_k (weights w, j₁ the nearest), root r, length scale s
and local offsets o (per vertex, in frame coordinates t, n, b):

    q₀ = r,  qᵢ = qᵢ₋₁ + ŝᵢ·(s Σⱼ wⱼ |Sⱼᵢ|),  ŝᵢ = Σⱼ wⱼ Sⱼᵢ / |Σⱼ wⱼ Sⱼᵢ|
    yᵢ = qᵢ + F_{j₁ i}ᵀ oᵢ

with Sⱼᵢ guide j's i-th segment at n vertices and F its rotation-minimising frames
(:mod:`hairtool.guides.frames`): the guides' segments blended by weight and laid from the
child's root, each segment as long as the weighted guide segments (so a child is as long as the
guides it follows, times s), and the offsets carried by the nearest guide's frames, so a guide
that turns turns them. A child bound from a dense groom keeps that strand's points x and its
blend at rest y⁰ (float64) and is written x + (y − y⁰): the guides at rest give back x to the
bit, since y then repeats y⁰'s arithmetic exactly. Sums in float64; one thread per child, so
the bytes do not depend on the thread count. :func:`build_points` is the kernel,
:func:`build_points_reference` its numpy twin.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Protocol

import numpy as np
from numba import prange

from hairtool.guides.frames import TINY, guide_tables, guide_tables_reference, resampled, root_tangents
from hairtool.kernel_arrays import readonly
from hairtool.serial_twins import twin_njit

if TYPE_CHECKING:
    from hairtool.groom import Groom


class ChildBinding(Protocol):
    """What building children reads of a :class:`hairtool.guides.binding.ChildBinding` (which
    imports this module, so this one names the interface instead of importing the class)."""

    counts: np.ndarray
    roots: np.ndarray
    guide_ids: np.ndarray
    weights: np.ndarray
    scale: np.ndarray
    local: np.ndarray | None
    exact_points: np.ndarray | None
    exact_blend: np.ndarray | None
    offsets: np.ndarray
    vertex_counts: list[int]
    rest_guides: Groom

    @property
    def child_count(self) -> int: ...
    @property
    def vertex_count(self) -> int: ...
    def rest_tangents(self, n: int) -> np.ndarray: ...
    def check_guides(self, guides: Groom) -> None: ...


class GuideTables:
    """The guides at every child vertex count n: segments, their lengths and frames, rows
    ``base[n] + j·n + i`` (for the kernel); the rest root tangents come from the binding."""

    def __init__(self, guides: Groom, binding: ChildBinding, reference: bool = False) -> None:
        """Tabulate ``guides`` at every vertex count of ``binding``'s children.

        Parameters
        ----------
        guides : Groom
            The guides' current shapes.
        binding : ChildBinding
            The children.
        reference : bool, default False
            Build the tables for the numpy twin.
        """
        counts = list(binding.vertex_counts)
        self.base: dict[int, int] = {}
        rows = 0
        for n in counts:
            self.base[n] = rows
            rows += guides.strand_count * n
        self.counts = np.array(counts, np.int64)
        self.bases = np.array([self.base[n] for n in counts], np.int64)
        self.seg, self.seglen, self.frames = np.empty((rows, 3)), np.empty(rows), np.empty((rows, 9))
        for n in counts:
            span = slice(self.base[n], self.base[n] + guides.strand_count * n)
            # Root normals in the rest guides' scene axes, whatever record the posed guides carry.
            axes = binding.rest_guides.metadata.frame
            if reference:
                self.seg[span], self.seglen[span], self.frames[span] = guide_tables_reference(
                    guides, n, binding.rest_tangents(n), axes
                )
            else:
                out = (self.seg, self.seglen, self.frames)
                guide_tables(guides, n, binding.rest_tangents(n), out, self.base[n], axes)

    def child_base(self, binding: ChildBinding) -> np.ndarray:
        """``(N,)`` the first table row of each child's vertex count.

        Parameters
        ----------
        binding : ChildBinding
            The children.

        Returns
        -------
        ndarray
            ``(N,)`` int64.
        """
        if len(self.bases) == 1:
            return np.full(binding.child_count, self.bases[0], np.int64)
        return self.bases[np.searchsorted(self.counts, binding.counts)]


@twin_njit(nogil=True, parallel=True)
def _children_kernel(
    coff, tbase, roots, gid, w, scale, local, seg, seglen, frm, exact_x, exact_y, moved, out
):
    """Every child into ``out``, or with per-guide ``moved`` flags only those that follow a
    moved guide."""
    k = gid.shape[1]
    exact = exact_x.shape[0] > 0
    offsets = local.shape[0] > 0
    for c in prange(roots.shape[0]):
        if moved.size:
            follows = False
            for m in range(k):
                follows |= moved[gid[c, m]]
            if not follows:
                continue
        # Unsigned rows: numba then adds no wrap-around test for negative indices (8 % here).
        a = np.uint64(coff[c])
        n = np.uint64(coff[c + 1]) - a
        tb = np.uint64(tbase[c])
        qx, qy, qz = float(roots[c, 0]), float(roots[c, 1]), float(roots[c, 2])
        near = tb + np.uint64(gid[c, 0]) * n
        sc = scale[c]
        for i in range(n):
            if i > 0:
                dx = 0.0
                dy = 0.0
                dz = 0.0
                length = 0.0
                for m in range(k):
                    t = tb + np.uint64(gid[c, m]) * n + i
                    wm = w[c, m]
                    dx += wm * seg[t, 0]
                    dy += wm * seg[t, 1]
                    dz += wm * seg[t, 2]
                    length += wm * seglen[t]
                length *= sc
                d = np.sqrt(dx * dx + dy * dy + dz * dz)
                if d > TINY:
                    f = length / d
                    qx += dx * f
                    qy += dy * f
                    qz += dz * f
                else:  # the guides' segments cancel: along the nearest guide
                    qx += frm[near + i, 0] * length
                    qy += frm[near + i, 1] * length
                    qz += frm[near + i, 2] * length
            yx, yy, yz = qx, qy, qz
            v = a + i
            if offsets:
                r = near + i
                o0, o1, o2 = float(local[v, 0]), float(local[v, 1]), float(local[v, 2])
                yx += o0 * frm[r, 0] + o1 * frm[r, 3] + o2 * frm[r, 6]
                yy += o0 * frm[r, 1] + o1 * frm[r, 4] + o2 * frm[r, 7]
                yz += o0 * frm[r, 2] + o1 * frm[r, 5] + o2 * frm[r, 8]
            if exact:
                yx = exact_x[v, 0] + (yx - exact_y[v, 0])
                yy = exact_x[v, 1] + (yy - exact_y[v, 1])
                yz = exact_x[v, 2] + (yz - exact_y[v, 2])
            out[v, 0] = yx
            out[v, 1] = yy
            out[v, 2] = yz


_NONE32 = np.zeros((0, 3), np.float32)  # no offsets / not exact
_NONE64 = np.zeros((0, 3))
_ALL = np.zeros(0, np.bool_)  # no guide flags: every child


def build_points(
    binding: ChildBinding,
    guides: Groom,
    dtype: type = np.float32,
    exact: bool = True,
    out: np.ndarray | None = None,
    moved: np.ndarray | None = None,
) -> np.ndarray:
    """``(V, 3)`` child points from the guides' current shapes (``dtype`` float32, or float64
    for the rest blends the binding keeps); ``exact`` False: y without the dense groom's
    x + (y − y⁰); ``out``: an array to write them into (reused between frames). ``moved``:
    per guide, whether it differs from the guides ``out`` holds the children of (see
    :func:`moved_guides`): then only the children that follow a moved guide are built again,
    the others keep their points in ``out`` (a brush moves a few guides per mouse move).

    Parameters
    ----------
    binding : ChildBinding
        The children.
    guides : Groom
        The guides' current shapes.
    dtype : type, default numpy.float32
        float32, or float64 for the rest blends.
    exact : bool, default True
        Add back a dense groom's own offsets where the binding keeps them.
    out : ndarray, optional
        Where to write.
    moved : ndarray, optional
        ``(G,)`` bool, the guides that moved since ``out`` was built (only their children are
        rebuilt).

    Returns
    -------
    ndarray
        ``(V, 3)``.
    """
    binding.check_guides(guides)
    fresh = out is None or out.shape != (binding.vertex_count, 3) or out.dtype != dtype
    if fresh:
        out = np.empty((binding.vertex_count, 3), dtype)
    flags = _ALL
    if moved is not None and not fresh:
        flags = np.ascontiguousarray(moved, np.bool_)
        if not flags.any():
            return out
    tables = GuideTables(guides, binding)
    tbase = tables.child_base(binding)
    use_exact = exact and binding.exact_points is not None
    _children_kernel(
        binding.offsets, tbase, binding.roots, binding.guide_ids, binding.weights, binding.scale,
        _NONE32 if binding.local is None else binding.local, tables.seg, tables.seglen, tables.frames,
        readonly(binding.exact_points if use_exact else _NONE32),
        binding.exact_blend if use_exact else _NONE64, flags, out,
    )  # fmt: skip
    return out


def moved_guides(guides: Groom, last: np.ndarray) -> np.ndarray:
    """``(G,)`` whether each guide has a point that differs, bit for bit, from ``last`` (the points
    children were last built from; any other shape: every guide moved).

    Parameters
    ----------
    guides : Groom
        The guides now.
    last : ndarray
        The points the children were last built from.

    Returns
    -------
    ndarray
        ``(G,)`` bool.
    """
    points = np.ascontiguousarray(guides.points, np.float32)
    last = np.asarray(last)
    if last.shape != points.shape or last.dtype != np.float32:
        return np.ones(guides.strand_count, np.bool_)
    out = np.empty(guides.strand_count, np.bool_)
    _moved_kernel(points.view(np.uint32), np.ascontiguousarray(last).view(np.uint32), guides.offsets, out)
    return out


@twin_njit(nogil=True, parallel=True)
def _moved_kernel(points, last, offsets, out):
    for g in prange(out.size):
        differs = False
        for v in range(offsets[g], offsets[g + 1]):
            for a in range(3):
                differs |= points[v, a] != last[v, a]
        out[g] = differs


def moved_guides_reference(guides: Groom, last: np.ndarray) -> np.ndarray:
    """Numpy twin of :func:`moved_guides` (for ``last`` of the guides' shape).

    Parameters
    ----------
    guides, last
        As :func:`moved_guides` takes them.

    Returns
    -------
    ndarray
        ``(G,)`` bool.
    """
    differs = (np.asarray(guides.points, np.float32).view(np.uint32) != last.view(np.uint32)).any(axis=1)
    return np.logical_or.reduceat(differs, guides.offsets[:-1])


def build_points_reference(binding: ChildBinding, guides: Groom, chunk: int = 8192) -> np.ndarray:
    """Numpy twin of :func:`build_points`: the blend over whole arrays of children of one
    vertex count (``chunk`` at a time), the root-to-tip sum by ``np.cumsum``.

    Parameters
    ----------
    binding : ChildBinding
        The children.
    guides : Groom
        The guides' current shapes.
    chunk : int, default 8192
        Children blended at once.

    Returns
    -------
    ndarray
        ``(V, 3)`` float32.
    """
    binding.check_guides(guides)
    tables = GuideTables(guides, binding, reference=True)
    out = np.empty((binding.vertex_count, 3), np.float32)
    for n in binding.vertex_counts:
        group = np.flatnonzero(binding.counts == n)
        for ids in np.array_split(group, -(-group.size // chunk)):
            rows = tables.base[n] + binding.guide_ids[ids][:, :, None] * n + np.arange(n)  # (c, k, n)
            w = binding.weights[ids][:, :, None]
            d = (w[..., None] * tables.seg[rows]).sum(axis=1)  # (c, n, 3)
            length = binding.scale[ids][:, None] * (w * tables.seglen[rows]).sum(axis=1)
            norm = np.linalg.norm(d, axis=2)
            fr = tables.frames[rows[:, 0]]  # (c, n, 9): the nearest guide's frames
            ok = norm > TINY
            along = d * (length / np.where(ok, norm, 1.0))[..., None]
            step = np.where(ok[..., None], along, fr[..., :3] * length[..., None])
            step[:, 0] = 0.0
            y = binding.roots[ids][:, None, :] + np.cumsum(step, axis=1)
            vids = (binding.offsets[ids][:, None] + np.arange(n)).reshape(-1)
            if binding.local is not None:
                o = binding.local[vids].astype(np.float64).reshape(-1, n, 3)
                y += o[..., :1] * fr[..., 0:3] + o[..., 1:2] * fr[..., 3:6] + o[..., 2:3] * fr[..., 6:9]
            y = y.reshape(-1, 3)
            if binding.exact_points is not None:
                y = binding.exact_points[vids] + (y - binding.exact_blend[vids])
            out[vids] = y
    return out


def root_tangents_of(guides: Groom, n: int) -> np.ndarray:
    """``(G, 3)`` rest root tangents of the guides at n vertices (for a binding to keep).

    Parameters
    ----------
    guides : Groom
        The guides at rest.
    n : int
        Vertices per guide.

    Returns
    -------
    ndarray
        ``(G, 3)`` float64.
    """
    return root_tangents(resampled(guides, n), n)
