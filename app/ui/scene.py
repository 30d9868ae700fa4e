"""The studio's view of the groom side of the document: what the viewport draws of it (the
frozen groom, its render hair at a display share, colours), the brush settings, and the live
stroke on the document's engine.

The groom, its parameters, strokes, per-strand state, head mesh and render hair are the
document's (:class:`app.document.groom.GroomSide`, :attr:`Scene.hair`): every edit of them is a
document step, and an Undo or Redo lands here through the document's callback
(:meth:`Scene._on_hair`), which is the one place the views follow from. A stroke runs on the
document's engine while the mouse moves and becomes one step on release (:meth:`end_stroke`).

The scene knows nothing of widgets. Setters emit a signal only when the value really changes, so
a widget that writes a value and listens for it cannot loop; the viewport and the dock listen.

On a first start the engine's kernels compile in another process (:mod:`app.ui.engine_start`):
until :meth:`Scene.start_engine`, a scene made with ``engine_ready=False`` shows its groom as it
is, keeps parameter edits for later, and has no pipeline (``pipeline`` None, no strokes).
"""

from __future__ import annotations

import dataclasses
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np
from PySide6.QtCore import QObject, QTimer, Signal

from app.document.groom import STUDIO_PARAMS, GroomSide, GroomState
from app.document.undo import UndoStack
from app.render.ramps import DEFAULT_RAMP
from app.ui.brush_tool import LABELS, SIGNED, BrushTool, check_falloff
from app.ui.engine_thread import MoveEngine
from hairtool.errors import HairtoolError, ParameterError
from hairtool.frozen.brushes import CHANGE_STRANDS, NEED_SURFACE, registry, scalp_centre
from hairtool.frozen.pipeline import FrozenParams, FrozenPipeline
from hairtool.frozen.selection import SelectionSample
from hairtool.groom import Groom, Topology, vertex_ids_of
from hairtool.guides.binding import ChildBinding
from hairtool.io.obj import Mesh

ALIGN_MODES = ("paper", "preserve-length")
FOLLOW_SELECTION = registry.names_where(follows_selection=True)
COLOUR_MODES = {
    "root-to-tip": "Root to tip",
    "strand": "Per-strand random",
    "clump": "Clump membership",
    "displacement": "Displacement from rest",
    "hair": "Shaded hair",
}
DRAG_PERCENT = 10.0  # children drawn while a brush drags (XGen's preview density)
RELEASE_PERCENT = 100.0  # … and once the mouse is released
BRUSH_SHARE = 0.1  # a new groom's brush radius, of its largest side: about Blender's 50 px brush at
# the framed view, which is how artists start (a quarter of the side, as before, combed half the
# bear at once and made every move a whole-groom run: 120 ms against 28 at this size)


