"""FrozenPipeline: the interactive contract (strokes persist, clumping never accumulates)."""

from __future__ import annotations

import numpy as np
import pytest

from hairtool import samples
from hairtool.errors import ParameterError
from hairtool.frozen.align import align
from hairtool.frozen.clump import ClumpWorkspace, clump
from hairtool.frozen.freeze import freeze
from hairtool.frozen.pipeline import FrozenParams, FrozenPipeline
from hairtool.frozen.strand_clumps import auto_clump_radius, strand_clumps_reference

CURSOR = np.array([2.0, 0.5, 0.5])


@pytest.fixture(scope="module")
def rest():
    return samples.scalp(300, 16, seed=1)


def test_pipeline_is_the_three_stages_in_order(rest):
    p = FrozenParams(stretch_stiffness=4.0, bend_stiffness=3.0, seed=2)
    pipe = FrozenPipeline(rest, p)
    out = pipe.align(CURSOR, 2.0, 0.8)
    h = auto_clump_radius(rest)
    expect = clump(
        align(freeze(rest, 4.0, 3.0, p.max_bend_angle, 2), CURSOR, 2.0, 0.8), h, 3, None, "printed", 2
    )
    assert out.points.tobytes() == expect.points.tobytes()
    assert pipe.result is out
    assert pipe.clump_radius == h
    assert set(pipe.timings) == {"freeze", "align", "clump", "total"}
    assert pipe.mean_neighbours > 0 and pipe.clump_step > 0
    np.testing.assert_array_equal(out.roots, rest.roots)


def test_a_thousand_updates_at_a_fixed_cursor_stay_where_one_put_it(rest):
    pipe = FrozenPipeline(rest)
    first = pipe.align(CURSOR, 2.0, 1.0).points.copy()
    for _ in range(1000):
        pipe.align(CURSOR, 2.0, 1.0)
    np.testing.assert_allclose(pipe.result.points, first, atol=1e-5)
    for _ in range(50):
        pipe.update()
    np.testing.assert_allclose(pipe.result.points, first, atol=1e-5)


def test_clumping_never_accumulates(rest):
    pipe = FrozenPipeline(rest)
    a = pipe.update().points.copy()
    b = pipe.update().points
    assert a.tobytes() == b.tobytes()
    np.testing.assert_array_equal(pipe.aligned.points, pipe.frozen.points)


def test_strokes_accumulate_and_survive_stiffness_changes(rest):
    pipe = FrozenPipeline(rest)
    pipe.align(CURSOR, 2.0, 0.5)
    pipe.align(-CURSOR, 2.0, 0.5)
    assert len(pipe.strokes) == 2
    dragged = pipe.result.points.copy()
    soft = FrozenParams(stretch_stiffness=2.0, bend_stiffness=2.0)
    out = pipe.set_params(soft)
    replay = align(align(freeze(rest, 2.0, 2.0, soft.max_bend_angle, 0), CURSOR, 2.0, 0.5), -CURSOR, 2.0, 0.5)
    h = auto_clump_radius(rest)
    assert out.points.tobytes() == clump(replay, h, 3, None, "printed", 0).points.tobytes()
    assert len(pipe.strokes) == 2
    # back to the first parameters: the same result as before, strokes intact
    back = pipe.set_params(FrozenParams())
    np.testing.assert_array_equal(back.points, dragged)


def test_freeze_starts_from_rest_every_time(rest):
    pipe = FrozenPipeline(rest, FrozenParams(clump=False))
    frozen = pipe.frozen.points.copy()
    pipe.set_params(FrozenParams(clump=False, stretch_stiffness=3.0))
    pipe.set_params(FrozenParams(clump=False))
    np.testing.assert_array_equal(pipe.frozen.points, frozen)
    np.testing.assert_array_equal(pipe.result.points, frozen)


def test_clump_only_changes_do_not_refreeze(rest):
    pipe = FrozenPipeline(rest)
    pipe.align(CURSOR, 2.0, 0.5)
    aligned = pipe.aligned
    out = pipe.set_params(FrozenParams(clump_iterations=6, gap_mode="off"))
    assert pipe.aligned is aligned
    assert pipe.timings["freeze"] == 0.0
    # the cached neighbour list gives what a fresh run gives
    fresh = clump(aligned, auto_clump_radius(rest), 6, None, "off", 0)
    assert out.points.tobytes() == fresh.points.tobytes()
    out = pipe.set_params(FrozenParams(clump_radius=0.05))
    assert out.points.tobytes() == clump(aligned, 0.05, 3, None, "printed", 0).points.tobytes()


