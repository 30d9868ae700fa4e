"""VRM spring bones (``VRMC_springBone`` 1.0, and 0.x bone groups), the physics the cycle is
compared with, as the paper compares its cycle with MikuMikuDance's physics.

Per joint, root to tip, every step of ``dt`` seconds (the specification's update):

    inertia   = (tail − previous tail)·(1 − drag)
    stiffness = dt · parent's world rotation · rest local rotation · bone axis · stiffness
    external  = dt · gravity direction · gravity power
    tail'     = tail + inertia + stiffness + external, put back at the bone's length,
                pushed out of every sphere and capsule collider (collider radius + hit radius)
    rotation  = rest local rotation · the turn from the bone axis to the new tail

Tails live in the space of the chain's ``center`` node (the world without one), so a character
carried by its centre does not drag its hair. VRM 0.x lists every node as a joint: the last one
swings a virtual tail 7 cm along its own bone. Scale on the chains' parents is ignored.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from hairtool.character.model import Character
from hairtool.errors import ParameterError
from hairtool.mocap import quaternion as quat

F64 = NDArray[np.float64]
VIRTUAL_TAIL = 0.07  # metres, VRM 0.x


def forward(character: Character, local: F64) -> tuple[F64, F64]:
    """World positions ``(J, 3)`` and rotations ``(J, 4)`` of local rotations ``(J, 4)`` (no scale).

    Parameters
    ----------
    character : Character
        The character.
    local : ndarray
        ``(J, 4)`` wxyz local rotations.

    Returns
    -------
    tuple of (ndarray, ndarray)
        World positions and rotations.
    """
    nodes = character.nodes
    pos, rot = np.empty((nodes.count, 3)), np.empty((nodes.count, 4))
    for j in nodes.order.tolist():
        p = int(nodes.parents[j])
        if p < 0:
            pos[j], rot[j] = nodes.translation[j], local[j]
        else:
            pos[j] = pos[p] + quat.rotate(rot[p], nodes.translation[j])
            rot[j] = quat.multiply(rot[p], local[j])
    return pos, rot


def from_to(a: F64, b: F64) -> F64:
    """The least rotation (wxyz) taking unit ``a`` onto unit ``b``.

    Parameters
    ----------
    a, b : ndarray
        ``(3,)`` unit vectors.

    Returns
    -------
    ndarray
        ``(4,)`` wxyz.
    """
    d = float(np.dot(a, b))
    if d < -1.0 + 1e-12:
        axis = np.cross(a, [1.0, 0.0, 0.0])
        if np.linalg.norm(axis) < 1e-6:
            axis = np.cross(a, [0.0, 1.0, 0.0])
        return quat.from_axis_angle(axis / np.linalg.norm(axis), np.pi)
    return quat.normalize(np.concatenate([[1.0 + d], np.cross(a, b)]))


@dataclass
class _Joint:
    node: int
    parent: int
    axis: F64  # unit bone axis in the joint's local space
    tail_local: F64  # the tail in the joint's local space
    length: float
    stiffness: float
    gravity: F64  # direction · power
    drag: float
    hit_radius: float
    tail: F64  # current tail, center space
    prev: F64
    child: int  # the next node of the chain, −1 past the last


def _to_center(pos: F64, rot: F64, center: int, v: F64) -> F64:
    return v if center < 0 else quat.rotate(quat.conjugate(rot[center]), v - pos[center])


def _to_world(pos: F64, rot: F64, center: int, v: F64) -> F64:
    return v if center < 0 else pos[center] + quat.rotate(rot[center], v)


def _collide(
    tail: F64, hit: float, colliders: list[tuple[F64, F64 | None, float]], origin: F64, length: float
) -> F64:
    """Push ``tail`` out of each sphere or capsule in turn, back at ``length`` from ``origin`` after each."""
    for p, q, radius in colliders:
        if q is None:
            delta = tail - p
        else:
            pq = q - p
            dot = float(np.dot(pq, tail - p))
            ll = float(np.dot(pq, pq))
            delta = tail - (p if dot <= 0 or ll == 0 else q if dot >= ll else p + pq * (dot / ll))
        dist = float(np.linalg.norm(delta))
        reach = radius + hit
        if dist < reach and dist > 0:
            tail = tail + delta / dist * (reach - dist)
            d = tail - origin
            tail = origin + d / max(float(np.linalg.norm(d)), 1e-12) * length
    return tail


class SpringBones:
    """The spring state of a character's chains; :meth:`step` advances it on a driven pose."""

    def __init__(self, character: Character, local: F64, *, stale_lengths: bool = False) -> None:
        """The character's spring chains at rest on the pose ``local``.

        Parameters
        ----------
        character : Character
            The character.
        local : ndarray
            ``(J, 4)`` the driven pose they start on.
        stale_lengths : bool, default False
            Measure bone lengths as three-vrm 3.x does.
        """
        self.character = character
        self.stale_lengths = stale_lengths
        pos, rot = forward(character, local)
        self.chains: list[tuple[int, list[_Joint]]] = []
        nodes = character.nodes
        for chain in character.chains:
            joints = []
            ids = list(chain.nodes)
            owners = ids if chain.virtual_tail else ids[:-1]
            for k, j in enumerate(owners):
                if k + 1 < len(ids):
                    tail_local = nodes.translation[ids[k + 1]]
                else:  # VRM 0.x's virtual tail, along the last bone
                    t = nodes.translation[j]
                    n = np.linalg.norm(t)
                    tail_local = t / n * VIRTUAL_TAIL if n > 0 else np.array([0.0, VIRTUAL_TAIL, 0.0])
                length = float(np.linalg.norm(tail_local))
                if length == 0:
                    raise ParameterError("chain", chain.name, f"no zero-length bones (node {nodes.names[j]})")
                s = chain.settings[k]
                tail_world = pos[j] + quat.rotate(rot[j], tail_local)
                tail = _to_center(pos, rot, chain.center, tail_world)
                joints.append(
                    _Joint(
                        node=j,
                        parent=int(nodes.parents[j]),
                        axis=tail_local / length,
                        tail_local=tail_local,
                        length=length,
                        stiffness=s.stiffness,
                        gravity=np.asarray(s.gravity_dir, dtype=np.float64) * s.gravity_power,
                        drag=s.drag,
                        hit_radius=s.hit_radius,
                        tail=tail.copy(),
                        prev=tail.copy(),
                        child=ids[k + 1] if k + 1 < len(ids) else -1,
                    )
                )
            self.chains.append((chain.center, joints))
        self.rest = character.nodes.rotation.copy()
        self.last = local.copy()
        for _, joints in self.chains:
            for joint in joints:
                self.last[joint.node] = self.rest[joint.node]

    def _colliders(self, pos: F64, rot: F64, chain_index: int) -> list[tuple[F64, F64 | None, float]]:
        out = []
        for c in self.character.chains[chain_index].colliders:
            col = self.character.colliders[c]
            p = pos[col.node] + quat.rotate(rot[col.node], col.offset)
            q = None if col.tail is None else pos[col.node] + quat.rotate(rot[col.node], col.tail)
            out.append((p, q, col.radius))
        return out

    def step(self, local: F64, dt: float) -> F64:
        """Advance by ``dt`` seconds on the driven pose ``local`` ``(J, 4)``; the posed local rotations.

        Chains are independent: each starts from the driven pose of its parents (a chain hanging
        from another chain's node sees that node at rest).

        Parameters
        ----------
        local : ndarray
            ``(J, 4)`` the driven pose.
        dt : float
            Seconds.

        Returns
        -------
        ndarray
            ``(J, 4)`` float64 posed local rotations.
        """
        out = local.copy()
        for _, joints in self.chains:
            for joint in joints:
                out[joint.node] = self.rest[joint.node]
        pos, rot = forward(self.character, out)
        stale = None
        if self.stale_lengths:
            before = local.copy()
            for _, joints in self.chains:
                for joint in joints:
                    before[joint.node] = self.last[joint.node]
            stale = forward(self.character, before)[0]
        translation = self.character.nodes.translation
        for ci, (center, joints) in enumerate(self.chains):
            colliders = self._colliders(pos, rot, ci)
            to_center = None if center < 0 else quat.conjugate(rot[center])
            for joint in joints:
                j, p = joint.node, joint.parent
                parent_rot = rot[p] if p >= 0 else quat.identity()
                frame = quat.multiply(parent_rot, self.rest[j])
                inertia = (joint.tail - joint.prev) * (1.0 - joint.drag)
                stiff = dt * joint.stiffness * quat.rotate(frame, joint.axis)
                ext = dt * joint.gravity
                if to_center is not None:
                    stiff, ext = quat.rotate(to_center, stiff), quat.rotate(to_center, ext)
                length = joint.length
                if stale is not None and joint.child >= 0:
                    length = float(np.linalg.norm(pos[j] - stale[joint.child]))
                nxt = _to_world(pos, rot, center, joint.tail + inertia + stiff + ext)
                nxt = pos[j] + (nxt - pos[j]) / max(np.linalg.norm(nxt - pos[j]), 1e-12) * length
                nxt = _collide(nxt, joint.hit_radius, colliders, pos[j], length)
                joint.prev = joint.tail
                joint.tail = _to_center(pos, rot, center, nxt)
                to = quat.rotate(quat.conjugate(frame), nxt - pos[j])
                out[j] = quat.normalize(
                    quat.multiply(self.rest[j], from_to(joint.axis, to / np.linalg.norm(to)))
                )
                rot[j] = quat.multiply(parent_rot, out[j])
                if joint.child >= 0:
                    pos[joint.child] = pos[j] + quat.rotate(rot[j], translation[joint.child])
        self.last = out
        return out


