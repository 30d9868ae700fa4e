"""The groom side of the document: the groom as authored (its metadata is the scene description,
up axis included), the engine's parameters, the strokes with the per-strand state they made
(mask, clump strength, selection, hidden, origin), the head mesh, the render-hair definition and
the camera and view settings.

:class:`GroomState` is immutable and shares its arrays: a command keeps the state before and
after it, so undo is exact by construction. The strokes are the frozen pipeline's own snapshot
(:meth:`~hairtool.frozen.pipeline.FrozenPipeline.snapshot`); the pipeline itself is derived, made
on first use and brought to whatever state Undo or Redo lands on with
:meth:`~hairtool.frozen.pipeline.FrozenPipeline.restore` (rebuilt when the groom, its parameters or
its head changed). Only the pipeline's public API is used.

A stroke is one step however many samples it has: its samples are applied as the mouse moves
(:meth:`GroomSide.stroke`, the same ``stroke`` id merges them), or by the studio's engine thread,
which then records the stroke on release (:meth:`GroomSide.record`). Camera and view settings
are kept and saved, but moving the camera is not an undo step and leaves the document
unchanged, as in Blender and Maya.
"""

from __future__ import annotations

import dataclasses
import hashlib
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from types import MappingProxyType

import numpy as np

from app.document.undo import Command, UndoStack
from hairtool.errors import HairtoolError, ParameterError
from hairtool.frozen.pipeline import FrozenParams, FrozenPipeline, FrozenSnapshot
from hairtool.frozen.selection import SelectionSample
from hairtool.groom import Groom
from hairtool.guides.binding import ChildBinding
from hairtool.io.obj import Mesh
from hairtool.metadata import UP_AXES

STUDIO_PARAMS = FrozenParams(keep_lengths=True)  # the studio keeps strand lengths after clumping


@dataclass(frozen=True, eq=False)
class GroomState:
    """What a project holds of the groom, less the view (:attr:`GroomSide.view`: not an undo
    step, so Undo never turns the camera back). ``strokes`` None: no stroke yet."""

    rest: Groom
    params: FrozenParams = STUDIO_PARAMS
    strokes: FrozenSnapshot | None = None
    mesh: Mesh | None = None
    children: ChildBinding | None = None
    source: str | None = None
    clump_children: bool = False  # ClumpWithGaps among the render hair (saved, exported)


_SURFACES: dict[bytes, object] = {}  # the last heads' surfaces, by the mesh's content


def surface_of(mesh: Mesh | None):
    """The head mesh as the surface the brushes work on (None without a usable one); made once
    per head (a surface is read, never changed), so Undo of a head, an up axis or a reopened
    project builds none."""
    from hairtool.guides.planting import HeadSurface

    if mesh is None:
        return None
    digest = hashlib.blake2b(digest_size=16)
    for a in (mesh.vertices, mesh.faces, mesh.normals):
        digest.update(str((a.dtype, a.shape)).encode())
        digest.update(np.ascontiguousarray(a).tobytes())
    key = digest.digest()
    if key not in _SURFACES:
        try:
            surface = HeadSurface(mesh)
        except HairtoolError:
            surface = None
        if len(_SURFACES) >= 4:
            _SURFACES.clear()
        _SURFACES[key] = surface
    return _SURFACES[key]


class SetGroom(Command):
    """One edit of the groom side: the state before and after. Steps of one stroke (the same
    ``stroke`` id) merge: the step keeps the first state before and the last after."""

    def __init__(
        self, side: GroomSide, text: str, before: GroomState, after: GroomState, stroke: object = None
    ):
        self.side, self.text, self.before, self.after, self.stroke = side, text, before, after, stroke

    def do(self) -> None:
        self.side._set(self.after)

    def undo(self) -> None:
        self.side._set(self.before)

    def merge(self, other: Command) -> bool:
        if self.stroke is None or not isinstance(other, SetGroom) or other.stroke != self.stroke:
            return False
        self.after = other.after
        return True


class Steps(Command):
    """Several commands as one step (opening a groom closes the animation made of the old one)."""

    def __init__(self, text: str, commands: Sequence[Command]) -> None:
        self.text, self.commands = text, tuple(commands)

    def do(self) -> None:
        for c in self.commands:
            c.do()

    def undo(self) -> None:
        for c in reversed(self.commands):
            c.undo()


