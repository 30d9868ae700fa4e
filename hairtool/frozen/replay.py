"""A stroke log applied to a groom, one sample at a time, on state held outside any class.

The stroked state is three values: the aligned groom (the frozen groom with the strokes so far),
its per-strand state (:class:`~hairtool.frozen.strand_state.StrandState`) and the stroke memory
a stroke-keeping brush holds (:class:`~hairtool.frozen.brushes.spec.StrokeMemory`).
:func:`apply_sample` takes them and one sample and gives them back after it; :func:`replay`
runs a whole log from the frozen groom. What a sample reads besides them (the scalp's
normals and centre, the head and collision with it) is a :class:`StrokeSetting`. The pipeline
(:mod:`hairtool.frozen.pipeline`) keeps the values between calls; the brush-local path
(:mod:`hairtool.frozen.local_moves`) runs the same per-sample step on the strands under a brush.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from dataclasses import dataclass

import numpy as np

from hairtool.frozen.brushes import registry
from hairtool.frozen.brushes.align import AlignSample
from hairtool.frozen.brushes.sample import BrushSample, check_view
from hairtool.frozen.brushes.scalp import facing_away
from hairtool.frozen.brushes.sight import hidden_strands
from hairtool.frozen.brushes.spec import StrokeContext, StrokeMemory
from hairtool.frozen.head_collision import HeadCollision
from hairtool.frozen.selection import SelectionSample, apply_selection
from hairtool.frozen.strand_state import StrandState
from hairtool.groom import Groom

Sample = AlignSample | BrushSample | SelectionSample
NO_MEMORY: tuple[tuple, int, bool] = ((), 0, False)  # a stroke memory with nothing kept


@dataclass(frozen=True)
class StrokeSetting:
    """What a sample reads besides the stroked state: the rest roots' outward normals and the
    scalp's centre (callables: computed when first asked), the head's surface (or None) and
    collision with it."""

    root_normals: Callable[[], np.ndarray]
    scalp_centre: Callable[[], np.ndarray]
    surface: object | None
    collision: HeadCollision

    def strand_normals(self, aligned: Groom, state: StrandState) -> np.ndarray:
        """``(S', 3)`` outward normals at the roots of the stroked strands: a rest strand's from
        the rest roots (by ``state.origin``), a planted one's from the surface at its root.

        Parameters
        ----------
        aligned : Groom
            The stroked groom.
        state : StrandState
            Its per-strand state.

        Returns
        -------
        numpy.ndarray
            ``(S', 3)`` float normals (the rest roots' own array where nothing was deleted or
            planted).
        """
        n = self.root_normals()
        origin = state.origin
        if len(origin) == len(n) and origin.min(initial=0) >= 0:
            return n  # (deletes keep the order, plants come last: this is every rest strand)
        out = n[np.maximum(origin, 0)]
        new = origin < 0
        if new.any():
            _, out[new] = self.surface.project(aligned.roots[new].astype(np.float64))  # type: ignore[union-attr]
        return out

    def away(self, sample: Sample, g: Groom, normals: Callable[[], np.ndarray]) -> np.ndarray | None:
        """``(S,)`` the strands of ``g`` a sample's camera does not face (None: no view, none).

        A sample that says ``visible``, on a head mesh: the strands the head hides under its
        brush (:func:`~hairtool.frozen.brushes.sight.hidden_strands`; each vertex's ray to the
        sample's ``eye`` where it has one, a perspective camera's). Otherwise, as every log
        before that field: the strands whose root normal (``normals``, asked only then) faces
        away from the camera."""
        view = check_view(sample.view)
        if view is None:
            return None
        grid = getattr(self.surface, "face_grid", None)
        if getattr(sample, "visible", False) and grid is not None:
            eye = getattr(sample, "eye", None)
            return hidden_strands(g.points, g.offsets, sample.cursor, sample.radius, view, grid, eye)  # type: ignore[union-attr]
        return facing_away(normals(), view)

    def context(
        self, state: StrandState, memory: StrokeMemory, away: np.ndarray | None, planar: bool | None = None
    ) -> StrokeContext:
        """The :class:`~hairtool.frozen.brushes.spec.StrokeContext` a brush works in."""
        return StrokeContext(state, away, self.surface, self.scalp_centre, memory, planar)


def memory_for(brush, memory: StrokeMemory) -> StrokeMemory:
    """The stroke memory a sample of ``brush`` starts from: another brush (or a selection step,
    ``brush`` None) ends a stroke-keeping brush's stroke."""
    if brush is None or not brush.spec.keeps_stroke:
        return StrokeMemory.of(NO_MEMORY)
    return memory


def selection_after(
    setting: StrokeSetting, g: Groom, state: StrandState, sample: SelectionSample
) -> tuple[np.ndarray, np.ndarray]:
    """``(selected, hidden)`` after the selection step ``sample`` on ``g``: a box that says
    ``visible``, on a head mesh, judges each vertex inside it by sight; any other box with a
    view, each strand by its root normal (as every log before ``visible``)."""
    grid = getattr(setting.surface, "face_grid", None) if sample.visible else None
    if grid is not None:
        sample, away = sample._replace(view=check_view(sample.view)), None
    else:
        away = setting.away(sample, g, lambda: setting.strand_normals(g, state))
    return apply_selection(g, sample, state.selected, state.hidden, away, grid)


def apply_sample(
    setting: StrokeSetting, g: Groom, state: StrandState, memory: StrokeMemory, sample: Sample
) -> tuple[Groom, StrandState, StrokeMemory]:
    """One sample of any brush (or a selection step) on the stroked state.

    Parameters
    ----------
    setting : StrokeSetting
        The scalp, the head and collision with it.
    g : Groom
        The aligned groom before the sample.
    state : StrandState
        Its per-strand state (not written: a changed state is a new one).
    memory : StrokeMemory
        What a stroke-keeping brush held before the sample (written by that brush).
    sample : AlignSample, BrushSample or SelectionSample
        The sample.

    Returns
    -------
    tuple
        ``(groom, state, memory)`` after the sample.

    Raises
    ------
    HairtoolError
        The sample is refused (the caller keeps the state it had).
    """
    if isinstance(sample, SelectionSample):
        memory = memory_for(None, memory)
        selected, hidden = selection_after(setting, g, state, sample)
        return g, state.with_(selected=selected, hidden=hidden), memory
    brush = registry.brush_of(registry.name_of(sample))
    memory = memory_for(brush, memory)
    ctx = setting.context(state, memory, setting.away(sample, g, lambda: setting.strand_normals(g, state)))
    out = brush.apply(ctx, g, sample)
    if brush.spec.moves_points and sample.collide:
        out = setting.collision.collide(setting.surface, g, out)
    return out, ctx.state, memory


def replay(
    setting: StrokeSetting, frozen: Groom, log: Iterable[Sample]
) -> tuple[Groom, StrandState, StrokeMemory]:
    """A stroke log on the frozen groom, from a fresh per-strand state.

    Parameters
    ----------
    setting : StrokeSetting
        The scalp, the head and collision with it.
    frozen : Groom
        The frozen groom the log starts from.
    log : iterable of samples
        The stroke log, in order.

    Returns
    -------
    tuple
        ``(aligned, state, memory)`` after the log.
    """
    g, state, memory = frozen, StrandState.fresh(frozen.strand_count), StrokeMemory.of(NO_MEMORY)
    for sample in log:  # (the stroked state so far: planted strands' normals come from it)
        g, state, memory = apply_sample(setting, g, state, memory, sample)
    return g, state, memory
