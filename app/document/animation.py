"""The animation side of the document: the animation and where it came from, the capture it is
the skeleton of, the key settings with their pins and exclusions, and the capture's key edits.

Every change is a command on the document's one :class:`~app.document.undo.UndoStack`; a
command keeps the whole state before and after it (:class:`AnimationState` is immutable and
shares its arrays, so a step costs a few references), so undo is exact by construction and an
animation replaced, then brought back by Undo, brings its own edits and their steps back too.

The keys are derived, never stored: one solve of the animation under the settings, with the
frames of the capture's edits pinned (:func:`app.document.capture.edit_frames`), so an edit
survives a change of interpolation or key count as a key the solve must keep. A key edit of a
hair animation's own frames (:meth:`Document.edit_frames`) holds the keys it was made on until
the settings change. Per-channel edits of a capture are kept in order; the studio's layer
applies them. A change the
settings cannot meet (fewer keys than the pinned frames need, a budget no key set reaches) is
refused with a ParameterError before anything changes. An edit that cannot apply (its frame
excluded by the dope sheet, a key move its new neighbours block) waits, and
:meth:`Document.notes` says so.
"""

from __future__ import annotations

import copy
import dataclasses
import itertools
from collections import OrderedDict
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field

import numpy as np

from app.document.capture import edit_frames, skeleton_animation
from app.document.groom import GroomSide, GroomState, Steps
from app.document.undo import Command, UndoStack
from hairtool.errors import GroomError, HairtoolError, ParameterError
from hairtool.groom import Animation, Groom
from hairtool.keys import session as ks
from hairtool.mocap.bvh import Motion
from hairtool.mocap.pose_edit import Edit, PoseEditor

_TAKES = itertools.count()
DERIVED_KEPT = 64  # derived states (keys, edited capture) remembered for undo and redo


@dataclass(frozen=True, eq=False)
class AnimationState:
    """What a project holds of the animation (None: no animation)."""

    animation: Animation | None = None
    source: str = ""
    capture: Motion | None = None  # the BVH the animation is the skeleton of, as captured
    settings: ks.KeySettings = field(default_factory=ks.KeySettings)
    edits: tuple[Edit, ...] = ()  # IK poses and graph-editor key edits, in the order made
    channel_edits: tuple = ()  # per-channel key edits over the edited capture, in the order made
    # the keys a key edit of the animation's own frames was made on (a hair animation's key pose
    # dragged, a key moved in time): they stay the keys until the key settings change
    held_keys: tuple[int, ...] = ()
    # which animation this is: each new or closed one is another take; its edits, undo and redo
    # keep it (a view tells a key edit from a new animation by it; never saved)
    take: int = field(default_factory=lambda: next(_TAKES))


@dataclass(frozen=True, eq=False)
class Keyed:
    """What follows from a state: the keys, and the capture with the edits that apply."""

    keys: np.ndarray | None
    motion: Motion | None  # the edited capture (None without a capture)
    shown: Animation | None  # what the timeline plays: the edited skeleton, or the animation
    applied: tuple[bool, ...]


def derive(
    state: AnimationState, solve: Callable[[Animation, ks.KeySettings], ks.KeySession] = ks.solve
) -> Keyed:
    """The keys and edited capture of ``state``; ParameterError when its settings cannot be met.
    ``solve`` may be a cached :func:`hairtool.keys.session.solve`."""
    anim = state.animation
    if anim is None or anim.n_frames < 2:
        return Keyed(None, state.capture, anim, (False,) * len(state.edits))
    if state.held_keys and state.capture is None:
        return Keyed(np.array(state.held_keys, dtype=np.int64), None, anim, ())
    solving = solving_settings(state)
    solving.constraints.check(anim.n_frames)
    keys = solve(anim, solving).keys_for(solving)
    if state.capture is None:
        return Keyed(keys, None, anim, ())
    if not state.edits:  # the capture as captured: its skeleton is the animation
        return Keyed(keys, state.capture, anim, ())
    editor = PoseEditor(state.capture, keys, state.settings.interp)
    applied = []
    for e in state.edits:
        try:
            editor.apply_all([e])
            applied.append(True)
        except HairtoolError:
            applied.append(False)
    motion = editor.motion()  # the keys are the edited ones: a key moved in time is there
    return Keyed(np.array(editor.keys), motion, skeleton_animation(motion), tuple(applied))


