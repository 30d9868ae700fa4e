"""The interactive frozen-hair pipeline: FreezeDeform → UserAlign → ClumpWithGaps (Kim 2026).

This module is the stage engine: it keeps the frozen groom, the stroked state and the result,
and decides what to redo. A sample's effect and a log's replay are functions of explicit state
in :mod:`hairtool.frozen.replay`; brush-local moves are :mod:`hairtool.frozen.local_moves`;
strokes against the head are :mod:`hairtool.frozen.head_collision`.

Built for dragging in the studio:

- FreezeDeform always starts from the rest groom with noise hashed from (seed, strand, vertex),
  and is cached until a freeze parameter changes; it never feeds on its own output.
- Strokes persist: each brush sample (one mouse move of align, comb, smooth, length, puff,
  clump or mask, :mod:`hairtool.frozen.brushes`) is applied to the cached stroked state and
  appended to a log. When the frozen groom changes (new k_s, k_b, seed …) the log is replayed on
  it, so strokes survive parameter changes. Masked strands are locked for every brush; a sample
  with a ``view`` also locks, for itself only, the strands facing away from that camera.
- The clump brush paints a per-strand clump strength (1 everywhere until painted), kept with the
  mask in the state and the snapshots, which ClumpWithGaps scales each strand's step by.
- Clumping is recomputed from the aligned state at every update and never accumulates.
- Brush-local moves (:mod:`hairtool.frozen.local_moves`, :mod:`hairtool.frozen.local`): a
  sample of align, comb, smooth, length, puff, pinch, clump or mask runs only on the strands
  with a vertex within its radius (found in a vertex grid kept across moves), and
  ClumpWithGaps only on the vertices whose clumping the change can reach (the length pass on
  their strands), so the result is a full run's bytes; the rest of the groom is read, never
  written, and keeps its last result bit for bit. The other brushes, parameter changes, undo
  and replays run on the whole groom (a full run, after which the grid follows what moved).
- Delete (:mod:`hairtool.frozen.brushes.delete`) changes the strands: a stage like the others, applied
  to the stroked state, which takes the kept strands with their mask and clump strength; the
  pipeline records the rest strand each remaining strand comes from (:attr:`FrozenPipeline.origin`),
  kept in the snapshots, so undo brings the deleted strands back bit for bit and a replay deletes
  the same ones. The result has the stroked state's strands, not necessarily the rest groom's.
- With a head surface (:meth:`FrozenPipeline.set_surface`), a sample with ``collide`` (the
  default) leaves no vertex it moved inside the head (:mod:`hairtool.frozen.collide`).
- Selection (:mod:`hairtool.frozen.selection`): every strand is selected or not, shown or
  hidden, kept per strand with the mask (deleted with its strand; a planted strand comes
  selected and shown) and in the snapshots. Selection steps (:class:`SelectionSample`) and the
  selection brush are samples of the log like the others; hidden strands are locked for every
  sample, and a sample with ``only_selected`` also locks the unselected ones.
- Snake hook hooks strands at a stroke's first sample (``start``) and drags them through the
  stroke's later samples; the hooked weights are part of the state (one set per sample of a
  stroke's start: its mirrored sample has its own, used in turn).
"""

from __future__ import annotations

import functools
import sys
import time
from collections.abc import Sequence
from dataclasses import dataclass, field, fields, replace

import numpy as np
from numpy.typing import ArrayLike

from hairtool.errors import ParameterError
from hairtool.frozen import local_moves
from hairtool.frozen.align import check_align_params
from hairtool.frozen.brushes.align import AlignSample
from hairtool.frozen.brushes.sample import BrushSample, check_view
from hairtool.frozen.brushes.scalp import root_normals, scalp_centre
from hairtool.frozen.brushes.slide import Surface
from hairtool.frozen.brushes.spec import StrokeMemory
from hairtool.frozen.clump import (
    ClumpWorkspace,
    check_clump_params,
    clump_points,
    record_key,
    vertex_strength,
)
from hairtool.frozen.freeze import MAX_VARIATION, check_freeze_params, freeze, strand_multipliers
from hairtool.frozen.head_collision import HeadCollision
from hairtool.frozen.local import LocalClump
from hairtool.frozen.local_moves import ClumpRun, LocalMoves
from hairtool.frozen.move_points import held_by_at_most, may_write
from hairtool.frozen.noise import check_seed, draw_seed
from hairtool.frozen.replay import NO_MEMORY, Sample, StrokeSetting, apply_sample, replay, selection_after
from hairtool.frozen.selection import SelectionSample
from hairtool.frozen.strand_clumps import auto_clump_radius, strand_clumps
from hairtool.frozen.strand_state import StrandState
from hairtool.groom import Groom

