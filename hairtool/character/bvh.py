"""A BVH of a character's hair chains, for tools that take motion capture (Blender, MotionBuilder).

The skeleton: a root ``World`` at the origin; under it, each node the chains hang from (the
head, usually) with its world position and rotation as six channels; under that, each chain's
nodes with three rotation channels (ZXY, degrees, their local rotations), the tip as an End
Site (VRM 0.x chains end in their 7 cm virtual tail instead). Lengths stay the file's metres.
"""

from __future__ import annotations

import os

import numpy as np
from numpy.typing import NDArray

from hairtool.character.model import Character
from hairtool.character.springs import VIRTUAL_TAIL, forward
from hairtool.errors import ParameterError
from hairtool.mocap import quaternion as quat
from hairtool.mocap.bvh import Motion, write_bvh

F64 = NDArray[np.float64]
ROTATION = ["Zrotation", "Xrotation", "Yrotation"]
ORDER = "ZXY"


def chains_motion(character: Character, rotations: F64, fps: float) -> Motion:
    """The hair chains of ``rotations`` ``(F, J, 4)`` (local, wxyz) as a BVH :class:`Motion`.

    Parameters
    ----------
    character : Character
        The character.
    rotations : ndarray
        ``(F, J, 4)`` wxyz.
    fps : float
        Frames per second.

    Returns
    -------
    Motion
        The chains as a BVH motion.
    """
    if not character.chains:
        raise ParameterError("chains", 0, f"at least one hair chain in {character.path}")
    if not np.isfinite(fps) or fps <= 0:
        raise ParameterError("fps", fps, "a positive frame rate")
    nodes = character.nodes
    names, parents, offsets, channels, columns = ["World"], [-1], [np.zeros(3)], [[]], []
    end_parents, end_offsets = [], []
    posed = [forward(character, r) for r in rotations]
    anchors: dict[int, int] = {}
    for chain in character.chains:
        top = int(nodes.parents[chain.nodes[0]])
        if top not in anchors:
            anchors[top] = len(names)
            names.append("World" if top < 0 else nodes.names[top])
            parents.append(0)
            offsets.append(np.zeros(3))
            channels.append(["Xposition", "Yposition", "Zposition", *ROTATION])
            if top < 0:
                columns.append(np.zeros((len(rotations), 6)))
            else:
                pos = np.stack([p[0][top] for p in posed])
                rot = quat.to_euler(np.stack([p[1][top] for p in posed]), ORDER)
                columns.append(np.concatenate([pos, rot], axis=1))
        parent = anchors[top]
        ids = list(chain.nodes) if chain.virtual_tail else list(chain.nodes[:-1])
        for j in ids:
            names.append(nodes.names[j])
            parents.append(parent)
            offsets.append(nodes.translation[j])
            channels.append(list(ROTATION))
            columns.append(quat.to_euler(rotations[:, j], ORDER))
            parent = len(names) - 1
        end_parents.append(parent)
        if chain.virtual_tail:
            t = nodes.translation[ids[-1]]
            end_offsets.append(t / max(np.linalg.norm(t), 1e-30) * VIRTUAL_TAIL)
        else:
            end_offsets.append(nodes.translation[chain.nodes[-1]])
    return Motion(
        joint_names=names,
        parents=np.array(parents),
        offsets=np.array(offsets),
        channels=channels,
        values=np.concatenate(columns, axis=1),
        frame_time=1.0 / fps,
        end_parents=np.array(end_parents),
        end_offsets=np.array(end_offsets),
    )


def write_chains_bvh(path: str | os.PathLike[str], character: Character, rotations: F64, fps: float) -> None:
    """Write the hair chains of ``rotations`` as BVH (atomically).

    Parameters
    ----------
    path : str or os.PathLike
        The ``.bvh`` file.
    character : Character
        The character.
    rotations : ndarray
        ``(F, J, 4)`` wxyz.
    fps : float
        Frames per second.
    """
    write_bvh(path, chains_motion(character, rotations, fps))
