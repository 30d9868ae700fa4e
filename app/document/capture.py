"""A BVH capture as the studio keeps it: drawn as a skeleton of bones, stored in a project as
BVH text, and keyed so that every edit of its key poses has its frame as a key."""

from __future__ import annotations

from collections.abc import Iterable

import numpy as np

from hairtool.errors import FormatError
from hairtool.groom import Animation
from hairtool.mocap.bvh import Motion, bvh_from_bytes, bvh_text
from hairtool.mocap.pose_edit import Edit, RetimeEdit


def skeleton_animation(motion: Motion) -> Animation:
    """``(F, 2·B, 3)`` frames of the B bones of a capture, at its frame rate: every bone (joint →
    parent, and each End Site → its joint) is one 2-vertex strand, root at the parent."""
    pos = motion.joint_positions(end_sites=True)  # (F, J + E, 3), End Sites last
    parents = np.concatenate([motion.parents, motion.end_parents])
    child = np.flatnonzero(parents >= 0)
    if child.size == 0:
        raise FormatError("<bvh>", "the skeleton has a single joint and no End Site: no bones to draw")
    ends = np.column_stack([parents[child], child]).reshape(-1)  # parent, child for each bone
    return Animation(pos[:, ends], np.full(child.size, 2), motion.fps)


def motion_text(motion: Motion) -> str:
    """The capture as BVH text (what a project keeps), as a BVH file of it holds it."""
    return bvh_text(motion)


def motion_from_text(text: str, source: str) -> Motion:
    """A capture from BVH text; :class:`FormatError` naming ``source`` when it does not read."""
    if not isinstance(text, str):
        raise FormatError(source, "the capture is not BVH text")
    return bvh_from_bytes(text.encode("utf-8"), source)


def edit_frames(edits: Iterable[Edit]) -> tuple[int, ...]:
    """The frames that must be keys for ``edits`` to apply in order: each edit's key, except a
    key an earlier edit moved there in time (that move makes it a key)."""
    need, moved = set(), set()
    for e in edits:
        if e.frame not in moved:
            need.add(int(e.frame))
        if isinstance(e, RetimeEdit):
            moved.discard(e.frame)
            moved.add(int(e.to))
    return tuple(sorted(need))