class GroomSide:
    """The groom side of one document, on the document's undo stack; see the module docstring."""

    def __init__(self, stack: UndoStack, state: GroomState, view: Mapping[str, object] | None = None) -> None:
        if not isinstance(state.rest, Groom):
            raise ParameterError("groom", type(state.rest).__name__, "a Groom")
        state.params.validate()
        self.stack = stack
        self.state = state
        self.view: Mapping[str, object] = MappingProxyType(dict(view or {}))  # camera and view settings
        self._listeners: list[Callable[[], None]] = []
        self._pipeline: FrozenPipeline | None = None
        self._made: tuple = ()  # (rest, params, mesh) the pipeline was made of
        self._at: FrozenSnapshot | None = None  # the strokes the pipeline holds now

    # -- observing -----------------------------------------------------------------------------
    def observe(self, callback: Callable[[], None]) -> None:
        """``callback()`` after every change of the state (an edit, an undo, a redo)."""
        self._listeners.append(callback)

    def _set(self, state: GroomState) -> None:
        self.state = state
        for callback in list(self._listeners):
            callback()

    # -- the engine, derived -------------------------------------------------------------------
    @property
    def pipeline(self) -> FrozenPipeline:
        """The frozen pipeline in the state's strokes (made or brought there now)."""
        s = self.state
        p = self._pipeline
        made = self._made
        new_params = made and made[1] is not s.params and made[1] != s.params
        if p is None or made[0] is not s.rest or made[2] is not s.mesh or new_params:
            p = FrozenPipeline(s.rest, s.params, surface_of(s.mesh))
            self._pipeline, self._made, self._at = p, (s.rest, s.params, s.mesh), None
        if self._at is not s.strokes:
            if s.strokes is None:
                p.reset_strokes()
            else:
                p.restore(s.strokes)
            self._at = s.strokes
        return p

    @property
    def result(self) -> Groom:
        return self.pipeline.result

    def settled(self) -> FrozenSnapshot | None:
        """The strokes as a replay gives them (brush-local moves settled: their bytes). In the
        middle of a stroke (moves the engine applied that are no step yet) the state as it is: the
        stroke settles as it is recorded."""
        p = self._pipeline
        recorded = 0 if self._at is None else len(self._at.log)
        if p is not None and self._at is self.state.strokes and p.unsettled and len(p.strokes) == recorded:
            p.settle()
            self._at = p.snapshot()
            self._set(dataclasses.replace(self.state, strokes=self._at))
        return self.state.strokes

    # -- commands ------------------------------------------------------------------------------
    def reset(self, state: GroomState) -> None:
        """A new document's groom (a file opened, a project read): no step. The caller starts a
        new history (the old steps hold states of the old groom)."""
        state.params.validate()
        self._set(state)

    def _idle(self) -> bool:
        """No engine made and no stroke to replay: a change needs no engine (a first start's
        parameters, axis or head set before its kernels are compiled)."""
        return self._pipeline is None and self.state.strokes is None

    def _push(
        self, text: str, after: GroomState, before: GroomState | None = None, stroke: object = None
    ) -> None:
        before = self.state if before is None else before
        self.stack.push(SetGroom(self, text, before, after, stroke))

    def _strokes_now(self, text: str, before: GroomState, stroke: object = None, **changes) -> None:
        """The pipeline moved on (samples, a new head, new parameters): its snapshot is the step's after."""
        snap = self._pipeline.snapshot()
        self._at = snap if snap.log else None  # no stroke: the fresh state (as a project loads it)
        self.state = dataclasses.replace(before, strokes=self._at, **changes)
        self._made = (self.state.rest, self.state.params, self.state.mesh)
        self._push(text, self.state, before, stroke)

    def stroke(
        self, samples: Sequence, stroke: object = None, text: str = "Stroke", local: bool = True
    ) -> None:
        """Samples of any brush applied now; samples of one stroke (the same ``stroke`` id) are one
        undo step. Refused (HairtoolError, nothing changes) where the engine refuses a sample."""
        before = self.state
        self.pipeline.apply_samples(list(samples), local)
        self._strokes_now(text, before, stroke)

    def record(self, before: GroomState, text: str = "Stroke") -> None:
        """A stroke the engine thread applied to :attr:`pipeline` from ``before``: one step."""
        if self._pipeline is None:
            return
        if self._at is not before.strokes or self.state.strokes is not before.strokes:
            # an Undo or Redo came mid-stroke: the document stays as it is, and the stroke's moves
            # go (an engine is made afresh on the document's strokes when it is next used)
            self._pipeline = None
            return
        if len(self._pipeline.strokes) == (0 if before.strokes is None else len(before.strokes.log)):
            return  # it applied nothing
        self._strokes_now(text, before)

    def end_stroke(self) -> None:
        """The mouse is released: the result is clumped as a replay clumps it (the step's after)."""
        top = self.stack.top
        if self._pipeline is None or not self._pipeline.unsettled:
            return
        self.settled()
        if isinstance(top, SetGroom) and top.after.strokes is not None and top.after.rest is self.state.rest:
            top.after = self.state

    def select(self, sample: SelectionSample, text: str = "") -> bool:
        """One selection step (select all, box, hide, reveal …); False where it changes nothing.
        Refused (ParameterError) where it would hide every strand."""
        p = self.pipeline
        selected, hidden = p.selected, p.hidden
        sel, hid = p.selection_after(sample)
        if np.array_equal(sel, selected) and np.array_equal(hid, hidden):
            return False
        if hid.all():
            raise ParameterError("hide", sample.op, "a step that leaves a strand to see and groom")
        self.stroke([sample], text=text or f"Select {sample.op.replace('_', ' ')}")
        return True

    def set_up_axis(self, axis: str) -> None:
        """Which axis is up (a relabelling: the points stay, the strokes are replayed)."""
        axis = str(axis).upper()
        if axis not in UP_AXES:
            raise ParameterError("up axis", axis, "Y or Z")
        s = self.state
        if axis == s.rest.metadata.up_axis:
            return
        rest = s.rest.with_metadata(s.rest.metadata.with_(up_axis=axis))
        if self._idle():
            self._push(f"Up axis {axis}", dataclasses.replace(s, rest=rest))
            return
        # The strokes replayed on the relabelled groom (brushes read the up axis): what a save
        # of it gives when it is opened again.
        p = FrozenPipeline(rest, s.params, surface_of(s.mesh))
        if s.strokes is not None:
            p.restore(FrozenSnapshot.replaying(s.strokes.log, rest))
        self._pipeline = p
        self._strokes_now(f"Up axis {axis}", s, rest=rest)

    def set_mesh(self, mesh: Mesh | None, text: str = "Head mesh") -> None:
        """A new head (None: none); the strokes are replayed on it. Refused when strokes need a
        head and ``mesh`` is none or unusable (the old head stays)."""
        if mesh is self.state.mesh:
            return
        before = self.state
        if self._idle():
            self._push(text, dataclasses.replace(before, mesh=mesh))
            return
        p = self.pipeline
        p.set_surface(surface_of(mesh))  # replays; refused: the old surface stays
        self._strokes_now(text, before, mesh=mesh)

    def set_params(self, params: FrozenParams, text: str = "Engine parameters", drag: object = None) -> None:
        """New engine parameters; the strokes are replayed on the new frozen groom. Edits of one
        slider drag (the same ``drag``, not None) are one step."""
        if params == self.state.params:
            return
        params.validate()
        before = self.state
        stroke = None if drag is None else ("parameters", drag)
        if self._idle():
            self._push(text, dataclasses.replace(before, params=params), stroke=stroke)
            return
        self.pipeline.set_params(params)
        self._strokes_now(text, before, stroke, params=params)

    def set_children(
        self, children: ChildBinding | None, text: str = "Render hair", clump: bool | None = None
    ) -> None:
        """The render-hair definition (None: none) and whether its children are clumped (None:
        grown children are, authored ones not: :func:`~hairtool.guides.binding.clumps_by_default`);
        ParameterError for children whose guides are not this groom's strands."""
        rest = self.state.rest
        if children is not None and (
            children.rest_guides.topology != rest.topology
            or not np.array_equal(children.rest_guides.points, rest.points)
        ):
            raise ParameterError("render hair", "children of another groom", "children of its strands")
        if clump is None:
            from hairtool.guides.binding import clumps_by_default

            clump = self.state.clump_children if children is None else clumps_by_default(children)
        if children is not self.state.children or bool(clump) != self.state.clump_children:
            self._push(text, dataclasses.replace(self.state, children=children, clump_children=bool(clump)))

    def set_clump_children(self, on: bool) -> None:
        """ClumpWithGaps among the render hair, on or off: one step."""
        if bool(on) != self.state.clump_children:
            text = "Clump children" if on else "Unclump children"
            self._push(text, dataclasses.replace(self.state, clump_children=bool(on)))

    def set_view(self, **changes: object) -> None:
        """Camera and view settings (JSON values): kept and saved, not an undo step."""
        self.view = MappingProxyType({**self.view, **changes})

    def replace(self, state: GroomState, text: str) -> Command:
        """A command that opens ``state`` (another groom), for the document to push."""
        return SetGroom(self, text, self.state, state)
