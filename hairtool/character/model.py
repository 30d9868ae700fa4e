"""A character as hairtool holds it: a node tree, skinned meshes, hair chains and their springs.

Quaternions are ``(w, x, y, z)`` as in :mod:`hairtool.mocap.quaternion`; glTF's ``(x, y, z, w)``
is converted where files are read and written. Lengths are the file's (glTF: metres, +Y up).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from hairtool.mocap import quaternion as quat

F64 = NDArray[np.float64]
I64 = NDArray[np.int64]


def trs_matrices(translation: F64, rotation: F64, scale: F64) -> F64:
    """``(..., 4, 4)`` T·R·S local matrices from ``(..., 3)``, wxyz ``(..., 4)``, ``(..., 3)``.

    Parameters
    ----------
    translation : ndarray
        ``(..., 3)``.
    rotation : ndarray
        ``(..., 4)`` wxyz unit quaternions.
    scale : ndarray
        ``(..., 3)``.

    Returns
    -------
    ndarray
        ``(..., 4, 4)`` float64.
    """
    m = np.zeros((*translation.shape[:-1], 4, 4))
    m[..., :3, :3] = quat.to_matrix(rotation) * scale[..., None, :]
    m[..., :3, 3] = translation
    m[..., 3, 3] = 1.0
    return m


@dataclass(frozen=True)
class Nodes:
    """The node tree in rest pose: names, parents (−1 for roots) and local T, R (wxyz), S."""

    names: tuple[str, ...]
    parents: I64  # (J,)
    translation: F64  # (J, 3)
    rotation: F64  # (J, 4) wxyz
    scale: F64  # (J, 3)
    order: I64  # (J,) an order in which every parent comes before its children

    @property
    def count(self) -> int:
        return len(self.names)

    def children(self, j: int) -> list[int]:
        """The nodes whose parent is ``j``, in order.

        Parameters
        ----------
        j : int
            A node's index.

        Returns
        -------
        list of int
            Its children's indices.
        """
        return [int(c) for c in np.flatnonzero(self.parents == j)]

    def world(self, rotation: F64 | None = None, root: F64 | None = None) -> F64:
        """``(..., J, 4, 4)`` world matrices for local rotations ``(..., J, 4)`` (default the rest pose).

        ``root`` ``(..., 4, 4)``: a transform applied above every root node (a head turn on the
        whole character is better given as a rotation of its head node).

        Parameters
        ----------
        rotation : ndarray, optional
            ``(..., J, 4)`` local rotations (None: the rest pose).
        root : ndarray, optional
            ``(..., 4, 4)`` a transform above every root node.

        Returns
        -------
        ndarray
            ``(..., J, 4, 4)`` float64 world matrices.
        """
        r = self.rotation if rotation is None else rotation
        lead = r.shape[:-2]
        t = np.broadcast_to(self.translation, (*lead, self.count, 3))
        s = np.broadcast_to(self.scale, (*lead, self.count, 3))
        local = trs_matrices(t, r, s)
        out = np.empty_like(local)
        for j in self.order.tolist():
            p = int(self.parents[j])
            if p >= 0:
                out[..., j, :, :] = out[..., p, :, :] @ local[..., j, :, :]
            elif root is not None:
                out[..., j, :, :] = root @ local[..., j, :, :]
            else:
                out[..., j, :, :] = local[..., j, :, :]
        return out


@dataclass(frozen=True)
class SkinnedMesh:
    """One primitive: triangles skinned to a skin's joints (node ids), with its base colour."""

    name: str
    positions: F64  # (V, 3) in the mesh node's space at bind time
    normals: F64 | None  # (V, 3)
    triangles: I64  # (T, 3)
    joints: I64  # (V, 4) node ids (already mapped through the skin's joint list)
    weights: F64  # (V, 4), rows sum to 1
    inverse_bind: F64  # (V-independent) (J_skin, 4, 4) per skin joint
    skin_joints: I64  # (J_skin,) node ids
    joint_slots: I64  # (V, 4) indices into skin_joints
    base_color: tuple[float, float, float, float]


@dataclass(frozen=True)
class Collider:
    """A sphere (``tail`` None) or capsule on a node, in that node's space; radius in metres."""

    node: int
    offset: F64
    radius: float
    tail: F64 | None = None


@dataclass(frozen=True)
class Joint:
    """One joint's spring settings (VRM SpringBone), as the file declares them."""

    stiffness: float = 1.0
    gravity_power: float = 0.0
    gravity_dir: tuple[float, float, float] = (0.0, -1.0, 0.0)
    drag: float = 0.5
    hit_radius: float = 0.0


@dataclass(frozen=True)
class Chain:
    """A hair chain root → tip (node ids); ``settings`` one per node (the tip's unused in 1.0)."""

    name: str
    nodes: tuple[int, ...]
    settings: tuple[Joint, ...]
    colliders: tuple[int, ...] = ()  # indices into Character.colliders
    center: int = -1  # a node whose space the tails live in, −1 for world
    virtual_tail: bool = False  # VRM 0.x: a 7 cm tail past the last node, along its parent's direction


