"""How close a generated cycle is to reference chains: the paper's two measures (Table 1).

Angular error: at every node, how differently the two chains turn there: each child segment is
seen from its parent's frame (frames carried down each chain from the root without twist) and
the two views are compared (for planar chains, |Δθ_A − Δθ_B|). The first segment's parent is the
fixed world frame, so there the segments' directions are compared directly. Degrees, mean over
nodes.

Position error: the distance between corresponding nodes relative to the reference chain's
length, in %, mean over the non-root nodes (roots are pinned in both). Nothing is aligned or
rescaled first: references are expected in the groom's space.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from hairtool.errors import ParameterError
from hairtool.groom import Animation, Groom
from hairtool.resample import resample_points
from hairtool.rotation import any_perpendicular, normalize

F64 = NDArray[np.float64]


def _angle(u: F64, v: F64) -> F64:
    """Angle between rows of unit-or-zero vectors, radians, stable near 0 and π."""
    return np.arctan2(np.linalg.norm(np.cross(u, v), axis=-1), np.sum(u * v, axis=-1))


def _min_rotation(u: F64, v: F64) -> F64:
    """``(..., 3, 3)`` the least rotation taking unit rows ``u`` onto ``v`` (π about a ⟂ axis if opposed)."""
    axis = np.cross(u, v)
    sin = np.linalg.norm(axis, axis=-1)
    cos = np.sum(u * v, axis=-1)
    flip = (sin < 1e-12) & (cos < 0.0)
    axis = normalize(axis)
    if np.any(flip):
        axis[flip] = any_perpendicular(u[flip])
    theta = np.arctan2(sin, cos)
    k = np.zeros((*axis.shape[:-1], 3, 3))
    k[..., 0, 1], k[..., 0, 2], k[..., 1, 2] = -axis[..., 2], axis[..., 1], -axis[..., 0]
    k[..., 1, 0], k[..., 2, 0], k[..., 2, 1] = axis[..., 2], -axis[..., 1], axis[..., 0]
    s, c = np.sin(theta)[..., None, None], np.cos(theta)[..., None, None]
    return np.eye(3) + s * k + (1.0 - c) * (k @ k)


def _local_children(d: F64, first: F64) -> F64:
    """``(..., N−2, 3)`` each child segment seen from its parent's frame, parallel-transported from the root.

    The frame of segment 0 is the smallest rotation taking ``first`` onto it; each next frame
    turns with the chain (the smallest rotation from parent to child), so no twist is added.
    """
    frame = _min_rotation(first, d[..., 0, :])
    out = np.empty((*d.shape[:-2], d.shape[-2] - 1, 3))
    for j in range(1, d.shape[-2]):
        out[..., j - 1, :] = np.einsum("...ji,...j->...i", frame, d[..., j, :])  # frameᵀ · child
        frame = _min_rotation(d[..., j - 1, :], d[..., j, :]) @ frame
    return out


def node_angle_errors(a: F64, b: F64) -> F64:
    """``(..., N−1)`` radians: per node, how differently chains ``a`` and ``b`` (``(..., N, 3)``) turn.

    Node 0 compares the first segments' directions. Node j ≥ 1 compares the child segment j as
    seen from each chain's own parent frame (frames parallel-transported from the root, both
    starting from ``b``'s first segment), so a rigid turn of the whole chain about its root
    shows at node 0 only, and planar chains give |Δθ_a − Δθ_b| exactly.

    Parameters
    ----------
    a, b : ndarray
        ``(..., N, 3)`` chains.

    Returns
    -------
    ndarray
        ``(..., N−1)`` float64 radians.
    """
    da = normalize(np.diff(np.asarray(a, dtype=np.float64), axis=-2))
    db = normalize(np.diff(np.asarray(b, dtype=np.float64), axis=-2))
    if da.shape != db.shape:
        raise ParameterError("reference", db.shape, f"chains of shape {da.shape}")
    err = np.empty(da.shape[:-1])
    err[..., 0] = _angle(da[..., 0, :], db[..., 0, :])
    if da.shape[-2] > 1:
        ref = db[..., 0, :]
        err[..., 1:] = _angle(_local_children(da, ref), _local_children(db, ref))
    return err


@dataclass(frozen=True)
class ChainErrors:
    """Mean angular error (degrees) and node displacement (% of chain length), overall and per frame."""

    angular_deg: float
    position_pct: float
    per_frame_angular_deg: F64
    per_frame_position_pct: F64

    @property
    def n_frames(self) -> int:
        return int(self.per_frame_angular_deg.size)

    def to_dict(self) -> dict:
        return {
            "angular_error_deg": self.angular_deg,
            "position_error_pct": self.position_pct,
            "frames_compared": self.n_frames,
            "per_frame_angular_error_deg": self.per_frame_angular_deg.tolist(),
            "per_frame_position_error_pct": self.per_frame_position_pct.tolist(),
        }


def chain_errors(generated: F64, reference: F64) -> ChainErrors:
    """Errors of ``generated`` ``(F, S, N, 3)`` chains against ``reference`` of the same shape.

    Means are over nodes and chains (float64), per frame, then over frames.

    Parameters
    ----------
    generated, reference : ndarray
        ``(F, S, N, 3)`` chains.

    Returns
    -------
    ChainErrors
        Mean angular error and node displacement, overall and per frame.
    """
    g = np.asarray(generated, dtype=np.float64)
    r = np.asarray(reference, dtype=np.float64)
    if g.ndim != 4 or g.shape != r.shape or g.shape[-1] != 3 or g.shape[-2] < 2:
        raise ParameterError("reference", r.shape, f"chains of the generated shape {g.shape} (F, S, N≥2, 3)")
    ang = np.degrees(node_angle_errors(g, r)).mean(axis=(1, 2))
    length = np.linalg.norm(np.diff(r, axis=-2), axis=-1).sum(axis=-1)  # (F, S)
    disp = np.linalg.norm(g[..., 1:, :] - r[..., 1:, :], axis=-1).mean(axis=-1)  # (F, S)
    with np.errstate(invalid="ignore", divide="ignore"):
        rel = np.where(length > 0, disp / np.where(length > 0, length, 1.0), 0.0)
    pos = 100.0 * rel.mean(axis=1)
    return ChainErrors(
        angular_deg=float(ang.mean()),
        position_pct=float(pos.mean()),
        per_frame_angular_deg=ang,
        per_frame_position_pct=pos,
    )


def _frames_as_chains(obj: Groom | Animation, m: int | None) -> F64:
    """``(F, S, N, 3)`` float64: a groom is one frame; ``m`` resamples every strand by arc length."""
    pts = obj.points[None] if isinstance(obj, Groom) else obj.frames
    if m is None:
        n = int(obj.counts[0])
        return pts.astype(np.float64).reshape(pts.shape[0], obj.strand_count, n, 3)
    return np.stack([resample_points(Groom(p, obj.topology, metadata=obj.metadata), m) for p in pts])


def compare_cycle(generated: Animation | Groom, reference: Animation | Groom) -> ChainErrors:
    """The paper's errors of a generated cycle against reference chains (a drawn key or a simulation).

    Frames are matched by index over the frames both have; a static reference (a groom or a
    one-frame animation) is compared with every generated frame. Chains are matched strand by
    strand; unless both have the same, uniform vertex count, every chain is first resampled by
    arc length to the largest vertex count (so a hand-drawn chain need not have the same nodes).

    Parameters
    ----------
    generated : Animation or Groom
        The cycle.
    reference : Animation or Groom
        The chains to compare with, the same strands.

    Returns
    -------
    ChainErrors
        The errors.
    """
    if generated.strand_count != reference.strand_count:
        raise ParameterError(
            "reference",
            f"{reference.strand_count} strands",
            f"the generated groom's {generated.strand_count} strands (chains are matched one to one)",
        )
    same = np.array_equal(generated.counts, reference.counts) and np.all(
        generated.counts == generated.counts[0]
    )
    m = None if same else int(max(generated.counts.max(), reference.counts.max()))
    g = _frames_as_chains(generated, m)
    r = _frames_as_chains(reference, m)
    if r.shape[0] == 1:
        r = np.broadcast_to(r, g.shape)
    else:
        n = min(g.shape[0], r.shape[0])
        g, r = g[:n], r[:n]
    return chain_errors(g, r)
