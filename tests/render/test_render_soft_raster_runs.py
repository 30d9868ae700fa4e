"""The CPU raster told which vertices a move wrote (``StrandRaster.draw(..., changed=)``): it
compares only those, and every frame keeps the bytes of a fresh full draw."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from app.render import soft_raster
from app.render.camera import Camera
from app.render.soft_raster import StrandRaster, changed_in_runs_reference, merged_runs
from app.render.strand_gpu import vertex_runs
from hairtool import samples
from hairtool.errors import ParameterError
from hairtool.kernel_arrays import readonly

SIZE = (256, 192)
GROOM = samples.scalp(strands=120, vertices=8, seed=4)
STARTS = GROOM.topology.segment_end - 1
STARTS.flags.writeable = False  # as the renderer's: fixed, kept without a copy


def _mvp(yaw: float = 0.0) -> np.ndarray:
    cam = Camera.for_groom(GROOM, aspect=SIZE[0] / SIZE[1])
    cam.yaw += yaw
    return cam.view_matrix() @ cam.projection_matrix(SIZE[0] / SIZE[1])


move = st.tuples(
    st.lists(st.integers(0, GROOM.strand_count - 1), min_size=0, max_size=12),  # strands moved
    st.sampled_from(["points", "colors", "both", "none"]),  # what they changed
    st.floats(0.0005, 0.2),  # how far
    st.lists(st.integers(0, GROOM.strand_count - 1), max_size=3),  # told, though unchanged
    st.booleans(),  # the camera turned (a full draw)
)


@settings(max_examples=12, deadline=None)
@given(
    moves=st.lists(move, min_size=1, max_size=6), width=st.sampled_from([1.0, 2.5]), seed=st.integers(0, 99)
)
def test_moves_of_random_strands_told_give_the_bytes_of_a_fresh_draw(moves, width, seed):
    rng = np.random.default_rng(seed)
    points = GROOM.points.copy()
    colors = rng.random((GROOM.vertex_count, 3)).astype(np.float32)
    raster = StrandRaster()
    raster.draw(points, STARTS, colors, _mvp(), SIZE, width, clear=(3, 2, 1, 255))
    with pytest.MonkeyPatch.context() as patch:
        # (a cost choice, not a byte: on this small groom nearly every move's tiles hold more
        # entries than it has segments, which would make them full draws)
        patch.setattr(soft_raster, "REDRAW_ALL", 1e9)
        _told_moves(raster, points, colors, moves, width, rng)


def _told_moves(raster, points, colors, moves, width, rng):
    yaw, offsets = 0.0, GROOM.offsets
    for strands, what, far, extra, turn in moves:
        moved = np.unique(np.asarray(strands, np.int64))
        for s in moved:
            a, b = offsets[s], offsets[s + 1]
            if what in ("points", "both"):  # a random run of its vertices, maybe one alone
                j = int(rng.integers(a, b))
                k = int(rng.integers(j + 1, b + 1))
                points[j:k] += rng.normal(scale=far, size=(k - j, 3)).astype(np.float32)
            if what in ("colors", "both"):
                colors[a:b] = rng.random((b - a, 3)).astype(np.float32)
        yaw += 0.3 if turn else 0.0
        told = vertex_runs(offsets, np.union1d(moved, np.asarray(extra, np.int64)), gap=4)
        rgba, depth = raster.draw(
            points, STARTS, colors, _mvp(yaw), SIZE, width, clear=(3, 2, 1, 255), changed=told[::-1]
        )
        want = StrandRaster().draw(points, STARTS, colors, _mvp(yaw), SIZE, width, clear=(3, 2, 1, 255))
        np.testing.assert_array_equal(rgba, want[0])
        np.testing.assert_array_equal(depth, want[1])
        if not turn:
            PARTIAL.append(raster.tiles_redrawn >= 0)


PARTIAL: list[bool] = []  # which frames above without a turn were redrawn in part (most)


def test_the_told_frames_were_mostly_redrawn_in_part():
    assert sum(PARTIAL) > len(PARTIAL) // 2


def test_a_told_move_compares_only_its_vertices_and_redraws_in_part(monkeypatch):
    searches = []
    whole = soft_raster._changed_vertices
    monkeypatch.setattr(soft_raster, "_changed_vertices", lambda *a: searches.append(1) or whole(*a))
    points, colors = GROOM.points.copy(), np.full((GROOM.vertex_count, 3), 0.5, np.float32)
    raster, size = StrandRaster(), (320, 240)
    raster.draw(points, STARTS, colors, _mvp(), size, 1.0)
    a, b = GROOM.offsets[7], GROOM.offsets[8]
    points[b - 2 : b] += np.float32(0.002)
    raster.draw(points, STARTS, colors, _mvp(), size, 1.0, changed=[[a, b]])
    assert searches == [] and raster.tiles_redrawn > 0
    points[b - 2 : b] -= np.float32(0.002)  # told nothing: the whole groom is compared
    raster.draw(points, STARTS, colors, _mvp(), size, 1.0)
    assert searches == [1] and raster.tiles_redrawn > 0
    np.testing.assert_array_equal(
        raster.rgba, StrandRaster().draw(points, STARTS, colors, _mvp(), size, 1.0)[0]
    )


@pytest.mark.parametrize("python", [False, True])
def test_the_runs_kernel_flags_what_its_numpy_reference_does(python):
    rng = np.random.default_rng(11)
    v = GROOM.vertex_count
    last_p, last_c = GROOM.points.copy(), rng.random((v, 3)).astype(np.float32)
    p, c = last_p.copy(), last_c.copy()
    hit = rng.random(v) < 0.05
    p[hit] += np.float32(0.01)
    c[rng.random(v) < 0.05] = 0.0
    p[3, 0] = -0.0 if p[3, 0] == 0.0 else p[3, 0]  # (bits, not values)
    runs = merged_runs(rng.integers(0, v, size=(9, 2)).clip(0, v).cumsum(axis=1).clip(0, v), v)
    want_p, want_c = last_p.copy(), last_c.copy()
    want = changed_in_runs_reference(p, c, want_p, want_c, STARTS, runs)
    seg_runs = np.stack(
        [np.searchsorted(STARTS, runs[:, 0] - 1), np.searchsorted(STARTS, runs[:, 1])], axis=1
    )
    which, flags = np.zeros(STARTS.size, bool), np.zeros(v, bool)
    kernel = soft_raster._changed_in_runs.py_func if python else soft_raster._changed_in_runs
    # read-only inputs, as the raster passes them (the warm-up's compilation, not one of the test's own)
    n = kernel(readonly(p), readonly(c), last_p, last_c, readonly(STARTS), runs, seg_runs, flags, which)
    np.testing.assert_array_equal(which, want)
    assert n == want.sum() > 0
    np.testing.assert_array_equal(last_p, want_p)
    np.testing.assert_array_equal(last_c, want_c)


def test_told_ranges_are_merged_and_bad_ones_refused():
    np.testing.assert_array_equal(merged_runs([[6, 9], [0, 2], [2, 4], [8, 12]], 12), [[0, 4], [6, 12]])
    assert merged_runs(np.zeros((0, 2), np.int64), 5).shape == (0, 2)
    for bad in ([[-1, 2]], [[3, 2]], [[0, 13]]):
        with pytest.raises(ParameterError, match="changed"):
            merged_runs(bad, 12)
