"""A capture's edits as a studio project keeps them, read for ``hairtool keys --edit`` and
replayed the way the studio replays them, so a pipeline gets the animator's motion.

EDITS.json is a list of edits of the pose keys, or the object a project keeps of its capture
(``{"edits": [...], "channel_edits": [...]}``; its ``bvh``, ``source`` and ``chain`` may be
there and are not used: the capture is the command's input). Each entry is one of

- a pose by IK ``{"frame", "joint", "target": [x, y, z], "chain"}`` (:class:`PoseEdit`),
- a key moved in time ``{"frame", "to"}`` (:class:`RetimeEdit`: the pose key, every channel),
- a key's value ``{"frame", "joint", "channel", "value"}`` (:class:`ChannelEdit`, degrees),
- a key's handle ``{"frame", "joint", "channel", "slope"}`` (:class:`TangentEdit`, per frame),
- one channel's key moved in time ``{"frame", "joint", "channel", "to"}``
  (:class:`ChannelRetimeEdit`: per-channel keys only, so in ``channel_edits``),

told apart by their fields; an entry of no kind is refused naming it. The ``edits`` apply in
order on the pose keys (:class:`PoseEditor`), then the ``channel_edits`` in order on each
channel's own keys over the pose-edited capture (:class:`ChannelEditor`), the keys solved as the
studio solves them (:func:`channel_keys`): the studio's Per-channel keys layer. A pose by IK in
``channel_edits`` is a joint the studio dragged with per-channel keys on: it keys each channel it
turns on that channel's own keys, at a key of some channel or at a pose key (as edited).
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike

from hairtool.errors import FormatError, HairtoolError
from hairtool.keys.channels import per_channel_keys
from hairtool.mocap.bvh import Motion
from hairtool.mocap.channel_edit import (
    ChannelEditor,
    ChannelRetimeEdit,
    channel_features,
    parse_channel_edits,
)
from hairtool.mocap.pose_edit import (
    ChannelEdit,
    EditReport,
    PoseEdit,
    PoseEditor,
    TangentEdit,
    parse_edit_list,
    read_json,
)

#: What a project's capture object holds; "edits" and "channel_edits" are the edits.
PROJECT_FIELDS = ("edits", "channel_edits", "bvh", "source", "chain")
KINDS = (
    "a pose {frame, joint, target, chain}, a key move {frame, to}, a key value {frame, joint, "
    "channel, value}, a handle {frame, joint, channel, slope} or a channel's key move {frame, "
    "joint, channel, to}"
)
CHANNEL_KINDS = (ChannelEdit, TangentEdit, ChannelRetimeEdit, PoseEdit)  # what "channel_edits" holds
#: The studio's price per key (relative) of its per-channel keys (KeySettings().tau).
STUDIO_CHANNEL_PRICE = 0.01


@dataclass
class CaptureEdits:
    """The edits of the pose keys, in order, and the per-channel key edits over them."""

    edits: list = field(default_factory=list)
    channel_edits: list = field(default_factory=list)
    project: bool = False  # read from a project's capture object (not a plain list)

    def to_dict(self) -> dict:
        return {
            "edits": [e.to_dict() for e in self.edits],
            "channel_edits": [e.to_dict() for e in self.channel_edits],
        }


def _kind(e: object) -> str | None:
    """Which kind of edit an entry's fields say it is (None: none)."""
    if not isinstance(e, dict):
        return None
    if "target" in e or "chain" in e:
        return "pose"
    if "channel" in e:
        return "channel move" if "to" in e else "handle" if "slope" in e else "value"
    if "to" in e and "joint" not in e:
        return "move"
    return None


def parse_entry(e: object, motion: Motion, source: str, where: str) -> object:
    """One entry of an edit list (module docstring), checked against the skeleton; a fault or
    an entry of no kind raises :class:`FormatError` naming ``source`` and ``where``.

    Parameters
    ----------
    e : object
        The entry as parsed from JSON.
    motion : Motion
        The capture whose joints and channels it names.
    source : str
        The file, named in a refusal.
    where : str
        The entry's place (``edit 3``), named in a refusal.

    Returns
    -------
    object
        A PoseEdit, ChannelEdit, TangentEdit or RetimeEdit.
    """
    kind = _kind(e)
    if kind is None:
        shown = str(e)[:80]
        raise FormatError(source, f"{where} {shown} is no edit the studio keeps: {KINDS}")
    try:
        if kind == "channel move":
            (edit,) = parse_channel_edits([e], motion, source)
        else:
            (edit,) = parse_edit_list([e], motion, source)
    except FormatError as err:
        reason = err.reason.replace("channel edit 1", where, 1).replace("edit 1", where, 1)
        raise FormatError(source, reason) from None
    return edit