def test_snapshot_restore_and_reset(rest):
    pipe = FrozenPipeline(rest)
    pipe.align(CURSOR, 2.0, 0.8)
    snap = pipe.snapshot()
    one = pipe.result.points.copy()
    pipe.align(-CURSOR, 2.0, 0.8)
    two = pipe.result.points.copy()
    assert np.abs(two - one).max() > 1e-2
    np.testing.assert_array_equal(pipe.restore(snap).points, one)
    assert len(pipe.strokes) == 1
    # a snapshot taken under other freeze parameters is replayed on the current frozen groom
    pipe.set_params(FrozenParams(stretch_stiffness=3.0))
    redone = pipe.restore(snap)
    expect = FrozenPipeline(rest, FrozenParams(stretch_stiffness=3.0)).align(CURSOR, 2.0, 0.8)
    np.testing.assert_array_equal(redone.points, expect.points)
    pipe.reset_strokes()
    assert pipe.strokes == ()
    np.testing.assert_array_equal(pipe.aligned.points, pipe.frozen.points)


def test_redraw_noise_is_an_option(rest):
    fixed = FrozenPipeline(rest, FrozenParams(clump=False))
    a = fixed.update().points.copy()
    assert fixed.update().points.tobytes() == a.tobytes()
    redraw = FrozenPipeline(rest, FrozenParams(clump=False, redraw_noise=True))
    redraw.align(CURSOR, 2.0, 1.0)
    b = redraw.result.points.copy()
    c = redraw.update().points
    assert np.abs(b - c).max() > 1e-3
    assert len(redraw.strokes) == 1


def test_planar_grooms_stay_planar_through_the_pipeline():
    rest = samples.portrait(200, 20)
    pipe = FrozenPipeline(rest, FrozenParams(strand_variation=1.0))
    out = pipe.align([1.5, 1.5, 0.3], 1.5, 0.8, "preserve-length")
    assert out.is_planar
    np.testing.assert_array_equal(out.roots, rest.roots)


def test_clump_ids_are_the_density_basins_of_the_result(rest):
    pipe = FrozenPipeline(rest, FrozenParams(clump_radius=0.03))
    ids = pipe.clump_ids()
    assert ids.shape == (rest.strand_count,)
    np.testing.assert_array_equal(ids, strand_clumps_reference(pipe.result, 0.03))
    assert ids.max() > 0


def test_params_equality_and_validation(rest):
    assert FrozenParams() == FrozenParams()
    assert FrozenParams(seed=1) != FrozenParams()
    assert FrozenParams(strand_variation=np.ones(3)) == FrozenParams(strand_variation=np.ones(3))
    assert hash(FrozenParams()) == hash(FrozenParams())
    for bad, name in [
        ({"stretch_stiffness": -1.0}, "stretch_stiffness"),
        ({"clump_radius": 0.0}, "clump_radius"),
        ({"clump_iterations": 101}, "clump_iterations"),
        ({"gap_mode": "x"}, "gap_mode"),
        ({"strand_variation": -1.0}, "strand_variation"),
    ]:
        with pytest.raises(ParameterError, match=name):
            FrozenParams(**bad).validate()
    with pytest.raises(ParameterError, match="strand_variation"):
        FrozenPipeline(rest, FrozenParams(strand_variation=np.ones(5)))
    pipe = FrozenPipeline(rest)
    with pytest.raises(ParameterError, match="intensity"):
        pipe.align(CURSOR, 1.0, 2.0)
    assert pipe.strokes == ()


def test_the_automatic_step_is_the_frozen_grooms_and_a_drag_is_redone_near_the_brush():
    # Dense hair (kernel weights above 1 per vertex): the automatic step depends on the points,
    # and is taken from the frozen groom, so that strokes leave it be.
    rest = samples.scalp(900, 12, seed=3)
    h = 2.0 * auto_clump_radius(rest)
    pipe = FrozenPipeline(rest, FrozenParams(clump_radius=h))
    ws = ClumpWorkspace()
    clump(pipe.frozen, h, 1, None, "off", 0, ws)
    frozen_step = ws.step
    assert frozen_step < 0.2 * h  # not the cap: set by the weights
    lo, hi = rest.bounds
    tip = rest.tips[np.argmax(rest.tips[:, 1])]
    redone = []
    for k in range(6):
        out = pipe.align(
            tip + 0.05 * (hi - lo) * np.array([np.cos(k), np.sin(k), 0.0]), 0.1 * float(np.max(hi - lo))
        )
        redone.append(pipe.clump_redone)
    assert pipe.clump_step == frozen_step
    expect = clump(pipe.aligned, h, 3, frozen_step, "printed", 0)
    assert out.points.tobytes() == expect.points.tobytes()  # local or not, a drag gives a full run's bytes
    assert pipe.settle().points.tobytes() == expect.points.tobytes()  # and so does the release
    other = ClumpWorkspace()
    clump(pipe.aligned, h, 1, None, "off", 0, other)
    assert other.step != frozen_step  # what the aligned groom alone would have given
    assert 0.0 < min(r for r in redone if r > 0.0) < 0.5  # redone near the brush only
