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


@dataclass(frozen=True)
class Clip:
    """An animation in the file: per node, rotation keys (wxyz) on its own times."""

    name: str
    rotations: dict[int, tuple[F64, F64]] = field(default_factory=dict)  # node → (times, (K, 4))
    step: frozenset[int] = frozenset()  # nodes whose keys hold (STEP) instead of slerping
    # CUBICSPLINE nodes → (in-tangents, out-tangents) ``(K, 4)`` wxyz, per second
    cubic: dict[int, tuple[F64, F64]] = field(default_factory=dict)

    @property
    def duration(self) -> float:
        return max((float(t[-1]) for t, _ in self.rotations.values()), default=0.0)

    def frame_rate(self) -> float:
        """The rate of the closest keys, snapped to a whole number within 0.1 % (float32 times)."""
        gaps = [np.diff(t) for t, _ in self.rotations.values() if len(t) > 1]
        if not gaps:
            return 24.0
        rate = 1.0 / float(np.min(np.concatenate(gaps)))
        return float(round(rate)) if round(rate) > 0 and abs(rate - round(rate)) <= 1e-3 * rate else rate

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
