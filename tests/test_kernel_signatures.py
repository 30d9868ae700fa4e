"""A kernel compiles once per dtype, whatever the write flag or memory order of the caller's
arrays: numba types both, and each variant is a compile of its own (seconds for a parallel
kernel, on a studio's first run and on every fresh clone's test run, where the variants the
tests' own writable arrays asked for took about a hundred compiles). Each public entry here is
called with a writable, a read-only and (where it takes any) a Fortran-ordered copy of the same
input; every signature its kernel holds afterwards takes that input read-only and C-ordered, and
the answers agree bit for bit."""

from __future__ import annotations

from dataclasses import astuple

import numpy as np
import pytest

from app.render import screen_pick
from hairtool import samples, serial_twins
from hairtool.anime import pose
from hairtool.anime.schedule import schedule
from hairtool.anime.wave import WaveParams, make_bunches, pose_pictures
from hairtool.bounds import _box, box
from hairtool.frozen import freeze, lengths, neighbour_update, spatial, vertex_grid
from hairtool.frozen.freeze import _freeze_kernel
from hairtool.groom import Animation
from hairtool.guides import child_clumps, children
from hairtool.guides.binding import bind_roots
from hairtool.keys import features
from hairtool.keys.reconstruct import _curve_distances, key_curve_errors, key_poses


def variants(a: np.ndarray, fortran: bool = True) -> list[np.ndarray]:
    """``a`` writable, read-only and (``fortran``) in Fortran order: the same values."""
    ro = a.copy()
    ro.flags.writeable = False
    return [a.copy(), ro, *([np.asfortranarray(a)] if fortran else [])]


_before: dict[int, set] = {}  # each kernel's signatures as the test began


@pytest.fixture(autouse=True)
def _signatures_before():
    """What every kernel held before the test: another file in this worker may have called a
    kernel directly with writable arrays (a kernel-against-numpy test), and those signatures
    are not the product's."""
    import sys

    from numba.core.registry import CPUDispatcher

    _before.clear()
    for name, module in list(sys.modules.items()):
        if module is not None and name.startswith(("hairtool.", "app.render.")):
            for value in list(vars(module).values()):
                if isinstance(value, CPUDispatcher):
                    _before[id(value)] = set(value.signatures)
    yield


def argument_types(kernel, index: int) -> list:
    """The types at ``index`` of the signatures ``kernel`` compiled during this test."""
    old = _before.get(id(kernel), set())
    return [sig[index] for sig in kernel.signatures if sig not in old]


def assert_one_signature(kernel, index: int) -> None:
    assert kernel.signatures, "the kernel ran"
    kinds = argument_types(kernel, index)
    assert all(t.layout == "C" and not t.mutable for t in kinds), kinds


def assert_one_signature_each_twin(kernel, *indexes: int, callee: bool = False) -> None:
    """:func:`assert_one_signature` at each argument of ``indexes``, for a twinned kernel its
    parallel kernel and its serial twin both (whichever this process runs). A ``callee`` (a
    kernel only other kernels call) holds signatures only where its callers compiled, not where
    they came from the cache: its callers' types are its own."""
    twinned = serial_twins.is_twinned(kernel)
    pair = (serial_twins.parallel_of(kernel), serial_twins.serial(kernel)) if twinned else (kernel,)
    assert callee or any(k.signatures for k in pair), "the kernel ran"
    for k in pair:
        for i in indexes:
            kinds = argument_types(k, i)
            assert all(t.layout == "C" and not t.mutable for t in kinds), (k, i, kinds)


@pytest.mark.parametrize("dtype", [np.float32, np.float64])
def test_box(dtype):
    p = np.random.default_rng(1).standard_normal((40, 3)).astype(dtype)
    got = [box(a) for a in variants(p)]
    assert all(np.array_equal(g[0], got[0][0]) and np.array_equal(g[1], got[0][1]) for g in got)
    assert_one_signature(_box, 0)


def test_resampled_frames():
    frames = np.random.default_rng(2).standard_normal((3, 9, 3)).astype(np.float32)
    counts = np.array([4, 5])
    got = [features.resample_frames(f, counts, 6) for f in variants(frames, fortran=False)]
    assert all(np.array_equal(g, got[0]) for g in got)
    assert_one_signature(features._resample_kernel, 0)