class PackedSprings:
    """:class:`SpringBones` as flat arrays, stepped by the numba kernel (same formulas)."""

    def __init__(self, springs: SpringBones) -> None:
        """``springs``' chains, joints and colliders packed into the kernel's arrays.

        Parameters
        ----------
        springs : SpringBones
            The springs, at rest.
        """
        from hairtool.character.springs_kernel import collider_arrays

        self.springs = springs
        joints = [j for _, js in springs.chains for j in js]
        self.node = np.array([j.node for j in joints], dtype=np.int64)
        self.parent = np.array([j.parent for j in joints], dtype=np.int64)
        self.child = np.array([j.child for j in joints], dtype=np.int64)
        self.axis = np.array([j.axis for j in joints]).reshape(-1, 3)
        self.length = np.array([j.length for j in joints], dtype=np.float64)
        self.stiffness = np.array([j.stiffness for j in joints], dtype=np.float64)
        self.gravity = np.array([j.gravity for j in joints]).reshape(-1, 3)
        self.drag = np.array([j.drag for j in joints], dtype=np.float64)
        self.hit = np.array([j.hit_radius for j in joints], dtype=np.float64)
        self.tail = np.array([j.tail for j in joints]).reshape(-1, 3)
        self.prev = np.array([j.prev for j in joints]).reshape(-1, 3)
        self.chain_start = np.cumsum([0] + [len(js) for _, js in springs.chains]).astype(np.int64)
        self.chain_center = np.array([c for c, _ in springs.chains], dtype=np.int64)
        self.col_start, self.col_index, self.col_capsule, self.col_radius = collider_arrays(springs.character)
        cols = springs.character.colliders
        self.col_node = np.array([c.node for c in cols], dtype=np.int64)
        self.col_offset = np.array([c.offset for c in cols], dtype=np.float64).reshape(-1, 3)
        self.col_tail = np.array([c.offset if c.tail is None else c.tail for c in cols]).reshape(-1, 3)

    def step(self, local: F64, dt: float) -> F64:
        """:meth:`SpringBones.step` by the numba kernel.

        Parameters
        ----------
        local : ndarray
            ``(J, 4)`` the driven pose.
        dt : float
            Seconds.

        Returns
        -------
        ndarray
            ``(J, 4)`` float64 posed local rotations.
        """
        from hairtool.character.springs_kernel import spring_step_kernel

        sb = self.springs
        out = np.array(local, dtype=np.float64, copy=True)
        out[self.node] = sb.rest[self.node]
        pos, rot = forward(sb.character, out)
        stale = np.zeros((0, 3))
        if sb.stale_lengths:
            before = np.array(local, dtype=np.float64, copy=True)
            before[self.node] = sb.last[self.node]
            stale = forward(sb.character, before)[0]
        crot = rot[self.col_node]
        col_p = pos[self.col_node] + quat.rotate(crot, self.col_offset)
        col_q = pos[self.col_node] + quat.rotate(crot, self.col_tail)
        spring_step_kernel(
            out,
            pos,
            rot,
            stale,
            sb.stale_lengths,
            self.node,
            self.parent,
            self.child,
            self.axis,
            self.length,
            self.stiffness,
            self.gravity,
            self.drag,
            self.hit,
            self.tail,
            self.prev,
            self.chain_start,
            self.chain_center,
            self.col_start,
            self.col_index,
            col_p.reshape(-1, 3),
            col_q.reshape(-1, 3),
            self.col_capsule,
            self.col_radius,
            sb.rest,
            sb.character.nodes.translation,
            float(dt),
        )
        sb.last = out
        return out