class Scene(QObject):
    """One groom being edited: rest strands, pipeline, brush settings and display settings."""

    groom_loaded = Signal()  # new strands: topology may have changed, re-upload everything
    points_changed = Signal()  # same strands at new positions: re-upload positions only
    params_changed = Signal(object)  # FrozenParams
    tool_changed = Signal()  # the brush, its radius, strength, falloff, symmetry …
    mask_changed = Signal()  # the mask or the painted clump strengths changed (their colours show them)
    selection_changed = Signal(bool)  # the selected or hidden strands changed (True: hidden ones too)
    refused = Signal(str)  # a stroke the brush cannot make, in words for the status bar
    display_changed = Signal()  # colour mode, ramp or line width
    mesh_changed = Signal()
    path_changed = Signal()
    drawn_changed = Signal()  # the drawn strands' topology changed (children density, guides shown)
    engine_starting = Signal()  # the pipeline is about to be built (may compile: show a wait)
    engine_started = Signal()
    up_axis_changed = Signal()  # the document's up axis (Y or Z): the view turns, engines follow

    def __init__(
        self,
        groom: Groom,
        params: FrozenParams | None = None,
        parent: QObject | None = None,
        *,
        engine_ready: bool = True,
        hair: GroomSide | None = None,
    ):
        """``hair``: the document's groom side (the window's); None: one of the scene's own, on
        an undo stack of its own. ``groom`` (and ``params``) replace its groom unless it is
        ``groom`` already."""
        super().__init__(parent)
        self.engine_ready = engine_ready
        # The studio keeps strand lengths after clumping (FrozenParams' own default is the
        # paper's printed ClumpWithGaps, which stretches them).
        params = params if params is not None else STUDIO_PARAMS
        if hair is None:
            hair = GroomSide(UndoStack(), GroomState(groom, params))
        elif hair.state.rest is not groom:
            hair.reset(GroomState(groom, params))
        self.hair = hair
        self._shown: GroomState | None = None  # the document's state the views show
        self._seen_pipeline: FrozenPipeline | None = None
        self._followed: tuple | None = None  # (key, binding): the children of the guides planted / removed
        self.show_guides = True
        # A first start clumps the children once the warm-up has cached their kernels (until
        # then the render hair shows unclumped, rather than the window freezing to compile them)
        self.children_clump_ready = engine_ready
        self.drag_percent = DRAG_PERCENT
        self.release_percent = RELEASE_PERCENT
        self.dragging = False
        self.frames_live = False  # an animation plays or is scrubbed: its children drawn unclumped
        # While points_changed is heard: the only strands of the result that moved since the
        # last points_changed (a brush move's region); None: any.
        self.moved: np.ndarray | None = None
        self._subsets: dict[float, ChildBinding] = {}
        self._cache: dict = {}  # per drawn density: its topology and colours (see cached)
        self._rest_drawn: np.ndarray | None = None
        self.last_children_ms = 0.0
        self.colour_mode = "root-to-tip"
        self.ramp = DEFAULT_RAMP
        self.line_width = 2.0
        self.path: Path | None = None
        self.tool = BrushTool()
        self.locked = np.zeros(0, dtype=bool)  # the masked strands (a copy of the pipeline's)
        self.clump_strength = np.ones(0)  # each strand's painted clump strength (a copy too)
        self.selected = np.ones(0, dtype=bool)  # the selected strands (a copy of the pipeline's)
        self.hidden = np.zeros(0, dtype=bool)  # … and the hidden ones
        self.hidden_version = 0  # counts changes of ``hidden`` (what the drawn strands are made for)
        self.shown_cache: tuple | None = None  # :func:`app.ui.selection_look.shown_part`'s
        self.last_update_ms = 0.0
        #: Callables naming what holds the strands as they are (e.g. an animation of them), or
        #: None: brushes that add or remove strands are refused while one names something.
        self.strand_holders: list = []
        # what a first stroke needs, prepared at the next idle turn after an engine is built
        self._prepare_timer = QTimer(self)
        self._prepare_timer.setSingleShot(True)
        self._prepare_timer.timeout.connect(self.prepare_strokes)
        # a stroke's moves run in a worker thread; whatever else uses the pipeline drains it first
        self.moves = MoveEngine(self, self)
        self._show_groom()
        self._shown = hair.state
        hair.observe(self._on_hair)

    # -- the document ----------------------------------------------------------------------
    @property
    def rest(self) -> Groom:
        """The groom as authored (the document's, with its metadata and up axis)."""
        return self.hair.state.rest

    @property
    def pipeline(self) -> FrozenPipeline | None:
        """The document's engine in the document's strokes (None until :meth:`start_engine` on a
        first start). A new engine prepares what a first stroke needs at the next idle turn."""
        if not self.engine_ready:
            return None
        p = self.hair.pipeline
        if p is not self._seen_pipeline:
            self._seen_pipeline = p
            self._prepare_timer.start(0)
        return p

    @property
    def mesh(self) -> Mesh | None:
        """The groom's head or scalp mesh (None: none): drawn under the hair, the surface the
        brushes slide on, plant on and collide with."""
        return self.hair.state.mesh

    @property
    def binding(self) -> ChildBinding | None:
        """Render hair interpolated from the groom (its strands the guides), or None."""
        return self.hair.state.children

    @property
    def clump_children(self) -> bool:
        """ClumpWithGaps among the children once the mouse is released."""
        return self.hair.state.clump_children

    def _on_hair(self) -> None:
        """The document's groom side changed (an edit, an Undo, a Redo, a file opened): the views
        follow, each signal only for what changed."""
        new, old = self.hair.state, self._shown
        if new is old:
            return
        self._shown = new
        self.moves.drain()
        relabel = (
            new.rest is not old.rest
            and new.rest.points is old.rest.points
            and new.rest.topology == old.rest.topology
        )
        if new.rest is not old.rest and not relabel:
            self._show_groom()
            self.groom_loaded.emit()
        elif relabel:
            self.up_axis_changed.emit()
        if new.params != old.params:
            self.params_changed.emit(new.params)
        if new.mesh is not old.mesh:
            self.mesh_changed.emit()
        if new.children is not old.children or new.clump_children != old.clump_children:
            self._followed = None
            self._subsets = {}
            self._cache = {}
            self._rebuild_drawn()
            self.drawn_changed.emit()
        if self.engine_ready:
            self._stroke_step(lambda: self.pipeline.result)
        else:
            self.result = new.rest
            self._children_moved()
            self.points_changed.emit()

    # -- strands -----------------------------------------------------------------------
    def _show_groom(self) -> None:
        """A new groom shown: its result, centre, brush size, per-strand state, drawn strands."""
        groom = self.rest
        self.result: Groom = self.pipeline.result if self.engine_ready else groom
        lo, hi = groom.bounds
        self.centre = ((lo.astype(np.float64) + hi) * 0.5).astype(np.float32)
        extent = float(np.max(hi - lo))
        self.tool.reset_radius(BRUSH_SHARE * extent if extent > 0 else 1.0)
        self.tool.mirror_x = None  # the new groom's own centre
        self.locked = np.zeros(groom.strand_count, dtype=bool)
        self.clump_strength = np.ones(groom.strand_count)
        self.selected = np.ones(groom.strand_count, dtype=bool)
        self.hidden = np.zeros(groom.strand_count, dtype=bool)
        self.hidden_version += 1
        self._followed = None
        self._subsets = {}
        self._cache = {}
        self._rebuild_drawn()

    def load(
        self,
        groom: Groom,
        path: str | Path | None = None,
        params: FrozenParams | None = None,
        mesh: Mesh | None = None,
    ) -> None:
        """Replace the groom being edited (strokes are dropped; the parameters stay unless
        ``params`` gives new ones, e.g. a project's, which may only fit the new strands). The
        head mesh is the new groom's own, ``mesh`` (None: it has none): a surface belongs to its
        groom, never to the window."""
        params = self.params if params is None else params
        self.open(GroomState(groom, params, None, mesh), path)

    def open(self, state: GroomState, path: str | Path | None = None) -> None:
        """Show another document's groom side (a file or project opened): not an undo step; the
        caller starts a new history."""
        self.moves.drain()
        self.path = None if path is None else Path(path)
        same = state.rest is self.rest
        self.hair.reset(state)  # (the views follow: see _on_hair)
        if same:  # the same strands opened again: shown afresh all the same
            self._show_groom()
            self.groom_loaded.emit()
            if self.engine_ready:
                self._stroke_step(lambda: self.pipeline.result)
        self.tool_changed.emit()
        self.path_changed.emit()

    def set_path(self, path: str | Path | None) -> None:
        p = None if path is None else Path(path)
        if p != self.path:
            self.path = p
            self.path_changed.emit()

    def start_engine(self) -> None:
        """Build the pipeline of a scene made with ``engine_ready=False`` (nothing when ready):
        the groom takes the frozen look with the parameters edited meanwhile."""
        if self.engine_ready:
            return
        self.engine_starting.emit()
        t0 = time.perf_counter()
        self.engine_ready = True
        try:
            self.result = self.pipeline.result
        except BaseException:
            self.engine_ready = False
            raise
        self._children_moved()  # the render hair follows the frozen guides
        self._sync_mask()
        self.last_update_ms = (time.perf_counter() - t0) * 1e3
        self.params_changed.emit(self.params)
        self.points_changed.emit()
        self.engine_started.emit()

    def prepare_strokes(self) -> None:
        """The engine computes and allocates now what a first brush move would otherwise wait
        for (:meth:`~hairtool.frozen.pipeline.FrozenPipeline.prepare_strokes`)."""
        if self.pipeline is not None:
            self.pipeline.prepare_strokes()

    @property
    def up_axis(self) -> str:
        """The groom's up axis, "Y" or "Z": its file's (a USD stage's upAxis), or the artist's
        choice for formats that have none. It lives in the groom's metadata, so the engines
        (puff's head sphere, simulation, anime cycles) and every save read it from there."""
        return self.rest.metadata.up_axis

    def set_up_axis(self, axis: str) -> None:
        """Say which axis is up (the points stay where they are: a relabelling, as a USD stage's
        upAxis is): one document step; the strokes are replayed on the relabelled groom (brushes
        read the up axis), so the groom looks as a save of it reopens."""
        self.moves.drain()
        self.hair.set_up_axis(axis)

    @property
    def is_planar(self) -> bool:
        return self.rest.is_planar

    def align(self, cursor: np.ndarray) -> Groom:
        """One mouse move of the align tool: align → freeze → clump, timed in ms."""
        self.moves.drain()
        self.start_engine()
        t0 = time.perf_counter()
        self.result = self.pipeline.align(
            np.asarray(cursor, dtype=np.float64), self.radius, self.intensity, self.align_mode
        )
        self._children_moved()
        self.last_update_ms = (time.perf_counter() - t0) * 1e3
        self.points_changed.emit()
        return self.result

    def mirror_plane_x(self) -> float:
        """x of the X-symmetry plane: the artist's, or the centre of the sphere fitted to the roots."""
        if self.tool.mirror_x is not None:
            return self.tool.mirror_x
        if self.pipeline is not None:
            return float(self.pipeline.scalp_centre[0])
        return float(scalp_centre(self.rest)[0])

    def brush_move(
        self,
        cursor: np.ndarray,
        direction: np.ndarray = (0.0, 0.0, 0.0),
        view: np.ndarray | None = None,
        invert: bool = False,
        check_touch: bool = True,
        start: bool = False,
        pressure: float = 1.0,
        add: bool = False,
        eye: np.ndarray | None = None,
    ) -> bool:
        """One mouse move of the current brush (its mirror too with symmetry on), applied through
        the pipeline in one call; ``direction`` the mouse's motion in the world, ``view`` the
        camera's direction at the cursor, ``invert`` Ctrl held. Returns whether the brush
        reached a strand (its circle held a vertex; False unchecked with ``check_touch`` off).
        ``start``: the stroke's first move; ``pressure`` a pen's (1 for a mouse); ``add`` Shift
        held (select adds to the selection instead of starting a new one); ``eye`` a perspective
        camera's eye (None: orthographic), recorded by the samples. A move the
        engine refuses (a delete that would leave no strand) changes nothing and says why
        (``refused``)."""
        self.moves.drain()
        self.start_engine()
        plane = self.mirror_plane_x()
        samples = self.tool.samples(cursor, direction, view, plane, invert, start, pressure, add, eye)
        if samples:
            try:
                self.apply_samples(samples)
            except HairtoolError as e:
                self.refused.emit(f"{LABELS.get(self.tool.brush, self.tool.brush)}: {e}")
                return False
        else:  # a comb standing still: nothing to apply; the view still follows the cursor
            self.points_changed.emit()
        return check_touch and self.tool.touches(self.pipeline.aligned.points, cursor, plane, pressure)

    def apply_samples(self, samples: list) -> None:
        """Samples of any brush (a replayed stroke log) in one pipeline call."""
        self.moves.drain()
        self._stroke_step(lambda: self.pipeline.apply_samples(samples))

    def stroke_refusal(self) -> str | None:
        """Why a stroke of the current brush cannot start now (None: it can): slide needs the
        head mesh; brushes that add or remove strands wait while an animation holds the strands
        (render hair follows the guides they plant and remove: see :meth:`children_binding`)."""
        label = LABELS.get(self.tool.brush, self.tool.brush)
        if self.tool.brush in NEED_SURFACE and (self.pipeline is None or self.pipeline.surface is None):
            return f"{label} works on the head's surface: load its mesh first (File → Load head mesh…)"
        if self.tool.only_selected and self.tool.brush in FOLLOW_SELECTION:
            if not (self.selected & ~self.hidden).any():
                return (f"{label}: no shown strand is selected: Select ▸ All (A) selects them, or "
                        "switch off Affect selection only")  # fmt: skip
        if self.tool.brush not in CHANGE_STRANDS:
            return None
        reasons = [r for r in (h() for h in self.strand_holders) if r]
        if not reasons:
            return None
        return f"{label} changes the strands, but {' and '.join(reasons)}: remove it first"

    def _stroke_step(self, step, moved: np.ndarray | None = None) -> None:
        """``step()`` (a pipeline call that changes strokes, so maybe the mask or the strands)
        on the running engine, timed; the render hair, the mask and the views follow.
        ``moved``: the only strands of the result the step may have changed (None: any), told
        to the views as :attr:`moved` while they hear :attr:`points_changed`."""
        self.start_engine()
        t0 = time.perf_counter()
        topology, children = self.result.topology, self.children_binding()
        self.result = step()
        # strands deleted or planted (or brought back by an undo): the render hair follows them
        if self.result.topology != topology or self.children_binding() is not children:
            self._cache = {}
            self._subsets = {}
            self._rest_drawn = None
            self._rebuild_drawn()
            self.drawn_changed.emit()
        self._children_moved()
        self._sync_mask()
        self.last_update_ms = (time.perf_counter() - t0) * 1e3
        same = self.result.topology == topology and not self.has_children
        self.moved = moved if same else None
        try:
            self.points_changed.emit()
        finally:
            self.moved = None

    def _sync_mask(self) -> None:
        locked, clump = self.pipeline.locked, self.pipeline.clump_strength
        if not (np.array_equal(locked, self.locked) and np.array_equal(clump, self.clump_strength)):
            self.locked, self.clump_strength = locked, clump
            self.mask_changed.emit()
        selected, hidden = self.pipeline.selected, self.pipeline.hidden
        hid = not np.array_equal(hidden, self.hidden)
        if hid or not np.array_equal(selected, self.selected):
            self.selected, self.hidden = selected, hidden
            self.hidden_version += hid
            self.selection_changed.emit(hid)

    def selection_step(self, sample: SelectionSample, text: str = "") -> bool:
        """One selection step (:class:`~hairtool.frozen.selection.SelectionSample`: select all,
        box, hide …) as a document step named ``text``; False, logging nothing, where it changes
        nothing or would hide every strand (the viewport draws at least one)."""
        self.moves.drain()
        self.start_engine()
        try:
            return self.hair.select(sample, text)
        except ParameterError:
            self.refused.emit("Hide: that would hide every strand, leaving nothing to see or groom")
            return False

    def set_only_selected(self, on: bool) -> None:
        """Brushes keep to the selected strands (Blender's selection toggle of sculpt mode)."""
        if bool(on) != self.tool.only_selected:
            self.tool.only_selected = bool(on)
            self.tool_changed.emit()

    def snapshot(self) -> GroomState:
        """The document's groom state before a stroke (what :meth:`end_stroke` records from);
        strokes need the engine running."""
        self.moves.drain()
        self.start_engine()
        return self.hair.state

    def end_stroke(self, before: GroomState, text: str | None = None) -> GroomState:
        """The stroke that ran on the engine since ``before`` becomes one document step (named
        after the brush, or ``text``; none when nothing was applied), its brush-local moves
        settled (they left the bytes a replay gives: nothing is clumped again); returns the
        state after."""
        self.moves.drain()
        if text is None:
            text = f"{LABELS.get(self.tool.brush, self.tool.brush)} stroke"
        p = self.pipeline
        if p is not None and p.unsettled:
            p.settle()  # (first: the document's step holds the settled strokes)
        self.hair.record(before, text)
        self.hair.end_stroke()
        if self.engine_ready and self.pipeline.result is not self.result:  # (moves dropped)
            self._stroke_step(lambda: self.pipeline.result)
        return self.hair.state

    # -- render hair ---------------------------------------------------------------------
    def set_binding(
        self, binding: ChildBinding | None, clump: bool | None = None, text: str | None = None
    ) -> None:
        """Render hair interpolated from the groom, which becomes its guides (None: no children).
        The engine and the brushes keep running on the guides; the children follow. ``clump``:
        Clump children for them; None: on for grown children, off for authored hair
        (:func:`hairtool.guides.binding.clumps_by_default`). ``text``: an undo step of that
        name; None: part of the document as opened (a sample's or a project's render hair),
        which is a step only once the history holds others."""
        if binding is not None and binding.rest_guides.topology != self.rest.topology:
            raise ParameterError(
                "binding",
                f"children bound to {binding.rest_guides.strand_count} guides",
                f"children bound to this groom's {self.rest.strand_count} strands",
            )
        self.moves.drain()
        if text is None and self.hair.stack.count == 0:
            from hairtool.guides.binding import clumps_by_default

            on = clump
            if on is None:
                on = self.clump_children if binding is None else clumps_by_default(binding)
            self.hair.reset(dataclasses.replace(self.hair.state, children=binding, clump_children=bool(on)))
        else:
            self.hair.set_children(binding, text or "Render hair", clump)

    def children_binding(self) -> ChildBinding | None:
        """The render hair of the guides as they are now: :attr:`binding` itself while every
        guide it was bound to is there; after add, delete or density strokes, its children
        following the guides planted and removed (:func:`hairtool.guides.follow.follow_guides`:
        a removed guide's children go, a planted one gets its own), made once per state."""
        b = self.binding
        if b is None or self.pipeline is None:
            return b
        origin = self.pipeline.origin
        if len(origin) == b.rest_guides.strand_count and np.array_equal(origin, np.arange(len(origin))):
            return b
        aligned = self.pipeline.aligned
        key = (id(b), origin.tobytes(), aligned.roots[origin < 0].tobytes())
        if self._followed is None or self._followed[0] != key:
            from hairtool.guides.follow import follow_guides, guides_now

            guides = guides_now(b.rest_guides, aligned, origin)
            self._followed = (key, follow_guides(b, guides, origin, self.pipeline.surface))
        return self._followed[1]

    @property
    def has_children(self) -> bool:
        return self.binding is not None

    def set_clump_children(self, on: bool) -> None:
        """ClumpWithGaps among the drawn children (at their own automatic radius, with the
        engine's passes, gaps and length rule) whenever the mouse is up, and in what a save
        writes (one document step). Off while a brush drags: the preview shows them unclumped,
        as XGen's does."""
        self.moves.drain()
        self.hair.set_clump_children(on)

    def set_children_clump_ready(self) -> None:
        """The children's clumping kernels are cached now (a first start's warm-up): Clump
        children clumps the render hair from here on."""
        if self.children_clump_ready:
            return
        self.children_clump_ready = True
        if self.binding is not None and self.clump_children and not self.dragging:
            self._rebuild_drawn()
            self.drawn_changed.emit()

    def _child_clump(self):
        from hairtool.guides.render import ChildClump

        return ChildClump.following(self.params)

    def children_clump(self):
        """The children's :class:`~hairtool.guides.render.ChildClump` as Clump children sets it
        (the engine's passes, gaps and length rule), or None while it is off: what saves and
        exports write."""
        return self._child_clump() if self.clump_children else None

    def _clumps_drawn(self) -> bool:
        """Whether the drawn children are clumped now (not while a brush drags, and on a first
        start not before the warm-up has their kernels)."""
        return self.clump_children and self.children_clump_ready and not self.dragging

    def set_show_guides(self, on: bool) -> None:
        if bool(on) != self.show_guides:
            self.show_guides = bool(on)
            self._rebuild_drawn()
            self.drawn_changed.emit()

    def set_display_percent(self, drag: float | None = None, release: float | None = None) -> None:
        """The share of the children drawn while dragging and after release, in percent (0, 100]."""
        for name, value in (("drag display percentage", drag), ("release display percentage", release)):
            if value is not None and (not np.isfinite(value) or not 0.0 < value <= 100.0):
                raise ParameterError(name, value, "a percentage in (0, 100]")
        changed = False
        if drag is not None and float(drag) != self.drag_percent:
            self.drag_percent, changed = float(drag), changed or self.dragging
        if release is not None and float(release) != self.release_percent:
            self.release_percent, changed = float(release), changed or not self.dragging
        if changed:
            self._rebuild_drawn()
            self.drawn_changed.emit()

    def set_dragging(self, on: bool) -> None:
        """A brush stroke begins (children at the drag percentage) or ends (release density)."""
        if bool(on) == self.dragging:
            return
        self.dragging = bool(on)
        if self.binding is not None and (self.drag_percent != self.release_percent or self.clump_children):
            self._rebuild_drawn()
            self.drawn_changed.emit()

    @property
    def display_percent(self) -> float:
        return self.drag_percent if self.dragging else self.release_percent

    def drawn_binding(self) -> ChildBinding | None:
        """The children drawn now: p % of them (the drag or the release percentage), evenly
        spaced over the binding's order (its scattering is random, so they cover the scalp)."""
        b = self.children_binding()
        if b is None:
            return None
        p = self.display_percent
        if p >= 100.0:
            return b
        sub = self._subsets.get(p)
        if sub is None:
            n = b.child_count
            m = max(1, round(n * p / 100.0))
            ids = (np.arange(m, dtype=np.int64) * n) // m
            sub = self._subsets[p] = b.subset(ids)
        return sub

    def cached(self, key: tuple, make):
        """``make()`` once per drawn density and ``key`` (e.g. the ramp colours of 3 million
        vertices), forgotten when the groom or its children change."""
        full = (self.display_percent, self.show_guides, *key)
        if full not in self._cache:
            self._cache[full] = make()
        return self._cache[full]

    def _build_drawn(self) -> None:
        """The drawn children rebuilt from the guides' current shapes into ``drawn_points``
        (the guides after them when shown): one array per density, written in place on every
        move, so neither a drag nor a release allocates (or concatenates) millions of points."""
        from hairtool.guides.children import build_points, moved_guides

        b = self.drawn_binding()
        guides = self.result.vertex_count if self.show_guides else 0
        drawn = self.cached(("points",), lambda: np.empty((b.vertex_count + guides, 3), np.float32))
        # The guides the drawn children were built from: only the children of guides that moved
        # since are built again (none before the first build: NaN matches nothing).
        source = self.cached(
            ("built from",), lambda: np.full((self.result.vertex_count, 3), np.nan, np.float32)
        )
        t0 = time.perf_counter()
        if self._clumps_drawn():
            from hairtool.guides.render import RenderHair

            clump = self._child_clump()  # (the engine's settings are part of the key)
            clumper = self.cached(("clumped", clump), lambda: RenderHair(b, clump))
            drawn[: b.vertex_count] = clumper.update_points(self.result)
            source[...] = np.nan  # built whole: the next unclumped build starts afresh
        else:
            build_points(b, self.result, out=drawn[: b.vertex_count], moved=moved_guides(self.result, source))
            source[...] = self.result.points
        self.last_children_ms = (time.perf_counter() - t0) * 1e3
        if guides:
            drawn[b.vertex_count :] = self.result.points
        self.drawn_points = drawn

    def _rebuild_drawn(self) -> None:
        """What the viewport draws: the groom itself, or the children (then the guides, if
        shown, as the last strands)."""
        b = self.drawn_binding()
        if b is None:
            self.drawn_topology = self.result.topology
            self.drawn_points = self.result.points
            self.drawn_guides = self.result.strand_count
            return
        self._rest_drawn = None
        self._build_drawn()
        if self.show_guides:
            key = (self.display_percent, "guides")
            if key not in self._cache:  # one topology per density, so what hangs on it is kept
                self._cache[key] = Topology(np.concatenate([b.counts, self.result.counts]))
            self.drawn_topology = self._cache[key]
            self.drawn_guides = self.result.strand_count
        else:
            self.drawn_topology = b.topology
            self.drawn_guides = 0

    def _children_moved(self) -> None:
        if self.binding is None:
            self.drawn_points = self.result.points
            return
        self._build_drawn()

    def set_frames_live(self, on: bool) -> None:
        """An animation starts or stops playing or being scrubbed: meanwhile the children of its
        frames are drawn unclumped (clumping Sintel's 30,000 takes 0.3 s a frame); the frame it
        stops on and every exported one are clumped as the groom's are."""
        self.frames_live = bool(on)

    def drawn_for(self, guide_points: np.ndarray, *, kept: bool = False) -> np.ndarray:
        """The drawn strands' points for the guides at ``guide_points`` (an animation frame),
        the children clumped as the groom's are: not while an animation plays or is scrubbed,
        unless the frame is ``kept`` (an exported one)."""
        g = Groom(guide_points, self.result.topology)
        b = self.drawn_binding()
        if self._clumps_drawn() and (kept or not self.frames_live):
            from hairtool.guides.render import RenderHair

            clump = self._child_clump()
            # one of its own (the groom's keeps its last run): frame after frame redoes the
            # clumps of the guides that moved between them
            # (the children's roots carried by the guides', as the exported frames' are)
            frames = self.cached(("frames clumped", clump), lambda: RenderHair(b, clump, follow_roots=True))
            children = frames.update_points(g)  # (its own array: copied below)
            return np.concatenate([children, g.points]) if self.drawn_guides else children.copy()
        from hairtool.guides.children import build_points
        from hairtool.guides.root_motion import following

        children = build_points(following(b, g), g)
        return np.concatenate([children, g.points]) if self.drawn_guides else children

    def render_hair(self) -> Groom | None:
        """Every child at the guides' current shapes (full density; clumped when switched on),
        or None without children."""
        b = self.children_binding()
        if b is None:
            return None
        if self.clump_children:
            from hairtool.guides.render import RenderHair

            return RenderHair(b, self.children_clump()).update(self.result)
        return b.build(self.result)

    def export_groom(self) -> Groom:
        """What a save or export writes: the edited groom, or with children the render hair
        (tapered widths) and the guides as a second prim of purpose "guide"."""
        return self.export_snapshot()()

    def export_snapshot(self) -> Callable[[], Groom]:
        """:meth:`export_groom` in two halves: the immutable inputs taken now (cheap, on the GUI
        thread), the returned function building the groom from them later (in a save's worker),
        whatever the document becomes meanwhile."""
        result, binding = self.result, self.children_binding()
        if binding is None:
            return lambda: result
        clump, metadata = self.children_clump(), self.rest.metadata

        def build() -> Groom:
            from hairtool.guides.files import with_guides
            from hairtool.guides.render import RenderHair

            hair = binding.build(result) if clump is None else RenderHair(binding, clump).update(result)
            return with_guides(hair, result, metadata)

        return build

    # -- engine parameters ---------------------------------------------------------------
    @property
    def params(self) -> FrozenParams:
        return self.hair.state.params

    def set_params(self, params: FrozenParams, name: str = "", drag: object = None) -> None:
        """New engine parameters: one document step (``name``: the field changed, in the step's
        words; edits of one slider ``drag`` of that field are one step). On a first start they
        are kept for the engine when it starts."""
        self.moves.drain()
        if params == self.params:
            return
        t0 = time.perf_counter()
        text = f"Change {name.replace('_', ' ')}" if name else "Engine parameters"
        self.hair.set_params(params, text, None if drag is None else (name, drag))
        self.last_update_ms = (time.perf_counter() - t0) * 1e3

    def with_param(self, name: str, value: object) -> FrozenParams:
        """The current parameters with one field changed; ParameterError names a bad value."""
        return dataclasses.replace(self.params, **{name: value}).validate()

    # -- brush ---------------------------------------------------------------------------
    @property
    def brush(self) -> str:
        return self.tool.brush

    @property
    def radius(self) -> float:
        """The current brush's radius (groom units); each brush keeps its own."""
        return self.tool.radius[self.tool.brush]

    @property
    def intensity(self) -> float:
        """The current brush's strength in [0, 1] (its sign: :attr:`BrushTool.subtract`)."""
        return self.tool.strength[self.tool.brush]

    @property
    def align_mode(self) -> str:
        return self.tool.align_mode

    def set_brush(self, name: str) -> None:
        if name != self.tool.brush:
            self.tool.set_brush(name)
            self.tool_changed.emit()

    def set_radius(self, radius: float) -> None:
        if not np.isfinite(radius) or radius <= 0:
            raise ParameterError("radius", radius, "a positive number")
        if radius != self.radius:
            self.tool.radius[self.tool.brush] = float(radius)
            self.tool_changed.emit()

    def set_intensity(self, intensity: float) -> None:
        if not np.isfinite(intensity) or not 0.0 <= intensity <= 1.0:
            raise ParameterError("strength", intensity, "a number in [0, 1]")
        if intensity != self.intensity:
            self.tool.strength[self.tool.brush] = float(intensity)
            self.tool_changed.emit()

    def set_align_mode(self, mode: str) -> None:
        if mode not in ALIGN_MODES:
            raise ParameterError("mode", mode, f"one of {', '.join(ALIGN_MODES)}")
        if mode != self.tool.align_mode:
            self.tool.align_mode = mode
            self.tool_changed.emit()

    def set_subtract(self, brush: str, on: bool) -> None:
        """Shrink instead of grow (length), erase instead of paint (mask, clump)."""
        if brush not in SIGNED:
            raise ParameterError("brush", brush, "one of " + ", ".join(SIGNED))
        if bool(on) != self.tool.subtract[brush]:
            self.tool.subtract[brush] = bool(on)
            self.tool_changed.emit()

    def set_falloff(self, falloff) -> None:
        """A preset name ("smooth", "linear", "constant") or curve points [[t, w], ...]."""
        f = check_falloff(falloff)
        if f != self.tool.falloff:
            self.tool.falloff = f
            self.tool_changed.emit()

    def set_symmetry(self, on: bool) -> None:
        if bool(on) != self.tool.symmetry:
            self.tool.symmetry = bool(on)
            self.tool_changed.emit()

    def set_mirror_x(self, x: float | None) -> None:
        """The X-symmetry plane x = ``x`` (None: through the scalp's centre)."""
        if x is not None and not np.isfinite(x):
            raise ParameterError("mirror plane", x, "a finite x")
        x = None if x is None else float(x)
        if x != self.tool.mirror_x:
            self.tool.mirror_x = x
            self.tool_changed.emit()

    def set_front_only(self, on: bool) -> None:
        if bool(on) != self.tool.front_only:
            self.tool.front_only = bool(on)
            self.tool_changed.emit()

    def set_add_count(self, count: int) -> None:
        """Strands the add brush plants per mouse move."""
        from hairtool.frozen.brushes import MAX_COUNT

        if isinstance(count, bool) or int(count) != count or not 1 <= count <= MAX_COUNT:
            raise ParameterError("strands per move", count, f"a whole number in [1, {MAX_COUNT}]")
        if int(count) != self.tool.add_count:
            self.tool.add_count = int(count)
            self.tool_changed.emit()

    def set_delete_any_segment(self, on: bool) -> None:
        """Delete takes the strands with any segment under the brush (Blender's rule), or off:
        only those whose root is."""
        if bool(on) != self.tool.delete_any_segment:
            self.tool.delete_any_segment = bool(on)
            self.tool_changed.emit()

    def set_spacing(self, spacing: float) -> None:
        """The distance the density brush leaves between roots (groom units)."""
        if not np.isfinite(spacing) or spacing <= 0:
            raise ParameterError("spacing", spacing, "a positive distance between roots")
        if float(spacing) != self.tool.spacing:
            self.tool.spacing = float(spacing)
            self.tool_changed.emit()

    def set_pressure(self, what: str, on: bool) -> None:
        """A pen's pressure scales the current brush's ``what`` ("radius" or "strength"; each
        brush has its own toggles, as Blender's pressure buttons)."""
        toggles = {"radius": self.tool.pressure_radius, "strength": self.tool.pressure_strength}
        if what not in toggles:
            raise ParameterError("pressure toggle", what, "radius or strength")
        if bool(on) != toggles[what].get(self.tool.brush, False):
            toggles[what][self.tool.brush] = bool(on)
            self.tool_changed.emit()

    def set_collide(self, on: bool) -> None:
        """The current brush keeps strands out of the head mesh (each brush has its own)."""
        if bool(on) != self.tool.collide.get(self.tool.brush, True):
            self.tool.collide[self.tool.brush] = bool(on)
            self.tool_changed.emit()

    # -- display -------------------------------------------------------------------------
    def set_colour_mode(self, mode: str) -> None:
        if mode not in COLOUR_MODES:
            raise ParameterError("colour mode", mode, f"one of {', '.join(COLOUR_MODES)}")
        if mode != self.colour_mode:
            self.colour_mode = mode
            self.display_changed.emit()

    def set_ramp(self, name: str) -> None:
        if name != self.ramp:
            self.ramp = name
            self.display_changed.emit()

    def set_line_width(self, width: float) -> None:
        if not np.isfinite(width) or not 0.1 <= width <= 20.0:
            raise ParameterError("line width", width, "a number of pixels in [0.1, 20]")
        if width != self.line_width:
            self.line_width = float(width)
            self.display_changed.emit()

    def set_mesh(self, mesh: Mesh | None, text: str = "Head mesh") -> bool:
        """The groom's head or scalp mesh (None: none): one document step; the strokes are
        replayed on it (slides, plants, collisions). Refused, saying why, when strokes need a head
        and ``mesh`` is none or unusable: the old head stays (False)."""
        self.moves.drain()
        try:
            self.hair.set_mesh(mesh, text)
        except HairtoolError as e:
            self.refused.emit(f"the strokes that need a head keep the one they were made on ({e})")
            return False
        return True

    def displacement(self) -> np.ndarray:
        """``(V,)`` float64 distance of each drawn vertex from its rest position (scene units)."""
        if self.binding is not None:
            if self._rest_drawn is None or len(self._rest_drawn) != len(self.drawn_points):
                rest = self.drawn_binding().build().points
                self._rest_drawn = np.concatenate([rest, self.rest.points]) if self.drawn_guides else rest
            d = self.drawn_points.astype(np.float64) - self._rest_drawn
            return np.sqrt(np.einsum("ij,ij->i", d, d))
        rest = self.rest.points
        if self.result.topology != self.rest.topology:  # after a delete: the kept strands' rest
            rest = rest[vertex_ids_of(self.rest.topology, self.pipeline.origin)]
        d = self.result.points.astype(np.float64) - rest
        return np.sqrt(np.einsum("ij,ij->i", d, d))