def test_pose_times():
    g = samples.scalp(12, 6, seed=3)
    params = WaveParams(1.5, 0.4, -0.9, 2.5, 0.8)
    bunches = make_bunches(g, seed=11, amplitude_spread=0.5, phase_spread=1.0)
    times = schedule(params.period, 6, 2).picture_times
    got = [pose_pictures(g, params, t, bunches) for t in variants(np.asarray(times), fortran=False)]
    assert all(np.array_equal(x, got[0]) for x in got)
    assert_one_signature(pose._pose_kernel, 6)


def test_children_and_their_clumps():
    guides = samples.scalp(8, 5, seed=3)
    b = bind_roots(guides, count=40, seed=4)
    kids = b.build()
    got = []
    for p in variants(kids.points, fortran=False):  # the studio's live points are writable
        run = child_clumps.ChildClumps(b.guide_ids, 8, 0.08, 2, None, "printed", 1, False)
        got.append(run.run(p, kids.topology).copy())
    assert all(np.array_equal(x, got[0]) for x in got)
    assert_one_signature(child_clumps._clumps_kernel, 0)
    assert_one_signature(child_clumps._clumps_kernel, 1)
    assert_one_signature(children._children_kernel, 10)


def test_freeze_of_a_y_up_and_a_z_up_groom():
    """A Y-up groom's points reach the kernel as the groom holds them (read-only), a Z-up
    groom's as a fresh array in the reference axes."""
    g = samples.scalp(5, 4, seed=3)
    for groom in (g, g.with_metadata(g.metadata.with_(up_axis="Z"))):
        freeze(groom, seed=2)
    assert_one_signature_each_twin(_freeze_kernel, 0, 1)


def test_restored_lengths():
    g = samples.scalp(5, 4, seed=3)
    moved = g.points + np.float32(0.01) * np.random.default_rng(5).standard_normal(g.points.shape, np.float32)
    got = [
        lengths.restore_lengths(b, a, g.topology, parallel=parallel)
        for b, a in zip(variants(g.points), variants(moved), strict=True)
        for parallel in (True, False)
    ]
    assert all(np.array_equal(x, got[0]) for x in got)
    assert_one_signature_each_twin(lengths._restore_kernel, 0, 1, 2)


def test_moved_vertices():
    before = samples.scalp(5, 4, seed=3).points
    now = before.copy()
    now[[3, 7]] += np.float32(0.5)
    got = [
        neighbour_update.moved_vertices(p, r) for p, r in zip(variants(now), variants(before), strict=True)
    ]
    assert all(np.array_equal(x, [3, 7]) for x in got)
    assert_one_signature_each_twin(neighbour_update._moved_mask, 0, 1)


def test_the_vertex_grid_built_moved_and_searched():
    g = samples.scalp(6, 5, seed=3)
    strand = g.topology.strand_index
    moved = g.points.copy()
    moved[[4, 11]] += np.float32(0.3)
    one, many = g.points[[2]].astype(np.float64), g.points[[2, 9, 20]].astype(np.float64)
    got = []
    # the strands as a topology holds them (read-only) or as a caller made them (writable)
    strands = [*variants(strand, fortran=False), strand]
    for p, q, s in zip(variants(g.points), variants(moved), strands, strict=True):
        grid = vertex_grid.VertexGrid(p, s, 1.0)
        changed = grid.move(q, np.array([4, 11]))
        marks = []
        for queries, radius in ((one, 0.6), (many, 1.5), (many, 0.5)):  # wide, each, grouped
            for parallel in (True, False):
                mark = np.zeros(6, np.bool_)
                grid.strands_near(q, queries, radius, mark, parallel)
                marks.append(mark)
        got.append((changed, grid.key.copy(), np.array(marks)))
    assert all(x[0] == got[0][0] and np.array_equal(x[1], got[0][1]) for x in got)
    assert all(np.array_equal(x[2], got[0][2]) for x in got)
    for kernel in (vertex_grid._build, vertex_grid._move, vertex_grid._mark_near_grouped):
        assert_one_signature_each_twin(kernel, 0)
    for kernel in (vertex_grid._mark_near_wide, vertex_grid._mark_near):
        assert_one_signature_each_twin(kernel, 0, 1)
    assert_one_signature_each_twin(vertex_grid._mark_slab, 0, 1, callee=True)


@pytest.mark.parametrize("dense", [True, False])
def test_neighbour_lists(dense):
    g = samples.scalp(6, 5, seed=3)
    got = []
    for p, s in zip(variants(g.points), variants(g.topology.strand_index), strict=True):
        nl = spatial.neighbour_list(p, s, 0.3, dense=dense)
        got.append((nl.order.copy(), nl.x.copy(), nl.acnt.copy()))
    assert all(all(np.array_equal(a, b) for a, b in zip(x, got[0], strict=True)) for x in got)
    assert_one_signature_each_twin(spatial._row_sort if dense else spatial._cell_keys, 0)
    assert_one_signature_each_twin(spatial._row_keys, 0, callee=True)
    gather = spatial._gather if dense else spatial._gather_hashed
    assert_one_signature_each_twin(gather, 1, 2, 3)