PREPARED_REGION = 0.05  # of the vertices: the region lists' room :meth:`FrozenPipeline.prepare_strokes`
# makes (the studio's brush on the bear: regions of 3-4 %)
PREPARED_HEAD = 40_000  # vertices at most whose distances to the head prepare_strokes asks for
# (Sintel's 7,296: 70 ms on the 2-core VM, which a first stroke paid; a dense groom's would
# hold the idle GUI thread for seconds, so its first stroke still asks)


@dataclass(frozen=True, eq=False)
class FrozenParams:
    """Everything the pipeline needs besides the strokes. Angles in radians, lengths in groom units.

        ``strand_variation``: spread of the per-strand stiffness multiplier (0 … 4) or an ``(S,)``
        array of multipliers. ``clump_radius`` None: :func:`~hairtool.frozen.strand_clumps.auto_clump_radius`.
        ``clump_step`` None: :func:`~hairtool.frozen.clump.auto_step` of the frozen groom, before any stroke
        (so that a stroke does not change how strongly the whole groom clumps while it drags, and
        the studio can redo ClumpWithGaps only near the strands it moves). ``keep_lengths``: after
    ClumpWithGaps every segment goes back to its length before it (off: the paper's printed form,
    which stretches segments). ``redraw_noise``: new
        freeze noise at every :meth:`update` (the paper's behaviour; flickers while dragging).
    """

    stretch_stiffness: float = 7.0
    bend_stiffness: float = 7.0
    max_bend_angle: float = float(np.radians(30.0))
    seed: int = 0
    strand_variation: float | np.ndarray = 0.0
    freeze: bool = True
    clump: bool = True
    clump_radius: float | None = None
    clump_iterations: int = 3
    clump_step: float | None = None
    gap_mode: str = "printed"
    keep_lengths: bool = False
    redraw_noise: bool = False
    _key: tuple = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        sv = self.strand_variation
        sv_key = float(sv) if np.ndim(sv) == 0 else np.asarray(sv, np.float64).tobytes()
        values = tuple(
            sv_key if f.name == "strand_variation" else getattr(self, f.name) for f in fields(self)[:-1]
        )
        object.__setattr__(self, "_key", values)

    def validate(self) -> FrozenParams:
        """Raise :class:`~hairtool.errors.ParameterError` naming the first bad parameter."""
        check_freeze_params(self.stretch_stiffness, self.bend_stiffness, self.max_bend_angle)
        check_seed(self.seed)
        if np.ndim(self.strand_variation) == 0:
            v = float(self.strand_variation)
            if not np.isfinite(v) or not 0 <= v <= MAX_VARIATION:
                raise ParameterError("strand_variation", v, f"a number in [0, {MAX_VARIATION:g}] or an array")
        check_clump_params(
            1.0 if self.clump_radius is None else self.clump_radius,
            self.clump_iterations,
            self.clump_step,
            self.gap_mode,
        )
        return self

    def freeze_key(self) -> tuple:
        """What the frozen groom depends on."""
        return (self.freeze, *self._key[:5]) if self.freeze else (False,)

    def __eq__(self, other: object) -> bool:
        return isinstance(other, FrozenParams) and self._key == other._key

    def __hash__(self) -> int:
        return hash(self._key)

    def replace(self, **changes) -> FrozenParams:
        """These parameters with some changed (they are frozen: a change is a new object).

        Parameters
        ----------
        **changes
            Field names and their new values.

        Returns
        -------
        FrozenParams
            The changed copy (not validated: :meth:`validate` does that).
        """
        return replace(self, **changes)


