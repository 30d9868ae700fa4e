"""Brush-local moves write into the last move's arrays only where nothing else holds them."""

from __future__ import annotations

import numpy as np
import pytest

from hairtool import samples
from hairtool.errors import HairtoolError
from hairtool.frozen.brushes import BrushSample, falloff_lut
from hairtool.frozen.move_points import MovePoints, held_by_at_most
from hairtool.frozen.pipeline import FrozenParams, FrozenPipeline
from hairtool.groom import Groom


class _Box:
    def __init__(self, item) -> None:
        self.item = item


def comb(cursor, direction, radius, strength=0.8):
    lut = tuple(falloff_lut("smooth").tolist())
    where, way = tuple(map(float, cursor)), tuple(map(float, direction))
    return BrushSample("comb", where, way, float(radius), strength, lut)


def address(a: np.ndarray) -> int:
    """Where an array's data lives (an int: holding it holds no reference to the array)."""
    return a.__array_interface__["data"][0]


@pytest.fixture(scope="module")
def scalp():
    return samples.scalp(800, 12, seed=4)


def drag(g: Groom, moves: int = 8):
    """A comb stroke's samples circling a tip near the middle, at a brush of 0.06× the extent."""
    lo, hi = g.bounds
    extent = float(np.max(hi - lo))
    tips = g.tips.astype(np.float64)
    tip = tips[np.argmin(np.linalg.norm(tips - (lo + hi) / 2, axis=1))]
    out = []
    for k in range(moves):
        a = 2 * np.pi * k / moves
        at = tip + 0.03 * extent * np.array([np.cos(a), np.sin(a), 0.0])
        way = (0.02 * extent * -np.sin(a), 0.02 * extent * np.cos(a), 0.0)
        out.append(comb(at, way, 0.06 * extent))
    return out


# -- the reference counts ------------------------------------------------------------------------
def test_a_count_read_from_an_attribute_tells_one_holder_from_two():
    box = _Box(np.zeros(3))
    assert held_by_at_most(_count(box), 1)
    other = box.item  # a second holder
    assert not held_by_at_most(_count(box), 1) and held_by_at_most(_count(box), 2)
    view = other[1:]  # a view holds its base
    del other
    assert not held_by_at_most(_count(box), 1)
    del view
    assert held_by_at_most(_count(box), 1)


def _count(box: _Box) -> int:
    import sys

    return sys.getrefcount(box.item)


# -- MovePoints ----------------------------------------------------------------------------------
@pytest.mark.parametrize("in_place", [True, False])
def test_move_points_know_each_rows_value_before_the_move_and_undo_it(in_place):
    rng = np.random.default_rng(1)
    last = rng.normal(size=(50, 3)).astype(np.float32)
    kept = last.copy()
    last.flags.writeable = False
    cur = MovePoints(last, in_place)
    cur.write(np.arange(5, 15), rng.normal(size=(10, 3)).astype(np.float32))
    cur.write(np.arange(10, 20), rng.normal(size=(10, 3)).astype(np.float32))  # over the first
    cur.write(np.arange(0, 3), last[0:3].copy())  # the same values: no write at all
    rows = np.array([0, 4, 5, 12, 19, 30, 49])
    assert cur.before(rows).tobytes() == kept[rows].tobytes()
    assert (cur.points is last) == in_place
    assert not np.array_equal(cur.points[5:20], kept[5:20])
    if in_place:
        cur.undo()
        assert last.tobytes() == kept.tobytes() and not last.flags.writeable
    else:
        assert last.tobytes() == kept.tobytes()  # the last points untouched: written in a copy


def test_a_move_that_moves_nothing_copies_nothing():
    last = np.zeros((10, 3), np.float32)
    last.flags.writeable = False
    cur = MovePoints(last, False)
    cur.write(np.arange(4), np.zeros((4, 3), np.float32))
    assert cur.points is last


# -- the pipeline --------------------------------------------------------------------------------
def test_a_drag_whose_results_nobody_keeps_writes_in_place_with_the_same_bytes(scalp):
    strokes = drag(scalp)
    held = FrozenPipeline(scalp)  # every result kept: each move copies
    kept = [held.brush(s) for s in strokes]
    free = FrozenPipeline(scalp)  # results dropped: the moves write into the last ones
    free.brush(strokes[0])
    where = address(free.result.points), address(free.aligned.points)
    for k, s in enumerate(strokes[1:], 1):
        free.brush(s)
        assert free.clump_redone < 0.5  # (brush-local moves)
        assert (address(free.result.points), address(free.aligned.points)) == where  # in place
        assert free.result.points.tobytes() == kept[k].points.tobytes()
    assert held.aligned.points.tobytes() == free.aligned.points.tobytes()
    assert len({address(g.points) for g in kept}) == len(kept)  # each kept result its own