def solving_settings(state: AnimationState) -> ks.KeySettings:
    """The settings the keys are solved with: the state's, with the frames of the capture's
    edits pinned (but those the dope sheet excludes), so every edit has its key."""
    s = state.settings
    pins = set(s.pins) | (set(edit_frames(state.edits)) - set(s.excludes))
    return s.replace(pins=tuple(sorted(pins))) if pins != set(s.pins) else s


class SetState(Command):
    """One edit of the document: the state before and after. Steps of one drag (the same
    ``drag`` id) merge: the step keeps the first state before and the last after."""

    def __init__(self, doc: Document, text: str, after: AnimationState, drag: object = None) -> None:
        self.doc, self.text, self.before, self.after, self.drag = doc, text, doc.state, after, drag

    def do(self) -> None:
        self.doc._set(self.after)

    def undo(self) -> None:
        self.doc._set(self.before)

    def merge(self, other: Command) -> bool:
        if self.drag is None or not isinstance(other, SetState) or other.drag != self.drag:
            return False
        self.after = other.after
        return True


Confirm = Callable[[], bool]  # asks Save / Discard / Cancel: True to go on (saved or discarded)


class Document:
    """The studio's document: its groom side (:attr:`hair`, :mod:`app.document.groom`) and its
    animation side (:attr:`state`, this module), on one undo stack."""

    def __init__(self, groom: Groom | GroomState, state: AnimationState | None = None) -> None:
        if isinstance(groom, Groom):
            groom = GroomState(groom)
        if not isinstance(groom, GroomState):
            raise GroomError(f"expected a Groom, got {type(groom).__name__}")
        self.state = state if state is not None else AnimationState()
        self.stack = UndoStack()
        self.hair = GroomSide(self.stack, groom)
        self._listeners: list[Callable[[], None]] = []
        self._derived: OrderedDict[int, tuple[AnimationState, Keyed]] = OrderedDict()
        self._skeletons: OrderedDict[int, tuple[Motion, Animation]] = OrderedDict()
        self._solves: OrderedDict[tuple, tuple[Animation, ks.KeySession]] = OrderedDict()

    # -- observing -----------------------------------------------------------------------------
    @property
    def groom(self) -> Groom:
        """The groom as authored (its metadata: the scene description and up axis)."""
        return self.hair.state.rest

    def observe(self, callback: Callable[[], None]) -> None:
        """``callback()`` after every change of the animation side (an edit, an undo, a redo);
        the groom side has its own (``hair.observe``)."""
        self._listeners.append(callback)

    def _set(self, state: AnimationState) -> None:
        self.state = state
        for callback in list(self._listeners):
            callback()

    @property
    def changed(self) -> bool:
        """Unsaved work: the undo stack is not at its clean state."""
        return not self.stack.is_clean

    # -- derived -------------------------------------------------------------------------------
    def keyed(self, state: AnimationState | None = None) -> Keyed:
        state = self.state if state is None else state
        hit = self._derived.get(id(state))
        if hit is not None and hit[0] is state:
            self._derived.move_to_end(id(state))
            return hit[1]
        k = derive(state, self._solve)
        self._derived[id(state)] = (state, k)
        while len(self._derived) > DERIVED_KEPT:
            self._derived.popitem(last=False)
        return k

    def _skeleton(self, capture: Motion) -> Animation:
        """The capture's skeleton, made once per capture (reopening it draws the same bones)."""
        hit = self._skeletons.get(id(capture))
        if hit is None or hit[0] is not capture:
            hit = self._skeletons[id(capture)] = (capture, skeleton_animation(capture))
            while len(self._skeletons) > DERIVED_KEPT:
                self._skeletons.popitem(last=False)
        return hit[1]

    def _solve(self, animation: Animation, settings: ks.KeySettings) -> ks.KeySession:
        """One solve per animation, cost table and constraints (undo and redo solve nothing); other
        pins and exclusions on a table solved already share its table and solve only the layers."""
        what = (id(animation), settings.table_key, settings.constraints)
        hit = self._solves.get(what)
        if hit is not None and hit[0] is animation:
            self._solves.move_to_end(what)
            return hit[1]
        for (_, table_key, _), (solved, other) in reversed(self._solves.items()):
            if solved is animation and table_key == settings.table_key:  # other pins: the same table
                session = copy.copy(other).constrain(settings.constraints)
                break
        else:
            session = ks.solve(animation, settings)
        self._solves[what] = (animation, session)
        while len(self._solves) > DERIVED_KEPT:
            self._solves.popitem(last=False)
        return session

    def session(self, animation: Animation, settings: ks.KeySettings) -> ks.KeySession:
        """The solve of ``animation`` under ``settings`` the document's keys come from (one per
        animation, table and constraints; whoever shows the keys shares it)."""
        return self._solve(animation, settings)

    @property
    def keys(self) -> np.ndarray | None:
        return self.keyed().keys

    def notes(self) -> list[str]:
        """One line per edit that does not apply now (nothing waits without a word)."""
        k = self.keyed()
        return [
            f"{type(e).__name__} at frame {e.frame} waits: its key is not there now "
            "(the frame is excluded, or a key moved in time cannot move past its neighbours)"
            for e, ok in zip(self.state.edits, k.applied, strict=True)
            if not ok
        ]

    # -- commands ------------------------------------------------------------------------------
    def _push(self, text: str, after: AnimationState, drag: object = None, check: bool = True) -> None:
        if check:
            self.keyed(after)  # refused (ParameterError) before anything changes
        self.stack.push(SetState(self, text, after, drag))

    def replace_animation(
        self,
        animation: Animation | None,
        source: str = "",
        capture: Motion | None = None,
        confirm: Confirm | None = None,
        settings: ks.KeySettings | None = None,
        edits: Iterable[Edit] = (),
        channel_edits: Iterable = (),
        check: bool = True,
    ) -> bool:
        """A new animation (a cycle, a simulation, a capture opened) or none (Close animation):
        one undo step. Unsaved work is asked about first (``confirm``), as Open does; False when
        the answer was Cancel. The key settings stay but for the count (back to the knee), the
        pins and exclusions and an error budget (the last animation's units); ``settings`` (a
        project's, validated) replace them, and ``edits`` come with the capture (a project's).
        ``check=False`` leaves the first solve to whoever shows the keys (a long animation's
        solve in the background)."""
        if self.state.animation is not None and self.changed and confirm is not None and not confirm():
            return False
        if capture is not None:
            animation = self._skeleton(capture)
        if animation is not None and not isinstance(animation, Animation):
            raise GroomError(f"expected an Animation, got {type(animation).__name__}")
        s = self._settings_for_new() if settings is None else settings.validate()
        if settings is not None and animation is not None:
            s.constraints.check(animation.n_frames)
        after = AnimationState(
            animation, str(source) if animation is not None else "", capture, s,
            tuple(edits) if capture is not None else (),
            tuple(channel_edits) if capture is not None else (),
        )  # fmt: skip
        text = "Close animation" if animation is None else f"New animation ({source or 'untitled'})"
        self._push(text, after, check=check)
        return True

    def _settings_for_new(self) -> ks.KeySettings:
        s = self.state.settings.replace(count=0, pins=(), excludes=())
        if s.mode == "budget":
            d = ks.KeySettings()
            s = s.replace(mode=d.mode, budget=d.budget)
        return s

    def open_groom(self, groom: GroomState, confirm: Confirm | None = None, text: str = "") -> bool:
        """Another groom (File ▸ Open a groom): one undo step, asked about first as Open asks
        (False: Cancel). An animation made of the old groom's strands (a simulation, a cycle)
        closes with it; a capture stays (its skeleton is not the groom's)."""
        if self.changed and confirm is not None and not confirm():
            return False
        text = text or f"Open groom ({groom.source or 'untitled'})"
        steps: list[Command] = [self.hair.replace(groom, text)]
        if self.state.animation is not None and self.state.capture is None:
            steps.append(SetState(self, "Close animation", AnimationState(settings=self._settings_for_new())))
        self.stack.push(Steps(text, steps))
        return True

    def set_settings(
        self, text: str = "Key settings", drag: object = None, check: bool = True, **changes: object
    ) -> None:
        """Key count, mode, budget, price per key, interpolation…: one step (refused when the
        animation cannot be keyed so); the moves of one slider drag (the same ``drag``) are one
        step. Keys held by a key edit give way to the solve's. ``check=False``: the keys are
        solved elsewhere (in the background), which takes the step back if they cannot be."""
        s = self.state.settings.replace(**changes)
        if s != self.state.settings:
            if self.state.animation is not None:
                s.constraints.check(max(self.state.animation.n_frames, 2))
            after = dataclasses.replace(self.state, settings=s, held_keys=())
            self._push(text, after, drag, check)

    def steer(
        self, pins: Iterable[int], excludes: Iterable[int], text: str = "Steer keys", check: bool = True
    ) -> None:
        """The dope sheet's pinned and excluded frames."""
        self.set_settings(text, check=check, pins=tuple(pins), excludes=tuple(excludes))

    def edit_frames(self, animation: Animation, keys: Iterable[int], text: str = "Edit key") -> None:
        """A key edit of the animation's own frames (a hair animation's key pose dragged, a key's
        value, handle or time moved in the graph editor): the animation with the edited frames,
        and ``keys``, the keys the edit was made on (or moved to), held until the key settings
        change. A capture's frames follow from its edits (:meth:`edit`), never from this."""
        old = self.state.animation
        if old is None:
            raise ParameterError("edit", text, "an edit of an animation: make or open one first")
        if self.state.capture is not None:
            raise ParameterError("edit", text, "a pose edit of the capture (its frames follow its edits)")
        if not isinstance(animation, Animation) or animation.topology != old.topology:
            raise GroomError("a key edit keeps the animation's strands")
        if animation.n_frames != old.n_frames:
            raise GroomError("a key edit keeps the animation's frames")
        held = np.asarray(list(keys), dtype=np.int64)
        if held.size < 2 or held[0] != 0 or held[-1] != old.n_frames - 1 or np.any(np.diff(held) <= 0):
            raise ParameterError("keys", held.tolist(), "increasing frames from the first to the last")
        after = dataclasses.replace(self.state, animation=animation, held_keys=tuple(int(k) for k in held))
        self._push(text, after, check=False)

    def edit(self, edit: Edit | list[Edit], text: str = "", drag: object = None) -> None:
        """A key edit of the capture (IK pose, key value, handle, move in time; a list of them is
        one step: a key moved in time and value); moves of one drag (the same ``drag``) are one
        undo step. Refused when it does not apply."""
        new = list(edit) if isinstance(edit, list) else [edit]
        if self.state.capture is None or not new:
            raise ParameterError("edit", type(edit).__name__, "an edit of a capture: open a .bvh first")
        top = self.stack.top
        again = isinstance(top, SetState) and drag is not None and top.drag == drag
        again = again and top.after is self.state
        edits = self.state.edits[: -len(new)] if again else self.state.edits  # a drag's move replaces
        state = dataclasses.replace(self.state, edits=(*edits, *new))
        k = self.keyed(state)
        if not all(k.applied[-len(new) :]):
            raise ParameterError("edit", repr(new[-1]), "an edit at a key frame it can reach")
        last = new[-1]
        self._push(text or f"{type(last).__name__} at frame {last.frame}", state, drag)

    def edit_channels(self, edits: list, text: str) -> None:
        """Per-channel key edits of the capture (each channel on its own keys, over the edited
        capture): one step. Whoever shows the layer checks that they apply."""
        if self.state.capture is None:
            raise ParameterError("edit", text, "an edit of a capture: open a .bvh first")
        self._push(text, dataclasses.replace(self.state, channel_edits=(*self.state.channel_edits, *edits)))

    def undo(self) -> bool:
        return self.stack.undo()

    def redo(self) -> bool:
        return self.stack.redo()