def cubic_spline(times: F64, values: F64, tangent_in: F64, tangent_out: F64, i: int, t: float) -> F64:
    """glTF's CUBICSPLINE between keys ``i`` and ``i + 1`` at time ``t``: a cubic Hermite whose
    tangents (per second) are scaled by the key interval, the rotation normalised after.

    Parameters
    ----------
    times : ndarray
        ``(K,)`` key times in seconds.
    values : ndarray
        ``(K, 4)`` key rotations.
    tangent_in, tangent_out : ndarray
        ``(K, 4)`` per-second tangents.
    i : int
        The segment's first key.
    t : float
        The time, within the segment.

    Returns
    -------
    ndarray
        ``(4,)`` float64 unit quaternion.
    """
    span = times[i + 1] - times[i]
    u = (t - times[i]) / span
    u2, u3 = u * u, u * u * u
    p = (2 * u3 - 3 * u2 + 1) * values[i] + span * (u3 - 2 * u2 + u) * tangent_out[i]
    p = p + (-2 * u3 + 3 * u2) * values[i + 1] + span * (u3 - u2) * tangent_in[i + 1]
    return quat.normalize(p)


def key_rate(times: F64, *, fallback: float = 24.0, highest: float = 1000.0) -> float:
    """The lowest frame rate (up to ``highest``) on whose frames every key time lies.

    Key times are frame / fps stored as float32, so the rate of the closest keys is not enough:
    optimal keys three frames apart would be read at a third of the rate. The first whole
    divisor ``n`` of the closest gap ``g`` that makes every gap a whole number of frames of
    ``n / g`` gives the frames (a gcd of the gaps, within float32's error: each time may be off
    by an ulp, so the gaps and ``n / g`` are too); the rate is then fitted to all keys at once,
    and one within 0.1 % of a whole number is that number. ``fallback`` when fewer than two
    distinct times say anything.
    """
    t = np.unique(np.asarray(times, dtype=np.float64))
    if len(t) < 2 or not np.all(np.isfinite(t)):
        return fallback
    gaps = np.diff(t)
    gap = float(np.min(gaps))
    ulp = 2.0 * float(np.finfo(np.float32).eps) * float(np.max(np.abs(t)))  # a time's float32 error
    frames = np.round(gaps / gap)
    for n in range(1, max(1, int(gap * highest)) + 1):
        rate = n / gap
        tolerance = 1e-3 + 2.0 * ulp * rate * (1.0 + gaps / gap)
        if np.all(np.abs(gaps * rate - np.round(gaps * rate)) <= tolerance):
            frames = np.round(gaps * rate)
            break
    k = np.concatenate([[0.0], np.cumsum(frames)])
    d = t - t[0]
    rate = float(np.dot(k, k) / np.dot(k, d))  # least squares over every key
    whole = round(rate)
    return float(whole) if whole > 0 and abs(rate - whole) <= 1e-3 * rate else rate


@dataclass(frozen=True)
class Clip:
    """An animation in the file: per node, rotation keys (wxyz) on its own times."""

    name: str
    rotations: dict[int, tuple[F64, F64]] = field(default_factory=dict)  # node → (times, (K, 4))
    step: frozenset[int] = frozenset()  # nodes whose keys hold (STEP) instead of slerping
    # CUBICSPLINE nodes → (in-tangents, out-tangents) ``(K, 4)`` wxyz, per second
    cubic: dict[int, tuple[F64, F64]] = field(default_factory=dict)
    fps: float | None = None  # the rate the file declares (our exports write it), None if it does not

    @property
    def duration(self) -> float:
        return max((float(t[-1]) for t, _ in self.rotations.values()), default=0.0)

    def frame_rate(self) -> float:
        """The clip's frame rate: the one the file declares (``extras.fps``), else :func:`key_rate`
        of all its key times."""
        if self.fps is not None:
            return self.fps
        return key_rate(np.concatenate([t for t, _ in self.rotations.values()] or [np.zeros(0)]))

    def sample(self, nodes: Nodes, t: float) -> F64:
        """``(J, 4)`` local rotations at time ``t`` (seconds): keys held, slerped or on their cubic
        spline (normalised after, as glTF asks), rest where none.

        Parameters
        ----------
        nodes : Nodes
            The character's nodes.
        t : float
            Seconds.

        Returns
        -------
        ndarray
            ``(J, 4)`` float64.
        """
        r = nodes.rotation.copy()
        for j, (times, q) in self.rotations.items():
            if t <= times[0] or t >= times[-1]:
                end = q[0] if t <= times[0] else q[-1]
                r[j] = quat.normalize(end) if j in self.cubic else end
            else:
                i = int(np.searchsorted(times, t, side="right")) - 1
                if j in self.step:
                    r[j] = q[i]
                elif j in self.cubic:
                    r[j] = cubic_spline(times, q, *self.cubic[j], i, t)
                else:
                    u = (t - times[i]) / (times[i + 1] - times[i])
                    r[j] = quat.slerp(q[i], q[i + 1], u)
        return r

    def frames(self, nodes: Nodes, fps: float) -> F64:
        """``(F, J, 4)`` the clip sampled at every frame from 0 to its duration.

        Parameters
        ----------
        nodes : Nodes
            The character's nodes.
        fps : float
            Frames per second.

        Returns
        -------
        ndarray
            ``(F, J, 4)`` float64.
        """
        n = round(self.duration * fps) + 1
        return np.stack([self.sample(nodes, f / fps) for f in range(n)])


@dataclass(frozen=True)
class Character:
    """Everything hairtool reads from a character file."""

    path: str
    nodes: Nodes
    meshes: tuple[SkinnedMesh, ...]
    chains: tuple[Chain, ...]
    colliders: tuple[Collider, ...]
    clips: tuple[Clip, ...]
    vrm_version: str  # "1.0", "0.x" or "" for plain glTF