REPLAY = ("replay",)  # the frozen groom no pipeline has: a snapshot made on it is replayed


@dataclass(frozen=True)
class FrozenSnapshot:
    """Undo/redo state: the stroke log, the per-strand state and the stroked points it left
    (shared, read-only), and the result shown then (a brush-local move's result is not a full
    run's: undo and redo bring back what was shown; None: clump the stroked points again).

    ``memory``: what a stroke-keeping brush held (a snake hook's hooks,
    :meth:`~hairtool.frozen.brushes.spec.StrokeMemory.frozen`). ``frozen_on``: the frozen groom
    the log was stroked on (its freeze key and noise draw): a pipeline whose frozen groom is
    another replays the log instead (:data:`REPLAY`, :meth:`replaying`: always).
    ``clumped_on``: the parameters ``result`` was clumped with (others: clumped again)."""

    log: tuple[Sample, ...]
    state: StrandState
    aligned: Groom
    result: Groom | None = None
    memory: tuple[tuple, int, bool] = NO_MEMORY
    frozen_on: tuple = REPLAY
    clumped_on: tuple = ()

    @classmethod
    def replaying(cls, log: Sequence[Sample], rest: Groom) -> FrozenSnapshot:
        """The strokes ``log`` alone: restoring it replays them on the pipeline's frozen groom.

        Parameters
        ----------
        log : sequence of samples
            The stroke log.
        rest : Groom
            The rest groom of the pipeline it will be restored on.

        Returns
        -------
        FrozenSnapshot
            A snapshot that is always replayed.
        """
        return cls(tuple(log), StrandState.fresh(rest.strand_count), rest)


