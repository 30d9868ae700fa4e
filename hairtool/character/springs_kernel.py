"""The spring-bone step of :mod:`hairtool.character.springs` as a numba kernel.

Its numpy reference is :meth:`hairtool.character.springs.SpringBones.step`, joint by joint with
the same formulas; tests compare the two. The node tree's forward kinematics stays in numpy
(once a step); the kernel runs the joints, root to tip, chain after chain.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from hairtool.character.model import Character


@njit(cache=True, nogil=True, inline="always")
def _qmul(a, b):  # pragma: no cover - numba
    return np.array(
        [
            a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3],
            a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2],
            a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1],
            a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0],
        ]
    )


@njit(cache=True, nogil=True, inline="always")
def _qconj(q):  # pragma: no cover - numba
    return np.array([q[0], -q[1], -q[2], -q[3]])


@njit(cache=True, nogil=True, inline="always")
def _qrot(q, v):  # pragma: no cover - numba
    p = _qmul(_qmul(q, np.array([0.0, v[0], v[1], v[2]])), _qconj(q))
    return p[1:].copy()


@njit(cache=True, nogil=True, inline="always")
def _norm(v):  # pragma: no cover - numba
    return math.sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2])


@njit(cache=True, nogil=True, inline="always")
def _from_to(a, b):  # pragma: no cover - numba
    d = a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
    if d < -1.0 + 1e-12:
        axis = np.array([0.0, a[2], -a[1]])  # a × x
        if _norm(axis) < 1e-6:
            axis = np.array([-a[2], 0.0, a[0]])  # a × y
        axis = axis / _norm(axis)
        return np.array([0.0, axis[0], axis[1], axis[2]])
    q = np.array([1.0 + d, a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]])
    return q / math.sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3])


@njit(cache=True, nogil=True, inline="always")
def _put_at(origin, v, length):  # pragma: no cover - numba
    d = v - origin
    return origin + d / max(_norm(d), 1e-12) * length


@njit(cache=True, nogil=True)
def spring_step_kernel(
    out,
    pos,
    rot,
    stale,
    use_stale,
    node,
    parent,
    child,
    axis,
    length,
    stiffness,
    gravity,
    drag,
    hit,
    tail,
    prev,
    chain_start,
    chain_center,
    col_start,
    col_index,
    col_p,
    col_q,
    col_capsule,
    col_radius,
    rest,
    translation,
    dt,
):  # pragma: no cover - numba
    """One step: ``out`` (local rotations, chain joints at rest on entry), ``pos``/``rot`` (world),
    ``tail``/``prev`` (center space) updated in place."""
    for c in range(chain_start.size - 1):
        center = chain_center[c]
        for k in range(chain_start[c], chain_start[c + 1]):
            j, p = node[k], parent[k]
            parent_rot = rot[p].copy() if p >= 0 else np.array([1.0, 0.0, 0.0, 0.0])
            frame = _qmul(parent_rot, rest[j])
            inertia = (tail[k] - prev[k]) * (1.0 - drag[k])
            stiff = dt * stiffness[k] * _qrot(frame, axis[k])
            ext = dt * gravity[k]
            if center >= 0:
                inv = _qconj(rot[center])
                stiff = _qrot(inv, stiff)
                ext = _qrot(inv, ext)
            nxt = tail[k] + inertia + stiff + ext
            if center >= 0:
                nxt = pos[center] + _qrot(rot[center], nxt)
            bone = length[k]
            if use_stale and child[k] >= 0:
                bone = _norm(pos[j] - stale[child[k]])
            nxt = _put_at(pos[j], nxt, bone)
            for m in range(col_start[c], col_start[c + 1]):
                i = col_index[m]
                a = col_p[i]
                if col_capsule[i]:
                    pq = col_q[i] - a
                    dot = pq[0] * (nxt[0] - a[0]) + pq[1] * (nxt[1] - a[1]) + pq[2] * (nxt[2] - a[2])
                    ll = pq[0] * pq[0] + pq[1] * pq[1] + pq[2] * pq[2]
                    if dot <= 0 or ll == 0:
                        delta = nxt - a
                    elif dot >= ll:
                        delta = nxt - col_q[i]
                    else:
                        delta = nxt - (a + pq * (dot / ll))
                else:
                    delta = nxt - a
                dist = _norm(delta)
                reach = col_radius[i] + hit[k]
                if dist < reach and dist > 0:
                    nxt = _put_at(pos[j], nxt + delta / dist * (reach - dist), bone)
            prev[k] = tail[k]
            if center >= 0:
                tail[k] = _qrot(_qconj(rot[center]), nxt - pos[center])
            else:
                tail[k] = nxt
            to = _qrot(_qconj(frame), nxt - pos[j])
            q = _qmul(rest[j], _from_to(axis[k], to / _norm(to)))
            out[j] = q / math.sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3])
            rot[j] = _qmul(parent_rot, out[j])
            if child[k] >= 0:
                pos[child[k]] = pos[j] + _qrot(rot[j], translation[child[k]])


def collider_arrays(character: Character) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Each chain's colliders: ``col_start (C+1,)``, ``col_index (M,)``, ``capsule (N,)``, ``radius (N,)``.

    Parameters
    ----------
    character : Character
        The character.

    Returns
    -------
    tuple of ndarray
        ``col_start``, ``col_index``, ``capsule`` and ``radius``.
    """
    starts, index = [0], []
    for ch in character.chains:
        index.extend(ch.colliders)
        starts.append(len(index))
    capsule = np.array([c.tail is not None for c in character.colliders], dtype=np.bool_)
    radius = np.array([c.radius for c in character.colliders], dtype=np.float64)
    return np.array(starts, dtype=np.int64), np.array(index, dtype=np.int64), capsule, radius
