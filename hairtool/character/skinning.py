"""Linear blend skinning: each vertex moved by the weighted sum of its joints' skin matrices.

A skin matrix is the joint's posed world matrix times its inverse bind matrix, so the rest pose
gives back the bind positions. :func:`skin_reference` is the numpy twin of the kernel.
"""

from __future__ import annotations

import numpy as np
from numba import njit
from numpy.typing import NDArray

from hairtool.character.model import SkinnedMesh

F64 = NDArray[np.float64]


def skin_matrices(mesh: SkinnedMesh, world: F64) -> F64:
    """``(J_skin, 4, 4)`` world[joint] · inverse bind, for ``world`` ``(J, 4, 4)`` of its nodes.

    Parameters
    ----------
    mesh : SkinnedMesh
        The mesh.
    world : ndarray
        ``(J, 4, 4)`` its nodes' world matrices.

    Returns
    -------
    ndarray
        ``(J_skin, 4, 4)`` float64.
    """
    return world[mesh.skin_joints] @ mesh.inverse_bind


def skin_reference(positions: F64, slots: NDArray[np.int64], weights: F64, matrices: F64) -> F64:
    """``(V, 3)`` Σ_k w_k · M[slot_k] · (p, 1), in numpy (the oracle of :func:`skin_kernel`).

    Parameters
    ----------
    positions : ndarray
        ``(V, 3)`` rest positions.
    slots : ndarray
        ``(V, K)`` joint slots.
    weights : ndarray
        ``(V, K)`` their weights.
    matrices : ndarray
        ``(J_skin, 4, 4)`` skin matrices.

    Returns
    -------
    ndarray
        ``(V, 3)`` float64.
    """
    m = np.einsum("vk,vkij->vij", weights, matrices[slots])
    return np.einsum("vij,vj->vi", m[:, :3, :3], positions) + m[:, :3, 3]


@njit(cache=True, nogil=True)
def skin_kernel(positions, slots, weights, matrices, out):  # pragma: no cover - numba
    for v in range(positions.shape[0]):
        x, y, z = positions[v, 0], positions[v, 1], positions[v, 2]
        for c in range(3):
            acc = 0.0
            for k in range(4):
                w = weights[v, k]
                if w != 0.0:
                    m = matrices[slots[v, k]]
                    acc += w * (m[c, 0] * x + m[c, 1] * y + m[c, 2] * z + m[c, 3])
            out[v, c] = acc


def skin(mesh: SkinnedMesh, world: F64, *, use_numba: bool = True) -> F64:
    """``(V, 3)`` float64 posed vertex positions of ``mesh`` for node world matrices ``world``.

    Parameters
    ----------
    mesh : SkinnedMesh
        The mesh.
    world : ndarray
        ``(J, 4, 4)`` its nodes' world matrices.
    use_numba : bool, default True
        False runs the numpy twin.

    Returns
    -------
    ndarray
        ``(V, 3)`` float64.
    """
    matrices = np.ascontiguousarray(skin_matrices(mesh, world), dtype=np.float64)
    if not use_numba:
        return skin_reference(mesh.positions, mesh.joint_slots, mesh.weights, matrices)
    out = np.empty((len(mesh.positions), 3))
    skin_kernel(
        np.ascontiguousarray(mesh.positions),
        np.ascontiguousarray(mesh.joint_slots),
        np.ascontiguousarray(mesh.weights),
        matrices,
        out,
    )
    return out
