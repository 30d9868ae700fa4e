"""The document written out, and read back: the project file (the same fields the studio
writes: the groom with its scene description, engine parameters, strokes, head mesh, render
hair and view settings as ``display``; the animation, its source, the key settings, and the
capture with its edits as ``settings["capture"]``), the edited capture as BVH and the keys record.

Save is the state written whole and marks the stack clean; load is its inverse (a new document,
nothing to undo). Files are written to a temporary name and renamed by the writers used here.
"""

from __future__ import annotations

import dataclasses
import hashlib
import itertools
import os
import sys
from types import MappingProxyType

import numpy as np

from app.document.animation import AnimationState, Document
from app.document.capture import motion_from_text, motion_text
from app.document.groom import GroomSide, GroomState
from hairtool import project as pf
from hairtool.errors import FormatError, HairtoolError
from hairtool.keys import session as ks
from hairtool.keys.export import keys_record, write_keys_json
from hairtool.mocap.bvh import Motion, write_bvh
from hairtool.mocap.edit_file import parse_capture_edits

_TEXTS: dict[int, tuple[Motion, str]] = {}  # the last captures written, by identity


def _text(capture: Motion) -> str:
    """The capture's BVH text, written once per capture (captures are never changed in place)."""
    hit = _TEXTS.get(id(capture))
    if hit is None or hit[0] is not capture:
        if len(_TEXTS) >= 8:
            _TEXTS.clear()
        hit = _TEXTS[id(capture)] = (capture, motion_text(capture))
    return hit[1]


def animation_settings(s: AnimationState) -> dict:
    """The project's ``settings`` entries of the animation side: the capture with its edits, and
    the keys a key edit holds (a hair animation's)."""
    settings: dict = {}
    if s.capture is not None:
        settings["capture"] = {
            "bvh": _text(s.capture),
            "source": s.source,
            "edits": [e.to_dict() for e in s.edits],
            "channel_edits": [e.to_dict() for e in s.channel_edits],
        }
    if s.held_keys and s.capture is None:
        settings["held_keys"] = list(s.held_keys)
    return settings


def animation_state(project: pf.Project, where: str = "project") -> AnimationState:
    """The animation side of a project; FormatError naming ``where`` for what it cannot use."""
    try:
        settings = ks.KeySettings(**project.key_settings).validate()
    except (TypeError, ValueError, HairtoolError) as e:
        raise FormatError(where, f"key settings: {e}") from None
    capture, edits, channel_edits = None, (), ()
    saved = project.settings.get("capture")
    if saved is not None:
        if not isinstance(saved, dict):
            raise FormatError(where, "the capture is not an object with its BVH and edits")
        capture = motion_from_text(saved.get("bvh"), where)
        lists = {k: saved[k] for k in ("edits", "channel_edits") if k in saved}
        read = parse_capture_edits(lists, capture, where)
        edits, channel_edits = tuple(read.edits), tuple(read.channel_edits)
    held: tuple[int, ...] = ()
    saved_keys = project.settings.get("held_keys")
    if saved_keys is not None and project.animation is not None and capture is None:
        ok = isinstance(saved_keys, list) and all(type(k) is int for k in saved_keys)
        n = project.animation.n_frames
        ok = ok and len(saved_keys) >= 2 and saved_keys[0] == 0 and saved_keys[-1] == n - 1
        if not ok or any(b <= a for a, b in itertools.pairwise(saved_keys)):
            raise FormatError(where, "held_keys: expected increasing frames from the first to the last")
        held = tuple(saved_keys)
    return AnimationState(
        project.animation, project.animation_source, capture, settings, edits, channel_edits, held
    )


def to_project(doc: Document) -> pf.Project:
    s = doc.state
    settings = animation_settings(s)
    g = doc.hair.state
    strokes = doc.hair.settled()
    aligned = None
    if strokes is not None and strokes.aligned.topology == g.rest.topology:
        aligned = strokes.aligned.with_metadata(g.rest.metadata)
    return pf.Project(
        rest=g.rest,
        params=g.params,
        strokes=() if strokes is None else strokes.log,
        aligned=aligned,
        display={**doc.hair.view, "clump_children": g.clump_children},
        groom_source=g.source,
        children=g.children,
        mesh=g.mesh,
        animation=s.animation,
        animation_source=s.source,
        key_settings=dataclasses.asdict(s.settings),
        settings=settings,
    )


def from_project(project: pf.Project, where: str = "project") -> Document:
    """A document of a project; FormatError naming ``where`` for settings it cannot use."""
    doc = Document(groom_of(project), animation_state(project, where))
    doc.hair.view = MappingProxyType({k: v for k, v in project.display.items() if k != "clump_children"})
    return doc


def groom_of(project: pf.Project) -> GroomState:
    """The groom side of a project, its strokes replayed (or taken as saved) on its engine."""
    clump = bool(project.display.get("clump_children", False))  # (a project from before: off)
    g = GroomState(
        project.rest, project.params, None, project.mesh, project.children, project.groom_source, clump
    )
    if not project.strokes:
        return g
    key = _strokes_key(project)
    strokes = _REPLAYED.get(key)
    if strokes is None:
        side = GroomSide(None, g)
        p = side.pipeline
        p.restore(project.stroke_snapshot(p))
        strokes = p.snapshot()
        if len(_REPLAYED) >= 8:
            _REPLAYED.clear()
        _REPLAYED[key] = strokes
    return dataclasses.replace(g, strokes=strokes)


_REPLAYED: dict[bytes, object] = {}  # the strokes of the last projects read, by what made them


def _strokes_key(project: pf.Project) -> bytes:
    """What a project's strokes state follows from (groom, parameters, head, log, stored points),
    so that reopening the same strokes (Revert, a recovery) replays them once."""
    h = hashlib.blake2b(digest_size=20)
    mesh = project.mesh
    arrays = [project.rest.points, project.rest.counts]
    arrays += [] if mesh is None else [mesh.vertices, mesh.faces, mesh.normals]
    arrays += [] if project.aligned is None else [project.aligned.points]
    for a in arrays:
        h.update(repr((a.dtype.str, a.shape)).encode())
        h.update(np.ascontiguousarray(a).tobytes())
    with np.printoptions(threshold=sys.maxsize):  # (arrays in the metadata or params written whole)
        h.update(repr((project.rest.metadata, project.params, project.strokes)).encode())
    return h.digest()


def save(doc: Document, path: str | os.PathLike[str]) -> None:
    pf.save(path, to_project(doc))
    doc.stack.set_clean()


def load(path: str | os.PathLike[str]) -> Document:
    return from_project(pf.load(path), str(path))


def export_bvh(doc: Document, path: str | os.PathLike[str]) -> None:
    """The edited capture at every frame as BVH."""
    motion = doc.keyed().motion
    if motion is None:
        raise HairtoolError("BVH is written for a motion capture: open a .bvh first")
    write_bvh(path, motion)


def export_keys(doc: Document, path: str | os.PathLike[str]) -> None:
    """The keys record (JSON) of the document's keys; its count is the keys chosen."""
    anim, keys = doc.state.animation, doc.keys
    if anim is None or keys is None:
        raise HairtoolError("no keys to export: make or open an animation first")
    params = dataclasses.asdict(doc.state.settings) | {"count": int(np.size(keys))}
    result = {"frames": anim.n_frames, "fps": anim.fps, "keys": keys, "params": params}
    write_keys_json(path, keys_record(result, doc.state.source or None, time_codes=anim.time_codes))