def test_nearest_on_screen():
    g = samples.scalp(6, 5, seed=3)
    view = np.eye(4)
    skip = np.zeros(6, np.bool_)
    skip[1] = True
    got = [
        screen_pick.nearest_on_screen(p, view, (200.0, 100.0), (100.0, 50.0), 80.0, s, k)
        for p, s, k in zip(variants(g.points), variants(g.topology.strand_index), variants(skip), strict=True)
    ]
    assert got[0] >= 0 and all(x == got[0] for x in got)
    assert_one_signature_each_twin(screen_pick._nearest_kernel, 0, 7, 8)


@pytest.mark.parametrize("dtype", [np.float32, np.float64])
def test_guide_frame_tables(dtype):
    # A video of render hair hands the tables each frame's guides as a float64 copy (writable):
    # the kernel then compiled a second time at the first export (12 s on a fresh clone).
    from hairtool.groom import Groom
    from hairtool.guides import frames

    g = samples.scalp(10, 6, seed=5)
    tangent = np.tile([0.0, -1.0, 0.0], (g.strand_count, 1))
    got = [
        frames.guide_tables(Groom(p, g.counts), 4, t)
        for p in variants(g.points.astype(dtype))
        for t in variants(tangent, fortran=False)
    ]
    assert all(np.array_equal(a, b) for x in got for a, b in zip(x, got[0], strict=True))
    assert_one_signature_each_twin(frames._tables_kernel, 0, 4, 5)


def test_key_curve_errors_of_a_strided_animation():
    """An Animation keeps the memory order of the frames it was given (a capture's bones are a
    gather along the vertex axis: strided, as ``app.document.capture.skeleton_animation`` makes
    them); the key-curve distances see C-ordered read-only frames whatever it is."""
    frames = np.random.default_rng(4).standard_normal((5, 9, 3))
    strided = np.ascontiguousarray(frames.transpose(1, 0, 2)).transpose(1, 0, 2)
    anims = [Animation(f, np.full(3, 3)) for f in (frames, strided)]
    assert anims[0].frames.flags.c_contiguous and not anims[1].frames.flags.c_contiguous
    for interp in ("linear", "hermite"):
        c, f = (key_curve_errors(a, key_poses(a.frames, [0, 2, 4], interp)) for a in anims)
        assert all(np.array_equal(x, y) for x, y in zip(astuple(c), astuple(f), strict=True))
    assert_one_signature(_curve_distances, 0)


@pytest.mark.parametrize("dtype", [np.float32, np.float64])
def test_sight_of_points_and_strands(dtype):
    # A box selection, Add and Density ask about fresh float64 copies, a press about the groom's
    # own read-only points: each dtype compiles once (a writable float64 copy had compiled the
    # sight kernel again at the studio's first box selection by sight).
    from hairtool.frozen.brushes import sight
    from hairtool.frozen.brushes.sight import hidden_points, hidden_strands
    from hairtool.guides.planting import HeadSurface
    from hairtool.io.obj import Mesh

    v = np.array([[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]], np.float32) * 0.5
    f = np.array([[0, 2, 4], [2, 1, 4], [1, 3, 4], [3, 0, 4], [2, 0, 5], [1, 2, 5], [3, 1, 5], [0, 3, 5]])
    grid = HeadSurface(Mesh(v, f.astype(np.int32), v)).face_grid
    g = samples.scalp(10, 6, seed=2)
    pts = g.points.astype(dtype) - g.points.mean(axis=0).astype(dtype)
    view = (0.0, 0.0, -1.0)
    seen = [hidden_points(p, view, grid) for p in variants(pts)]
    assert all(np.array_equal(s, seen[0]) for s in seen)
    whole = [
        hidden_strands(p, o, (0.0, 0.0, 0.0), 9.0, view, grid)
        for p in variants(pts)
        for o in variants(g.offsets, fortran=False)
    ]
    assert all(np.array_equal(s, whole[0]) for s in whole)
    assert_one_signature(sight._points_kernel, 0)
    assert_one_signature(sight._hidden_kernel, 0)
    assert_one_signature(sight._hidden_kernel, 1)
