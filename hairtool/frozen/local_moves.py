"""Brush-local moves on explicit state: a batch of samples runs on the strands under the brushes
only, and ClumpWithGaps is redone near them (:class:`~hairtool.frozen.local.LocalClump`).

What the moves start from (the last full recorded run's :class:`~hairtool.frozen.local.LocalClump`,
the clump input its grid holds, each vertex's clump strength, the result's points as the moves
leave them) is one :class:`LocalMoves`, which the pipeline keeps and refreshes after each full
run. :func:`ready` says whether a batch can run so; :func:`move` runs it on the stroked state
(aligned groom, per-strand state, stroke memory: :mod:`hairtool.frozen.replay`) and returns
what it left (:class:`Moved`). Points are written in place where the pipeline alone holds them
(:mod:`hairtool.frozen.move_points`): the pipeline reads who holds its grooms before the call.
"""

from __future__ import annotations

import sys
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np

from hairtool.frozen.brushes import registry
from hairtool.frozen.brushes.spec import StrokeMemory
from hairtool.frozen.clump import ClumpRecord
from hairtool.frozen.lengths import restore_lengths
from hairtool.frozen.local import LocalClump, parallel_for, threads_for
from hairtool.frozen.move_points import MovePoints, held_by_at_most, may_write
from hairtool.frozen.replay import Sample, StrokeSetting, apply_sample, memory_for
from hairtool.frozen.selection import SelectionSample
from hairtool.frozen.strand_state import StrandState
from hairtool.groom import Groom, vertex_ids_of
from hairtool.sorted_ids import union


@dataclass(eq=False)
class LocalMoves:
    """What brush-local moves start from: ``clump`` the last full recorded run's local clumping
    (None: no move can run locally), ``grid_points`` the clump input its grid holds, ``sv`` each
    vertex's clump strength for it, ``kept`` the result's points as the moves leave them,
    ``nonplanar`` the stroked vertices off z = 0."""

    clump: LocalClump | None = None
    grid_points: np.ndarray | None = None
    sv: np.ndarray = field(default_factory=lambda: np.zeros(0))
    kept: np.ndarray = field(default_factory=lambda: np.zeros((0, 3), np.float32))
    nonplanar: int = 0


@dataclass(frozen=True)
class ClumpRun:
    """The clumping a move redoes near the brush: iterations, step, gap mode, seed, and whether
    segments get their lengths back."""

    iterations: int
    step: float
    gap_mode: str
    seed: int
    keep_lengths: bool


@dataclass
class Moved:
    """What a brush-local move left: the stroked state after it; ``clumped`` the result before
    keeping it out of the head (None: ``full``, a full run is cheaper, or nothing moved);
    ``region`` the strands redone, ``redone`` the share of the vertices; ``align_ms`` the time
    the samples took."""

    aligned: Groom
    state: StrandState
    memory: StrokeMemory
    clumped: Groom | None
    region: np.ndarray | None
    redone: float
    full: bool
    align_ms: float


def ready(
    moves: LocalMoves,
    aligned: Groom,
    samples: Sequence[Sample],
    record: ClumpRecord | None,
    key_now: Callable[[], tuple | None],
) -> bool:
    """Whether ``samples`` can run on the strands under their brushes only.

    Parameters
    ----------
    moves : LocalMoves
        What the moves start from.
    aligned : Groom
        The stroked groom now.
    samples : sequence of samples
        The batch.
    record : ClumpRecord or None
        The clump workspace's record now.
    key_now : callable
        The record key a full run would have now (None: not known without a full run).

    Returns
    -------
    bool
    """
    local = moves.clump
    if local is None or moves.grid_points is None or local.topology is not aligned.topology:
        return False
    if not all(
        isinstance(s, SelectionSample) or registry.spec_of(registry.name_of(s)).local for s in samples
    ):
        return False
    key = key_now()
    return (
        key is not None
        and record is local.record
        and record is not None
        and record.valid
        and record.key == key
    )


def _kept_writable(moves: LocalMoves, result_on_kept: bool, result_alone: bool) -> None:
    """``moves.kept`` ready for a move's rows: the result handed out over it is written in place
    where the pipeline alone holds it (``result_alone``, read by the pipeline), copied first where
    anything else does."""
    if moves.kept.flags.writeable:
        return
    if result_on_kept:
        mine = result_alone and held_by_at_most(sys.getrefcount(moves.kept), 2)
    else:
        mine = held_by_at_most(sys.getrefcount(moves.kept), 1)
    if mine and may_write(moves.kept):
        moves.kept.flags.writeable = True
    else:
        moves.kept = moves.kept.copy()