def simulate(
    character: Character,
    driver: F64,
    fps: float,
    substeps: int = 1,
    *,
    stale_lengths: bool = False,
    use_numba: bool = True,
) -> F64:
    """``(F, J, 4)`` local rotations: ``driver`` ``(F, J, 4)`` with the chains swung by their springs.

    The springs start at rest on the driver's first frame and step ``substeps`` times a frame.
    ``stale_lengths`` reproduces three-vrm (3.x), which measures a bone's length to its child's
    world position as it was before this step moved the bone, so its bones stretch and shrink a
    little while the hair moves; the specification keeps them rigid (the default).
    ``use_numba=False`` steps with the numpy reference.

    Parameters
    ----------
    character : Character
        The character.
    driver : ndarray
        ``(F, J, 4)`` the driven local rotations.
    fps : float
        Frames per second.
    substeps : int, default 1
        Spring steps per frame.
    stale_lengths : bool, default False
        Measure bone lengths as three-vrm 3.x does.
    use_numba : bool, default True
        False runs the numpy twin.

    Returns
    -------
    ndarray
        ``(F, J, 4)`` float64.
    """
    if driver.ndim != 3 or driver.shape[1:] != (character.nodes.count, 4):
        raise ParameterError("driver", driver.shape, f"(frames, {character.nodes.count}, 4) rotations")
    if not np.isfinite(fps) or fps <= 0 or int(substeps) != substeps or substeps < 1:
        raise ParameterError("fps", fps, "a positive frame rate and a whole number of substeps ≥ 1")
    springs = SpringBones(character, driver[0], stale_lengths=stale_lengths)
    stepper = PackedSprings(springs) if use_numba else springs
    out = np.empty_like(driver)
    dt = 1.0 / (fps * substeps)
    for f in range(len(driver)):
        for _ in range(int(substeps)):
            out[f] = stepper.step(driver[f], dt)
    return out


def head_shake(
    character: Character,
    frames: int,
    fps: float,
    *,
    turn_deg: float = 30.0,
    period: float = 1.0,
    node: str = "Head",
) -> F64:
    """``(F, J, 4)`` the rest pose, ``node`` turning ±``turn_deg`` about +Y, a shake every ``period`` s.

    Parameters
    ----------
    character : Character
        The character.
    frames : int
        Frames.
    fps : float
        Frames per second.
    turn_deg : float, default 30.0
        The turn's amplitude in degrees.
    period : float, default 1.0
        Seconds per shake.
    node : str, default "Head"
        The node turned.

    Returns
    -------
    ndarray
        ``(F, J, 4)`` float64.
    """
    nodes = character.nodes
    if node not in nodes.names:
        raise ParameterError("node", node, f"a node of {character.path}")
    j = nodes.names.index(node)
    t = np.arange(frames) / fps
    out = np.broadcast_to(nodes.rotation, (frames, nodes.count, 4)).copy()
    turn = quat.from_axis_angle(
        np.array([0.0, 1.0, 0.0]), np.radians(turn_deg) * np.sin(2 * np.pi * t / period)
    )
    out[:, j] = quat.multiply(turn, nodes.rotation[j])
    return out