def test_a_result_or_a_view_of_its_points_held_never_changes(scalp):
    strokes = drag(scalp, 6)
    pipe = FrozenPipeline(scalp)
    pipe.brush(strokes[0])
    groom = pipe.result  # the groom held
    groom_bytes = groom.points.tobytes()
    pipe.brush(strokes[1])
    tail = pipe.result.points[-40:]  # only a view of the points held
    tail_bytes = tail.tobytes()
    aligned = pipe.aligned.points  # the aligned points held
    aligned_bytes = aligned.tobytes()
    for s in strokes[2:]:
        pipe.brush(s)
    assert groom.points.tobytes() == groom_bytes
    assert tail.tobytes() == tail_bytes
    assert aligned.tobytes() == aligned_bytes
    assert pipe.result.points.tobytes() != groom_bytes  # (the drag did move hair)
    assert not groom.points.flags.writeable and not pipe.result.points.flags.writeable


def test_an_undo_snapshot_taken_during_a_drag_restores_its_bytes(scalp):
    strokes = drag(scalp, 6)
    pipe = FrozenPipeline(scalp)
    for s in strokes[:3]:
        pipe.brush(s)
    snap = pipe.snapshot()  # holds the grooms: the next moves copy
    want = pipe.result.points.tobytes(), pipe.aligned.points.tobytes()
    for s in strokes[3:]:
        pipe.brush(s)
    restored = pipe.restore(snap)
    assert (restored.points.tobytes(), pipe.aligned.points.tobytes()) == want


def test_a_refused_sample_in_a_batch_leaves_the_points_as_they_were(scalp):
    strokes = drag(scalp, 4)
    pipe = FrozenPipeline(scalp)
    ref = FrozenPipeline(scalp)
    for s in strokes[:2]:
        pipe.brush(s)
        ref.brush(s)
    was = address(pipe.aligned.points)
    bad = BrushSample("comb", strokes[2].cursor, strokes[2].direction, -1.0, 0.8, strokes[2].lut)
    with pytest.raises(HairtoolError):
        pipe.apply_samples([strokes[2], bad])  # the first writes in place, the second is refused
    assert address(pipe.aligned.points) == was
    assert pipe.aligned.points.tobytes() == ref.aligned.points.tobytes()
    assert not pipe.aligned.points.flags.writeable
    pipe.brush(strokes[3])
    ref.brush(strokes[3])
    assert pipe.result.points.tobytes() == ref.result.points.tobytes()


def test_keep_lengths_moves_in_place_give_the_copying_moves_bytes(scalp):
    strokes = drag(scalp, 5)
    params = FrozenParams(keep_lengths=True)
    held = FrozenPipeline(scalp, params)
    kept = [held.brush(s) for s in strokes]
    free = FrozenPipeline(scalp, params)
    for s in strokes:
        free.brush(s)
    assert free.result.points.tobytes() == kept[-1].points.tobytes()


def test_the_kept_box_gives_the_full_builds_grid_after_moves_of_extreme_tips():
    from hairtool.frozen.vertex_grid import list_frame

    g = samples.scalp(6000, 8, seed=4)  # (dense: its list grid's lattice is finer than a comb's reach)
    pipe = FrozenPipeline(g)
    lo, hi = g.bounds
    extent = float(np.max(hi - lo))
    pipe.brush(comb(g.tips[0].astype(np.float64), (0.0, 0.0, 0.01), 0.03 * extent))  # (the box known)
    frames = [pipe.local_clump.frame(pipe.aligned.points)]
    for axis, sign in ((0, 1), (1, -1), *[(2, -1)] * 8):
        tips = pipe.aligned.tips.astype(np.float64)
        tip = tips[np.argmax(sign * tips[:, axis])]  # the tip farthest out along the axis
        way = np.zeros(3)
        way[axis] = 0.3 * extent * sign  # outward: the box grows
        pipe.brush(comb(tip, way, 0.03 * extent, 1.0))
        pts = pipe.aligned.points
        got, want = pipe.local_clump.frame(pts), list_frame(pts, pipe.local_clump.radius)
        assert got[0] == want[0] and got[2:] == want[2:] and np.array_equal(got[1], want[1])
        same = want[2:] == frames[-1][2:] and np.array_equal(want[1], frames[-1][1])
        # a move that changes the full build's grid changes every list's order: it runs in full
        assert pipe.clump_redone < 0.5 if same else pipe.clump_redone == 1.0
        frames.append(want)
    assert any(f[3:5] != frames[0][3:5] or not np.array_equal(f[1], frames[0][1]) for f in frames)
