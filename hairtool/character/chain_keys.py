"""Keys on a character's bones: one key set per hair chain, or one shared by all of them.

Each chain is keyed on its own BVH motion (:func:`hairtool.character.bvh.chains_motion` of that
chain alone: the node it hangs from, then its joints), weighing only the chain's own joints (the
node it hangs from would otherwise outweigh them all, being nearest the root), so a chain that
barely moves spends few keys while a swinging one gets what it needs. Animated nodes outside
every chain (a shaken head) are keyed at every frame some chain keys.
"""

from __future__ import annotations

import dataclasses

import numpy as np
from numpy.typing import NDArray

from hairtool.character.bvh import chains_motion
from hairtool.character.model import Character
from hairtool.mocap.bvh import Motion
from hairtool.mocap.costs import joint_weights

F64 = NDArray[np.float64]
I64 = NDArray[np.int64]


def chain_motion(character: Character, rotations: F64, fps: float, chain: int) -> Motion:
    """The BVH motion of one hair chain of ``rotations`` ``(F, J, 4)``.

    Parameters
    ----------
    character : Character
        The character.
    rotations : ndarray
        ``(F, J, 4)``.
    fps : float
        Frames per second.
    chain : int
        The chain's index.

    Returns
    -------
    Motion
        The chain as a BVH motion.
    """
    alone = dataclasses.replace(character, chains=(character.chains[chain],))
    return chains_motion(alone, rotations, fps)


def node_keys(character: Character, nodes: list[int], per_chain: list[I64]) -> dict[int, I64]:
    """Key frames per animated node from the keys of each chain: a chain's nodes take its keys;
    animated nodes in no chain take every frame some chain keys.

    Parameters
    ----------
    character : Character
        The character.
    nodes : list of int
        The animated nodes.
    per_chain : list of ndarray
        Each chain's key frames.

    Returns
    -------
    dict of int to ndarray
        Key frames by node.
    """
    union = np.unique(np.concatenate(per_chain)).astype(np.int64)
    owner = {j: keys for chain, keys in zip(character.chains, per_chain, strict=True) for j in chain.nodes}
    return {j: np.asarray(owner.get(j, union), dtype=np.int64) for j in nodes}


def chain_weights(motion: Motion) -> F64:
    """Seed 003's joint weights of a :func:`chain_motion` with its first two joints (the world root
    and the node the chain hangs from) at zero, the chain's joints' renormalised to sum 1.

    Parameters
    ----------
    motion : Motion
        A :func:`chain_motion`.

    Returns
    -------
    ndarray
        ``(J,)`` float64.
    """
    w = joint_weights(motion)
    w[:2] = 0.0
    return w / w.sum()