def move(
    moves: LocalMoves,
    setting: StrokeSetting,
    aligned: Groom,
    state: StrandState,
    memory: StrokeMemory,
    samples: Sequence[Sample],
    run: ClumpRun,
    in_place: bool,
    result_on_kept: bool,
    result_alone: bool,
) -> Moved:
    """One batch of samples as a brush-local move.

    Parameters
    ----------
    moves : LocalMoves
        What the moves start from (:func:`ready` said yes); updated.
    setting : StrokeSetting
        The scalp, the head and collision with it.
    aligned, state, memory
        The stroked state before the batch (``memory`` is written by a stroke-keeping brush).
    samples : sequence of samples
        The batch.
    run : ClumpRun
        The clumping to redo near the brush.
    in_place : bool
        The pipeline alone holds ``aligned`` and its points: the moves write into them.
    result_on_kept, result_alone : bool
        The pipeline's last result is over ``moves.kept``; the pipeline alone holds it.

    Returns
    -------
    Moved
        The stroked state after the batch and the clumping redone (or ``full``: a full run
        is cheaper).

    Raises
    ------
    HairtoolError
        A sample is refused: the points are as they were, and no state changed.
    """
    t0 = time.perf_counter()
    top, local = aligned.topology, moves.clump
    assert local is not None and moves.grid_points is not None
    cur = MovePoints(moves.grid_points, in_place)
    touched = np.zeros(aligned.strand_count, bool)  # strands a sample of this batch ran on
    painted = np.zeros(0, np.int64)  # strands whose clump strength changed
    planar = moves.nonplanar == 0
    normals = setting.strand_normals(aligned, state) if any(s.view is not None for s in samples) else None
    try:
        for sample in samples:
            state, memory, more = _sample(
                moves, setting, aligned, state, memory, cur, sample, touched, planar, normals
            )
            painted = union(painted, more)
    except BaseException:  # a refused sample: none of these samples happened
        cur.undo()
        raise
    cur.done()
    ran = np.flatnonzero(touched)
    rv = vertex_ids_of(top, ran)
    went = rv[np.any(cur.before(rv).view(np.uint32) != cur.points[rv].view(np.uint32), axis=1)]
    pv = vertex_ids_of(top, painted)
    changed = union(went, pv)  # the vertices whose clump input changed
    now_aligned = aligned
    if went.size:
        was = cur.before(went)
        moves.nonplanar += int(np.count_nonzero(cur.points[went, 2])) - int(np.count_nonzero(was[:, 2]))
        now_aligned = aligned.with_moved_rows(cur.points, went)  # (the pipeline's own: a copy, or its last)
    align_ms = (time.perf_counter() - t0) * 1e3
    if changed.size == 0:
        local.lists_ms = 0.0
        return Moved(now_aligned, state, memory, None, np.zeros(0, np.int64), 0.0, False, align_ms)
    sv = moves.sv
    sv[pv] = state.clump_strength[top.strand_index[pv]]
    now = now_aligned.points
    was = cur.before(changed)
    done = local.update(was, now, changed, sv, run.iterations, run.step, run.gap_mode, run.seed)
    if done is None:  # most of the groom, or every list's order changed: a full run
        return Moved(now_aligned, state, memory, None, None, 1.0, True, align_ms)
    region, vids = done
    rec = local.record
    _kept_writable(moves, result_on_kept, result_alone)
    if run.keep_lengths:  # whole strands: a segment's length is given back from the root on
        rows = vertex_ids_of(top, region)
        restore_lengths(now, rec.result, top, region, moves.kept, parallel_for(rows.size))
        still = rows[sv[rows] == 0.0]
        moves.kept[still] = now[still]
    else:
        rows = vids
        moves.kept[vids] = rec.result[vids]
    moves.grid_points = now
    clumped = now_aligned.with_moved_rows(moves.kept, rows)  # (new: the region)
    return Moved(
        now_aligned, state, memory, clumped, region, vids.size / max(top.vertex_count, 1), False, align_ms
    )


def _sample(
    moves: LocalMoves,
    setting: StrokeSetting,
    aligned: Groom,
    state: StrandState,
    memory: StrokeMemory,
    cur: MovePoints,
    sample: Sample,
    touched: np.ndarray,
    planar: bool,
    normals: np.ndarray | None,
) -> tuple[StrandState, StrokeMemory, np.ndarray]:
    """One sample on the strands with a vertex within its radius (where the grid holds the
    unmoved ones) and those this batch has moved, written into ``cur``: (the state and memory
    after it, the strands whose clump strength it changed). ``aligned``: the stroked groom
    before the batch (its topology, metadata and normals)."""
    none = np.zeros(0, np.int64)
    # a selection step, or a sample that reaches past its brush (a new selection): on the whole
    # groom (they move no strand)
    brush = None if isinstance(sample, SelectionSample) else registry.brush_of(registry.name_of(sample))
    if brush is None or brush.reaches_every_strand(sample):
        _, state, memory = apply_sample(setting, aligned.with_points(cur.points), state, memory, sample)
        return state, memory, none
    local, top = moves.clump, aligned.topology
    assert local is not None and moves.grid_points is not None
    memory = memory_for(brush, memory)
    brush.check(sample)
    reach = float(sample.radius) * (1.0 + 1e-6)  # a little wider: the brush itself decides
    near = local.near(moves.grid_points, np.asarray(sample.cursor, np.float64).reshape(1, 3), reach)
    cand = union(near, np.flatnonzero(touched))
    if cand.size == 0:
        return state, memory, none
    vids = vertex_ids_of(top, cand)
    with threads_for(vids.size):
        meta = aligned.metadata.subset(cand)  # (in the scene's frame; its prims' share)
        sub = Groom(cur.points[vids], top.counts[cand], metadata=meta)
        away = setting.away(sample, sub, lambda: normals[cand])  # type: ignore[index]
        was = state.subset(cand)
        ctx = setting.context(was, memory, away, planar)
        out = brush.apply(ctx, sub, sample)
        state = state.scatter(cand, ctx.state, was)
        now = ctx.state.clump_strength
        painted = cand[now != was.clump_strength] if now is not was.clump_strength else none
        if brush.spec.moves_points:
            if sample.collide:
                out = setting.collision.collide(setting.surface, sub, out)
            cur.write(vids, out.points)
            touched[cand] = True
    return state, memory, painted