def parse_capture_edits(data: object, motion: Motion, source: str = "edits") -> CaptureEdits:
    """A list of edits of the pose keys, or a project's capture object (module docstring).

    Parameters
    ----------
    data : object
        The parsed JSON.
    motion : Motion
        The capture.
    source : str, default "edits"
        The file, named in a refusal.

    Returns
    -------
    CaptureEdits
        The pose-key edits and the per-channel edits.
    """
    if isinstance(data, list):
        return CaptureEdits([parse_entry(e, motion, source, f"edit {i}") for i, e in enumerate(data, 1)])
    if not isinstance(data, dict):
        raise FormatError(source, 'expected a list of edits or a project\'s {"edits", "channel_edits"}')
    extra = sorted(str(k)[:40] for k in data if k not in PROJECT_FIELDS)
    if extra:
        known = ", ".join(PROJECT_FIELDS)
        raise FormatError(source, f"unknown fields {', '.join(extra)} (a project's capture: {known})")
    out = CaptureEdits(project=True)
    lists = (("edits", "edit", out.edits), ("channel_edits", "channel edit", out.channel_edits))
    for name, label, into in lists:
        entries = data.get(name, [])
        if not isinstance(entries, list):
            raise FormatError(source, f'"{name}" is not a list of edits')
        for i, e in enumerate(entries, 1):
            edit = parse_entry(e, motion, source, f"{label} {i}")
            if name == "channel_edits" and not isinstance(edit, CHANNEL_KINDS):
                what = "a pose key's move in time"
                raise FormatError(source, f'{label} {i} is {what}: it belongs in "edits" (the pose keys)')
            into.append(edit)
    return out


def read_capture_edits(path: str | os.PathLike[str], motion: Motion) -> CaptureEdits:
    """:func:`parse_capture_edits` of a JSON file (FormatError naming it).

    Parameters
    ----------
    path : str or os.PathLike
        The edit file.
    motion : Motion
        The capture.

    Returns
    -------
    CaptureEdits
        The edits.
    """
    return parse_capture_edits(read_json(path), motion, os.fspath(path))


def channel_keys(motion: Motion, interp: str, price: float = STUDIO_CHANNEL_PRICE) -> list:
    """Each channel's own keys as the studio's graph editor solves them: seed 003's per-channel
    DP on the capture's channels (angles unwrapped) at ``price`` per key, a share of each
    channel's two-key error.

    Parameters
    ----------
    motion : Motion
        The capture.
    interp : str
        The key curve.
    price : float, default STUDIO_CHANNEL_PRICE
        A key's price, a share of each channel's two-key error.

    Returns
    -------
    list
        Each channel's key frames.
    """
    x = channel_features(motion)
    return per_channel_keys(x, price, interp=interp, relative=True).keys


def _not_a_key(editor, e: object) -> str | None:
    """Why an edit's frame is no key it can be made at (None: it is): the pose keys as edited
    so far (a key moved in time is named by its new frame), or for an IK pose on per-channel
    keys a key of some channel or a pose key below them; a channel's own keys are checked by
    its editor."""
    if isinstance(editor, PoseEditor):
        keys, what = editor.keys, "a key"
    elif isinstance(e, PoseEdit):
        keys = editor.pose_frames
        what = "a key of any channel or a pose key" if editor.pose_keys.size else "a key of any channel"
    else:
        return None
    if e.frame in keys:
        return None
    return f"frame {e.frame} is not {what}; the keys are {' '.join(map(str, keys.tolist()))}"


def apply_each(editor, edits: list, source: str, label: str, method: str = "auto") -> list[EditReport]:
    """``editor.apply_all`` one edit at a time, a refusal raised as :class:`FormatError` naming
    ``source`` and the entry (``label`` and its number from 1).

    Parameters
    ----------
    editor : PoseEditor or ChannelEditor
        The editor.
    edits : list
        Its edits.
    source : str
        The file, named in a refusal.
    label : str
        What an entry is called there (``edit``, ``channel edit``).
    method : str, default "auto"
        The IK solver.

    Returns
    -------
    list of EditReport
        One per edit.
    """
    out = []
    for i, e in enumerate(edits, 1):
        why = _not_a_key(editor, e)
        if why is not None:
            raise FormatError(source, f"{label} {i}: {why}")
        try:
            out += editor.apply_all([e], method)
        except HairtoolError as err:
            raise FormatError(source, f"{label} {i}: {err}") from None
    return out


def replay(
    motion: Motion,
    keys: ArrayLike,
    interp: str,
    edits: CaptureEdits,
    *,
    price: float = STUDIO_CHANNEL_PRICE,
    source: str = "edits",
    method: str = "auto",
) -> tuple[Motion, list[EditReport]]:
    """The edited capture and one report per edit: ``edits.edits`` on the pose ``keys``, then
    ``edits.channel_edits`` on each channel's own keys (:func:`channel_keys` at ``price``) over
    the pose-edited capture (an IK pose there may be at a pose key as edited), as the studio
    applies a project's edits.

    Parameters
    ----------
    motion : Motion
        The capture.
    keys : array_like
        Its pose keys.
    interp : str
        The key curve.
    edits : CaptureEdits
        The edits, as the studio keeps them.
    price : float, default STUDIO_CHANNEL_PRICE
        The per-channel keys' price.
    source : str, default "edits"
        The file, named in a refusal.
    method : str, default "auto"
        The IK solver.

    Returns
    -------
    tuple of (Motion, list of EditReport)
        The edited capture and the reports.
    """
    pose = PoseEditor(motion, np.asarray(keys), interp)
    reports = apply_each(pose, edits.edits, source, "edit", method)
    out = pose.motion()
    if edits.channel_edits:
        layer = ChannelEditor(out, channel_keys(motion, interp, price), interp, pose_keys=pose.keys)
        reports += apply_each(layer, edits.channel_edits, source, "channel edit", method)
        out = layer.motion()
    return out, reports