class FrozenPipeline:
    """FreezeDeform → UserAlign → ClumpWithGaps on a rest groom, for interactive use.

    Every call that changes something returns the new result (a new, immutable groom), and the
    pipeline keeps the stroke log that :func:`~hairtool.frozen.strokes.read_strokes` files and
    the studio replay.

    Parameters
    ----------
    rest
        The groom as authored; FreezeDeform always starts from it.
    params
        The engine's parameters; None: the defaults of :class:`FrozenParams`.
    surface
        The head the slide, add and density brushes work on and every brush keeps hair out of;
        None: no head.
    """

    def __init__(
        self, rest: Groom, params: FrozenParams | None = None, surface: Surface | None = None
    ) -> None:
        self._rest = rest
        self._surface = surface  # the head the slide brush slides roots on
        self._params = (params or FrozenParams()).validate()
        strand_multipliers(rest.strand_count, self._params.strand_variation)  # shape check
        self._auto_h: float | None = None
        self._auto_step: tuple[tuple, float] | None = None  # (frozen groom's key, its auto step)
        self._log: list[Sample] = []
        self._state = StrandState.fresh(rest.strand_count)
        self._memory = StrokeMemory()  # what a brush keeps over its stroke (a snake hook's hooks)
        self._scalp_centre: np.ndarray | None = None
        self._root_normals: np.ndarray | None = None
        self._draw = 0
        self._workspace = ClumpWorkspace()
        self._workspace.record = True  # the record brush-local moves update
        self._moves = LocalMoves()  # what brush-local moves start from (after a full, recorded run)
        self._redone = 1.0  # share of the vertices the last clumping computed
        self._region: np.ndarray | None = None  # strands the last update redid (None: all)
        self._unsettled = False  # brush-local moves since the last full run
        self._timings = {"freeze": 0.0, "align": 0.0, "clump": 0.0, "total": 0.0}
        self._freeze_key: tuple | None = None
        self._frozen: Groom = rest
        self._aligned: Groom = rest
        self._result: Groom = rest
        self._refreeze()
        self._reclump()

    # -- state ---------------------------------------------------------------------------
    @property
    def rest(self) -> Groom:
        return self._rest

    @property
    def params(self) -> FrozenParams:
        return self._params

    @property
    def result(self) -> Groom:
        return self._result

    @property
    def frozen(self) -> Groom:
        """The FreezeDeform output (before any stroke)."""
        return self._frozen

    @property
    def aligned(self) -> Groom:
        """The aligned state (frozen + strokes), before clumping."""
        return self._aligned

    @property
    def strokes(self) -> tuple[Sample, ...]:
        return tuple(self._log)

    @property
    def locked(self) -> np.ndarray:
        """``(S,)`` the strands the mask brush has locked (a copy)."""
        return self._state.locked.copy()

    @property
    def selected(self) -> np.ndarray:
        """``(S',)`` the selected strands of the stroked state (a copy; all until a selection step)."""
        return self._state.selected.copy()

    @property
    def hidden(self) -> np.ndarray:
        """``(S',)`` the hidden strands of the stroked state (a copy), locked for every brush."""
        return self._state.hidden.copy()

    @property
    def origin(self) -> np.ndarray:
        """``(S',)`` the rest strand each strand of the stroked state (and the result) comes from,
        in order: the strands delete has removed are missing (a copy)."""
        return self._state.origin.copy()

    @property
    def clump_strength(self) -> np.ndarray:
        """``(S,)`` the clump strength the clump brush has painted, in [0, 1] (a copy)."""
        return self._state.clump_strength.copy()

    @property
    def root_normals(self) -> np.ndarray:
        """``(S, 3)`` outward scalp normals at the rest roots, for front-facing samples
        (:func:`~hairtool.frozen.brushes.root_normals`); index them by :attr:`origin` for the
        strands of the result."""
        if self._root_normals is None:
            self._root_normals = root_normals(self._rest)
        return self._root_normals

    @property
    def strand_normals(self) -> np.ndarray:
        """``(S', 3)`` :attr:`root_normals` of the strands of the stroked state and the result
        (a planted strand's: the surface normal at its root)."""
        return self._setting().strand_normals(self._aligned, self._state)

    def selection_after(self, sample: SelectionSample) -> tuple[np.ndarray, np.ndarray]:
        """``(selected, hidden)`` the selection step ``sample`` would leave, by the rule a
        replay applies (nothing changed here: the studio asks first whether it changes anything).

        Parameters
        ----------
        sample : SelectionSample
            The step: a box, an inversion, a hide or reveal, with its view and front-faces flag.

        Returns
        -------
        tuple of ndarray
            ``(S,)`` bool each: the strands selected and the strands hidden after the step.
        """
        return selection_after(self._setting(), self._aligned, self._state, sample)

    @property
    def scalp_centre(self) -> np.ndarray:
        """Centre of the sphere fitted to the rest roots: puff's outward normal, and the default
        X-symmetry plane (x = its x)."""
        if self._scalp_centre is None:
            self._scalp_centre = scalp_centre(self._rest)
        return self._scalp_centre

    @property
    def timings(self) -> dict[str, float]:
        """Milliseconds spent by the last update in each stage, and in total."""
        return dict(self._timings)

    @property
    def clump_radius(self) -> float:
        """h in use: the parameter, or 2× the median distance between neighbouring roots."""
        if self._params.clump_radius is not None:
            return float(self._params.clump_radius)
        if self._auto_h is None:
            self._auto_h = auto_clump_radius(self._rest)
        return self._auto_h

    @property
    def clump_step(self) -> float:
        """Δt²/m used by the last clumping (the parameter, or the frozen groom's automatic step)."""
        return self._workspace.step

    def _step(self) -> float:
        """The parameter, or :func:`~hairtool.frozen.clump.auto_step` of the frozen groom (cached)."""
        p = self._params
        if p.clump_step is not None:
            return float(p.clump_step)
        key = (self._freeze_key, self.clump_radius)
        if self._auto_step is None or self._auto_step[0] != key:
            # One iteration gives the step (the first sets it). In the pipeline's own workspace,
            # without a record: a groom without strokes then reuses this neighbour list.
            ws = self._workspace
            ws.record = False
            clump_points(self._frozen, self.clump_radius, 1, None, "off", 0, ws)
            self._auto_step = (key, ws.step)
        return self._auto_step[1]

    @property
    def neighbour_builds(self) -> int:
        """ClumpWithGaps neighbour lists built so far (a run on the points of the last one
        reuses its list, and one after a stroke updates it: :attr:`neighbour_updates`)."""
        return self._workspace.builds

    @property
    def neighbour_updates(self) -> int:
        """Neighbour lists brought up to date where strands moved, rather than built again
        (:mod:`hairtool.frozen.neighbour_update`)."""
        return self._workspace.updates

    @property
    def clump_redone(self) -> float:
        """Share of the vertices the last clumping computed (1: all; less: a brush-local move,
        :mod:`hairtool.frozen.local`)."""
        return self._redone

    @property
    def changed(self) -> np.ndarray | None:
        """Sorted ids of the strands of the result the last update may have changed (a brush-local
        move's region; the others keep their points bit for bit), or None: any strand (a full run)."""
        return None if self._region is None else self._region.copy()

    @property
    def local_clump(self) -> LocalClump | None:
        """The brush-local clumping the next move starts from (:class:`~hairtool.frozen.local.LocalClump`:
        its grid, record and list timings), or None where the next move runs in full."""
        return self._moves.clump

    @property
    def mean_neighbours(self) -> float:
        """Mean number of other-strand vertices within h per moving vertex in the last clumping."""
        return self._workspace.mean_neighbours

    @property
    def surface(self) -> Surface | None:
        """The head's surface (:class:`~hairtool.frozen.brushes.slide.Surface`) slide needs, or None."""
        return self._surface

    @functools.cached_property
    def _collision(self) -> HeadCollision:
        """Strokes against the head (:mod:`hairtool.frozen.head_collision`)."""
        return HeadCollision(self._rest)

    # -- operations ----------------------------------------------------------------------
    def set_surface(self, surface: Surface | None) -> Groom:
        """A new head surface; strokes that slid roots on the old one or collided with it are
        replayed on it (a log with slide strokes refuses to go without one, and keeps the old
        surface then).

        Parameters
        ----------
        surface : Surface or None
            The head (None: no head).

        Returns
        -------
        Groom
            The clumped result.
        """
        old, self._surface = self._surface, surface
        if self._log:
            try:
                self._replay()
            except BaseException:
                self._surface = old
                self._replay()
                raise
            self._reclump()
        return self._result

    def set_params(self, params: FrozenParams) -> Groom:
        """New parameters; the frozen groom is re-derived only if a freeze parameter changed,
        and the strokes are replayed on it.

        Parameters
        ----------
        params : FrozenParams
            The parameters (validated here).

        Returns
        -------
        Groom
            The clumped result.
        """
        params.validate()
        strand_multipliers(self._rest.strand_count, params.strand_variation)
        self._params = params
        self._timings = dict.fromkeys(self._timings, 0.0)
        self._refreeze()
        self._reclump()
        return self._result

    def align(
        self,
        cursor: ArrayLike,
        radius: float,
        intensity: float = 0.8,
        mode: str = "paper",
        view: ArrayLike | None = None,
    ) -> Groom:
        """One align sample (one mouse move); it persists. Returns the updated result. ``view``:
        the camera's viewing direction, for front-facing strands only (None: every strand).

        Parameters
        ----------
        cursor
            ``(3,)`` the cursor, in groom units.
        radius
            The tips within it of the cursor take part.
        intensity
            In [0, 1]: 1 turns a strand like a rod, 0 mostly its tip.
        mode
            ``"paper"`` or ``"preserve-length"`` (see :func:`~hairtool.frozen.align.align`).
        view
            ``(3,)`` the camera's viewing direction; None: every strand.

        Returns
        -------
        Groom
            The pipeline's new result: the strokes so far, clumped.

        Raises
        ------
        ParameterError
            A parameter is out of range; the sample is not logged.
        """
        c = check_align_params(cursor, radius, intensity, mode)
        v = check_view(view)
        cursor3 = (float(c[0]), float(c[1]), float(c[2]))
        sample = AlignSample(cursor3, float(radius), float(intensity), mode, v)
        return self.apply_samples([sample])

    def brush(self, sample: BrushSample) -> Groom:
        """One sample of a comb, smooth, length, puff, clump or mask brush; it persists (checked
        where it is applied: a refused sample leaves no trace in the log).

        Parameters
        ----------
        sample : BrushSample
            The sample.

        Returns
        -------
        Groom
            The clumped result.
        """
        return self.apply_samples([sample])

    def apply_samples(self, samples: Sequence[Sample], local: bool = True) -> Groom:
        """Samples of any brush (a stroke's, mirrored ones included), applied in order, then one
        clumping: what a replayed stroke log does. ``local``: a brush-local move where it can
        (:mod:`hairtool.frozen.local`); False: on the whole groom, as a replay after a parameter
        change does.

        Parameters
        ----------
        samples
            Align, brush and selection samples, in order.
        local
            Allow a brush-local move.

        Returns
        -------
        Groom
            The pipeline's new result: a full replay's bytes, brush-local moves included
            (:meth:`settle` then only marks them settled).

        Raises
        ------
        HairtoolError
            A sample is refused; none of ``samples`` is applied or logged.
        """
        self._timings = dict.fromkeys(self._timings, 0.0)
        if (
            local
            and samples
            and local_moves.ready(
                self._moves, self._aligned, samples, self._workspace.recorded, self._local_key
            )
        ):
            return self._apply_local(samples)
        t0 = time.perf_counter()
        hooks = self._hook_state()
        setting, g, state, memory = self._setting(), self._aligned, self._state, self._memory
        try:
            for sample in samples:
                g, state, memory = apply_sample(setting, g, state, memory, sample)
        except BaseException:  # a refused sample: none of these samples happened
            self._set_hooks(hooks)
            raise
        self._aligned, self._state, self._memory = g, state, memory
        self._log.extend(samples)
        self._timings["align"] = (time.perf_counter() - t0) * 1e3
        self._reclump()
        return self._result

    @property
    def unsettled(self) -> bool:
        """Whether the result comes from brush-local moves since the last full run or
        :meth:`settle`."""
        return self._unsettled

    def settle(self) -> Groom:
        """The result any replay of the strokes gives (the studio asks for it when the mouse is
        released). Brush-local moves leave exactly those bytes: each redoes every vertex its
        change can reach, and every other one is where a full run has it
        (:mod:`hairtool.frozen.local`; a move that cannot keep to that runs in full). So nothing
        is clumped again here: a full run on the release cost the bear 150 ms for the same bytes.
        The whole groom's neighbour list, left as the last full run built it, is brought up to
        date by the next full run (a parameter, an undo), where the stroke moved strands."""
        self._unsettled = False
        return self._result

    def update(self) -> Groom:
        """Re-run the pipeline (with ``redraw_noise``: new freeze noise, strokes replayed)."""
        self._timings = dict.fromkeys(self._timings, 0.0)
        if self._params.redraw_noise and self._params.freeze:
            self._draw += 1
            self._freeze_key = None
            self._refreeze()
        self._reclump()
        return self._result

    def reset_strokes(self) -> Groom:
        """Forget every stroke: back to the frozen groom (clumped)."""
        self._log = []
        self._clear_state()
        self._aligned = self._frozen
        self._timings = dict.fromkeys(self._timings, 0.0)
        self._reclump()
        return self._result

    def snapshot(self) -> FrozenSnapshot:
        """Cheap state for undo/redo (grooms are immutable; the per-strand arrays are copied)."""
        return FrozenSnapshot(
            tuple(self._log),
            self._state.copy(),
            self._aligned,
            self._result,
            self._hook_state(),
            self._frozen_on(),
            self._params._key,
        )

    def restore(self, snapshot: FrozenSnapshot) -> Groom:
        """Back to a snapshot's strokes; replayed on the current frozen groom if it has changed
        (a replay that fails, e.g. slide strokes without a surface, leaves the state as it was).

        Parameters
        ----------
        snapshot : FrozenSnapshot
            What :meth:`snapshot` returned, or :meth:`FrozenSnapshot.replaying`.

        Returns
        -------
        Groom
            The clumped result.
        """
        now = self.snapshot()
        try:
            return self._restore(snapshot)
        except BaseException:
            self._restore(now)
            raise

    def _restore(self, snapshot: FrozenSnapshot) -> Groom:
        self._log = list(snapshot.log)
        self._timings = dict.fromkeys(self._timings, 0.0)
        if snapshot.frozen_on == self._frozen_on():
            aligned = snapshot.aligned
            if aligned.metadata is not self._rest.metadata:  # a relabelled rest (its up axis): its record
                aligned = aligned.with_metadata(self._rest.metadata)
            self._aligned = aligned
            self._state = snapshot.state.copy()
            self._set_hooks(snapshot.memory)
            shown = snapshot.result
        else:
            self._replay()
            shown = None
        self._reclump()
        if shown is not None and snapshot.clumped_on == self._params._key and self._moves.clump is not None:
            if shown.metadata is not self._rest.metadata:
                shown = shown.with_metadata(self._rest.metadata)
            if (
                shown.topology is self._aligned.topology
                or shown.counts.tobytes() == self._aligned.counts.tobytes()
            ):
                # What was shown (the record is the full run's: later moves hold the rest to it).
                self._result = self._aligned.with_points(shown.points)
                self._moves.kept = self._result.points.copy()
        return self._result

    def clump_ids(self) -> np.ndarray:
        """``(S,)`` clump of each strand in the last result at the scale h (density basins of
        the strands' adhesion, :func:`~hairtool.frozen.strand_clumps.strand_clumps`), numbered in
        order of their first strand."""
        return strand_clumps(self._result, self.clump_radius)

    # -- internals -----------------------------------------------------------------------
    def _refreeze(self) -> None:
        p = self._params
        key = (*p.freeze_key(), self._draw)
        if key == self._freeze_key:
            return
        t0 = time.perf_counter()
        if p.freeze:
            seed = draw_seed(p.seed, self._draw)
            self._frozen = freeze(
                self._rest, p.stretch_stiffness, p.bend_stiffness, p.max_bend_angle, seed, p.strand_variation
            )
        else:
            self._frozen = self._rest
        self._freeze_key = key
        t1 = time.perf_counter()
        self._timings["freeze"] = (t1 - t0) * 1e3
        self._replay()
        self._timings["align"] = (time.perf_counter() - t1) * 1e3

    def _frozen_on(self) -> tuple:
        """What :attr:`FrozenSnapshot.frozen_on` holds for the frozen groom now."""
        return (self._freeze_key or (), self._draw)

    def _clear_state(self) -> None:
        self._state = StrandState.fresh(self._rest.strand_count)
        self._set_hooks(NO_MEMORY)

    def _hook_state(self) -> tuple[tuple, int, bool]:
        return self._memory.frozen()

    def _set_hooks(self, state: tuple[tuple, int, bool]) -> None:
        self._memory = StrokeMemory.of(state)

    def _setting(self) -> StrokeSetting:
        """What a sample reads besides the stroked state (:mod:`hairtool.frozen.replay`)."""
        return StrokeSetting(
            lambda: self.root_normals, lambda: self.scalp_centre, self._surface, self._collision
        )

    def _replay(self) -> None:
        """The log on the frozen groom (a refused sample leaves the stroked state as it was)."""
        self._aligned, self._state, self._memory = replay(self._setting(), self._frozen, self._log)

    def _reclump(self) -> None:
        """A full run on the stroked state (recorded: brush-local moves start from it)."""
        p = self._params
        t0 = time.perf_counter()
        self._redone, self._region, self._unsettled = 1.0, None, False
        g = self._aligned
        if p.clump and p.clump_iterations > 0:
            h, step, seed = self.clump_radius, self._step(), draw_seed(p.seed, self._draw)
            ws = self._workspace
            ws.record = True
            pts = clump_points(
                g,
                h,
                p.clump_iterations,
                step,
                p.gap_mode,
                seed,
                ws,
                bool(p.keep_lengths),
                self._state.clump_strength,
            )
            self._result = self._kept_out(g.with_points(pts))
            rec = ws.recorded
            key = record_key(g, h, p.clump_iterations, step, p.gap_mode, seed)
            if g.strand_count >= 2 and rec is not None and rec.valid and rec.key == key:
                moves = self._moves
                local = moves.clump
                if (
                    local is not None
                    and local.topology is g.topology
                    and local.h == h
                    and local.record is rec
                ):
                    local.resync(g.points, moves.grid_points)  # the grid follows what moved
                else:
                    longest = int(ws.neighbours.cnt.max(initial=0))
                    moves.clump = LocalClump(g.points, g.topology, h, rec, longest)
                moves.grid_points = g.points
                moves.sv = vertex_strength(g, self._state.clump_strength)
                moves.kept = pts
                moves.nonplanar = int(np.count_nonzero(g.points[:, 2]))
            else:
                self._moves.clump = None
        else:
            self._workspace.mean_neighbours = 0.0
            self._result = g
            self._moves.clump = None
        self._timings["clump"] = (time.perf_counter() - t0) * 1e3
        self._timings["total"] = self._timings["freeze"] + self._timings["align"] + self._timings["clump"]

    def prepare_strokes(self, region_share: float = PREPARED_REGION) -> None:
        """What a first brush move would otherwise compute or allocate, now (the studio calls
        it while idle after an open): the scalp's normals and centre, room for the lists of a
        region of ``region_share`` of the vertices, and (up to :data:`PREPARED_HEAD` vertices)
        each point's distance to the head, which keeping strokes out of it reads.

        Parameters
        ----------
        region_share : float, default PREPARED_REGION
            The share of the vertices a brush-local region is expected to reach.
        """
        _ = self.root_normals, self.scalp_centre
        if self._moves.clump is not None:
            self._moves.clump.grid.prepare(int(region_share * self._aligned.vertex_count))
        if self._aligned.vertex_count <= PREPARED_HEAD:
            self._collision.remember(
                self._surface, self._aligned, self._result
            )  # what a first collision asks

    def _kept_out(self, clumped: Groom) -> Groom:
        """The clumped result kept out of the head where strokes collide with it."""
        return self._collision.kept_out(self._surface, self._log, self._aligned, clumped)

    # -- brush-local moves (hairtool.frozen.local_moves) ---------------------------------
    def _local_key(self) -> tuple | None:
        """The record key a full run would have now (None: no step known without one)."""
        p = self._params
        h, seed = self.clump_radius, draw_seed(p.seed, self._draw)
        if self._auto_step is None and p.clump_step is None:
            return None
        return record_key(self._aligned, h, p.clump_iterations, self._step(), p.gap_mode, seed)

    def _owns_aligned(self) -> bool:
        """Whether the aligned groom and its points are held by the pipeline alone (as the
        grid's points too), so a move may write into them (:mod:`hairtool.frozen.move_points`).
        (Read before any local name holds them.)"""
        return (
            self._moves.grid_points is self._aligned.points
            and may_write(self._aligned.points)
            and held_by_at_most(sys.getrefcount(self._aligned), 1)
            and held_by_at_most(sys.getrefcount(self._aligned.points), 2)
        )

    def _apply_local(self, samples: Sequence[Sample]) -> Groom:
        """``samples`` as a brush-local move (:func:`~hairtool.frozen.local_moves.move`)."""
        t0 = time.perf_counter()
        in_place = self._owns_aligned()
        on_kept = self._result.points is self._moves.kept
        alone = held_by_at_most(sys.getrefcount(self._result), 1)  # (read before a name holds it)
        p = self._params
        run = ClumpRun(
            p.clump_iterations, self._step(), p.gap_mode, draw_seed(p.seed, self._draw), p.keep_lengths
        )
        hooks = self._hook_state()
        try:
            moved = local_moves.move(
                self._moves, self._setting(), self._aligned, self._state, self._memory, samples,
                run, in_place, on_kept, alone,
            )  # fmt: skip
        except BaseException:  # a refused sample: none of these samples happened
            self._set_hooks(hooks)
            raise
        self._log.extend(samples)
        self._aligned, self._state, self._memory = moved.aligned, moved.state, moved.memory
        self._timings["align"] = moved.align_ms
        if moved.full:
            self._reclump()
        elif moved.clumped is not None:
            self._unsettled = True
            self._result = self._kept_out(moved.clumped)
            self._redone, self._region = moved.redone, moved.region
        else:
            self._redone, self._region = 0.0, moved.region
            self._timings["total"] = self._timings["align"]
            return self._result
        self._timings["clump"] = (time.perf_counter() - t0) * 1e3 - moved.align_ms
        self._timings["total"] = self._timings["align"] + self._timings["clump"]
        return self._result
