"""Brush-local moves: the strands under the brush and those their clumps reach, the rest untouched."""

from __future__ import annotations

import numba
import numpy as np
import pytest

from hairtool import samples
from hairtool.frozen.brushes import BrushSample, falloff_lut
from hairtool.frozen.clump import clump_points
from hairtool.frozen.local import clump_region_reference
from hairtool.frozen.noise import draw_seed
from hairtool.frozen.pipeline import FrozenParams, FrozenPipeline
from hairtool.frozen.vertex_grid import (
    VertexGrid,
    list_frame,
    lists_reference,
    strands_near_reference,
    vertices_near_reference,
)
from hairtool.groom import Groom, vertex_ids_of


@pytest.fixture
def threads():
    before = numba.get_num_threads()
    yield lambda n: numba.set_num_threads(min(n, numba.config.NUMBA_NUM_THREADS))
    numba.set_num_threads(before)


def same_bytes(a: np.ndarray, b: np.ndarray) -> bool:
    return a.shape == b.shape and a.tobytes() == b.tobytes()


def bundles(spacing: float, per_side: int = 6, h: float = 1.0) -> Groom:
    """Bundles of 4 straight-ish strands 0.3 h apart (every strand within the clump reach of
    the others of its bundle), the bundles ``spacing`` h apart: a move's clump stays in its bundle."""
    rng = np.random.default_rng(7)
    strands = []
    for bx in range(per_side):
        for by in range(per_side):
            base = np.array([bx * spacing * h, by * spacing * h, 0.0])
            for dx, dy in ((0, 0), (0.3, 0), (0, 0.3), (0.3, 0.3)):
                root = base + np.array([dx * h, dy * h, 0.0])
                t = np.linspace(0.0, 1.0, 8)[:, None]
                line = root + t * np.array([0.0, 0.0, 4.0 * h]) + rng.normal(scale=0.02 * h, size=(8, 3))
                line[0] = root
                strands.append(line)
    return Groom.from_strands(strands)


def comb(cursor, direction, radius):
    lut = tuple(falloff_lut("smooth").tolist())
    return BrushSample(
        "comb", tuple(map(float, cursor)), tuple(map(float, direction)), float(radius), 0.8, lut
    )


def clump_paint(cursor, radius, strength):
    lut = tuple(falloff_lut("constant").tolist())
    return BrushSample("clump", tuple(map(float, cursor)), (0.0, 0.0, 0.0), float(radius), strength, lut)


def full_run(pipe: FrozenPipeline) -> np.ndarray:
    p = pipe.params
    return clump_points(
        pipe.aligned, pipe.clump_radius, p.clump_iterations, pipe.clump_step, p.gap_mode,
        draw_seed(p.seed, 0), None, p.keep_lengths, pipe.clump_strength,
    )  # fmt: skip


# -- the vertex grid ----------------------------------------------------------------------------
@pytest.mark.parametrize("spacing", [3.0, 50_000.0])  # the list build's row grid, then its hashed one
def test_the_grid_gives_the_lists_of_a_full_build_in_its_order_before_and_after_moves(spacing):
    g = bundles(spacing, per_side=5)
    top, r = g.topology, 1.1
    assert list_frame(g.points, r)[0] == (spacing < 100)
    grid = VertexGrid(g.points, top.strand_index, r)
    vids = np.arange(0, g.vertex_count, 3)
    for k in range(3):
        flat, cnt, cap = grid.lists(g.points, vids, r, list_frame(g.points, r))
        want = lists_reference(g.points, top.strand_index, vids, r)
        for n, w in enumerate(want):
            assert np.array_equal(flat[n * cap : n * cap + cnt[n]], w)
        assert cnt.sum() > vids.size  # (neighbours there are)
        queries = g.points[[3, 40, 100]]
        mark = np.zeros(g.strand_count, bool)
        grid.strands_near(g.points, queries, 2.5, mark)
        assert np.array_equal(
            mark, strands_near_reference(g.points, top.strand_index, queries, 2.5, g.strand_count)
        )
        pts = g.points.copy()  # some strands move across cells
        moved = vertex_ids_of(top, np.arange(k, g.strand_count, 5))
        pts[moved] += np.float32([0.7, -0.4, 0.2])
        g = g.with_points(pts)
        assert grid.move(g.points, moved) > 0


@pytest.mark.parametrize("spacing", [0.6, 3.0])
def test_the_vertices_near_queries_of_other_strands_match_the_reference(spacing):
    """What a move's reach asks the grid: each vertex of another strand than the query's within
    the list radius, those already counted left out, before and after strands move."""
    g = bundles(spacing, per_side=4)
    top, r = g.topology, 1.1
    grid = VertexGrid(g.points, top.strand_index, r)
    rng = np.random.default_rng(5)
    for k in range(3):
        picked = rng.choice(g.vertex_count, 12, replace=False)
        queries = g.points[picked] + rng.normal(scale=0.3, size=(12, 3))
        strands = top.strand_index[picked]
        skip = np.zeros(g.vertex_count, bool)
        skip[rng.choice(g.vertex_count, 20, replace=False)] = True
        want = vertices_near_reference(g.points, top.strand_index, queries, strands, r, skip)
        was = skip.copy()
        got = grid.vertices_near(g.points, queries, strands, r, skip)
        assert want.size > 0 and np.array_equal(got, want)
        was[want] = True
        assert np.array_equal(skip, was)  # the vertices found are flagged, no other
        pts = g.points.copy()
        moved = vertex_ids_of(top, np.arange(k, g.strand_count, 7))
        pts[moved] += np.float32([0.9, -0.5, 0.3])
        g = g.with_points(pts)
        grid.move(g.points, moved)
    with pytest.raises(ValueError, match="cell"):
        grid.vertices_near(g.points, queries, strands, 2 * r, skip)


@pytest.mark.parametrize("spacing", [3.0, 50_000.0])
def test_each_way_of_finding_the_strands_near_queries_matches_the_reference(spacing, monkeypatch):
    """Many queries within a cell's reach go by cell (one walk of the 27 cells per cell of
    queries), one brush over many cells by slabs in parallel, the rest query by query."""
    from hairtool.frozen import vertex_grid

    g = bundles(spacing, per_side=5)
    top, r = g.topology, 1.1
    grid = VertexGrid(g.points, top.strand_index, r)
    rng = np.random.default_rng(3)
    many = g.points[rng.choice(g.vertex_count, 80, replace=False)] + rng.normal(scale=0.4, size=(80, 3))
    used = []
    for name in ("_mark_near_grouped", "_mark_near_wide", "_mark_near"):
        kernel = getattr(vertex_grid, name)
        monkeypatch.setattr(vertex_grid, name, lambda *a, k=kernel, n=name: (used.append(n), k(*a)))
    cases = [
        (many, r, "_mark_near_grouped"),
        (many, 0.4 * r, "_mark_near_grouped"),
        (many, 2.5, "_mark_near"),
    ]
    cases += [(g.points[[5]], 4.0 * r, "_mark_near_wide"), (g.points[[5]], 1e6, "_mark_near")]
    for queries, radius, path in cases:
        used.clear()
        mark = np.zeros(g.strand_count, bool)
        grid.strands_near(g.points, queries, radius, mark)
        assert used == [path]
        want = strands_near_reference(g.points, top.strand_index, queries, radius, g.strand_count)
        assert np.array_equal(mark, want) and 0 < want.sum()


def test_the_blocks_count_their_vertices_across_moves_and_a_brush_skips_only_empty_ones():
    """A brush's box of cells is mostly empty; blocks of 4 × 4 × 4 cells over the groom's box
    count their vertices (one counter for those moved out of it), kept as vertices move, so a
    brush skips the empty blocks' cells and finds what a scan finds."""
    from hairtool.frozen import vertex_grid

    g = bundles(3.0, per_side=5)
    top, r = g.topology, 0.3
    grid = VertexGrid(g.points, top.strand_index, r)
    rng = np.random.default_rng(8)
    pts = g.points.copy()
    for k in range(6):
        moved = np.sort(rng.choice(g.vertex_count, 60, replace=False))
        pts[moved] += rng.normal(scale=2.0 if k % 2 else 0.2, size=(60, 3)).astype(np.float32)
        grid.move(pts, moved)
        origin, dims, shift, count = grid.blocks
        fresh = np.empty_like(count)
        vertex_grid._count_blocks(grid.key, origin, dims, shift, fresh)
        assert np.array_equal(count, fresh) and fresh.sum() == g.vertex_count
        assert 0 < count[-1] < g.vertex_count or k == 0  # (some moved out of the first box)
        for q in pts[rng.choice(g.vertex_count, 3)] + rng.normal(scale=1.0, size=(3, 3)):
            mark = np.zeros(g.strand_count, bool)
            grid.strands_near(pts, q[None], 4.0 * r, mark)  # (the wide brush's path)
            want = strands_near_reference(pts, top.strand_index, q[None], 4.0 * r, g.strand_count)
            assert np.array_equal(mark, want)


def test_a_crowded_block_of_cells_gives_the_full_builds_lists_too():
    """More vertices around a cell than a thread's scratch holds (vertex_grid._BLOCK_ROOM):
    that block gets arrays of its own, and the lists are the full build's all the same."""
    rng = np.random.default_rng(4)
    roots = rng.uniform(-0.2, 0.2, (300, 3))
    pts = roots[:, None, :] + np.linspace(0.0, 0.3, 3)[None, :, None] * np.array([0.0, 1.0, 0.0])
    g = Groom(pts.reshape(-1, 3), np.full(300, 3))
    grid = VertexGrid(g.points, g.topology.strand_index, 1.0)
    vids = np.arange(0, g.vertex_count, 7)
    flat, cnt, cap = grid.lists(g.points, vids, 1.0, list_frame(g.points, 1.0))
    want = lists_reference(g.points, g.topology.strand_index, vids, 1.0)
    assert int(cnt.min()) > 600  # every vertex sees nearly all the others
    for n, w in enumerate(want):
        assert np.array_equal(flat[n * cap : n * cap + cnt[n]], w)


def test_a_brush_wider_than_the_grid_scans_every_vertex():
    g = bundles(3.0, per_side=4)
    grid = VertexGrid(g.points, g.topology.strand_index, 0.05)  # tiny cells: the scan
    mark = np.zeros(g.strand_count, bool)
    grid.strands_near(g.points, g.points[[7]], 30.0, mark)
    assert mark.all()


# -- moves against full runs -------------------------------------------------------------------
@pytest.mark.parametrize(("gap_mode", "keep_lengths"), [("printed", False), ("text", True), ("off", False)])
@pytest.mark.parametrize("n_threads", [1, 2])
def test_where_a_move_stays_in_its_region_it_gives_a_full_runs_bytes(
    gap_mode, keep_lengths, n_threads, threads
):
    threads(n_threads)
    g = bundles(3.0)
    pipe = FrozenPipeline(g, FrozenParams(clump_radius=1.0, gap_mode=gap_mode, keep_lengths=keep_lengths))
    assert same_bytes(pipe.result.points, full_run(pipe))
    tips = g.tips.astype(np.float64)
    for k in range(6):
        shown = pipe.result.points.copy()
        target = tips[4 * (7 * k % 36) + 1]  # one strand of a bundle
        if k % 3 == 2:
            out = pipe.brush(clump_paint(target, 0.2, -0.6))
        elif k % 3 == 1:
            out = pipe.brush(comb(target, (0.2, 0.1, 0.0), 0.2))
        else:
            out = pipe.align(target + np.array([0.5, 0.3, 0.0]), 0.6, 0.8)
        region = pipe.changed
        assert region is not None and 0 < region.size <= 8 and pipe.clump_redone < 0.06
        assert same_bytes(out.points, full_run(pipe))  # the clump reaches no farther: a full run's bytes
        outside = np.ones(g.vertex_count, bool)
        outside[vertex_ids_of(g.topology, region)] = False
        assert same_bytes(out.points[outside], shown[outside])  # the rest: untouched
    assert np.any(pipe.clump_strength < 1.0)


@pytest.mark.parametrize("keep_lengths", [False, True])
def test_a_drag_on_dense_hair_equals_its_numpy_twin_and_leaves_the_rest_alone(keep_lengths):
    g = samples.scalp(1500, 12, seed=3)
    pipe = FrozenPipeline(g, FrozenParams(keep_lengths=keep_lengths, seed=4))
    lo, hi = g.bounds
    extent = float(np.max(hi - lo))
    tips = g.tips.astype(np.float64)
    tip = tips[np.argmin(np.linalg.norm(tips - (lo + hi) / 2, axis=1))]
    h = pipe.clump_radius
    local_moves = 0
    for k in range(5):
        rec = pipe._workspace.recorded  # the last run's trajectories, which the rest is held to
        iterates, forces, result = rec.iterates.copy(), rec.forces.copy(), rec.result.copy()
        shown = pipe.result.points.copy()
        a = 2 * np.pi * k / 5
        if k == 3:
            out = pipe.brush(comb(tip, (0.05 * extent, 0.0, 0.0), 0.05 * extent))
        else:
            out = pipe.align(tip + 0.04 * extent * np.array([np.cos(a), np.sin(a), 0.0]), 0.08 * extent, 0.8)
        region = pipe.changed
        assert region is not None and pipe.clump_redone < 0.5
        local_moves += region.size > 0
        inside = vertex_ids_of(g.topology, region)
        sv = np.asarray(pipe.clump_strength)[g.topology.strand_index]
        want = clump_region_reference(
            pipe.aligned.points, g.topology, pipe.local_clump.vertices, iterates, forces, result, sv,
            h, 3, pipe.clump_step, "printed", draw_seed(4, 0), keep_lengths,
        )  # fmt: skip
        # The same definition; the twin sums the pulls in another order (np.bincount): float32
        # results agree to an ulp or two.
        np.testing.assert_allclose(out.points[inside], want[inside], rtol=0, atol=2e-6 * extent)
        outside = np.ones(g.vertex_count, bool)
        outside[inside] = False
        assert same_bytes(out.points[outside], shown[outside])
        assert same_bytes(out.points, full_run(pipe))  # what the move can change is all redone
        moved = np.flatnonzero(np.any(pipe.aligned.points != pipe.local_clump.record.points, axis=1))
        assert moved.size == 0  # (the record holds this input)
    assert local_moves >= 3


def test_local_moves_are_deterministic_at_1_and_2_threads_and_on_the_serial_twins(threads, monkeypatch):
    """A region below SERIAL_BELOW runs the serial twins, a larger one the parallel kernels:
    the same bytes either way (here the threshold moves so that both run the same drag)."""
    from hairtool.frozen import local

    g = samples.scalp(400, 12, seed=5)
    lo, hi = g.bounds
    extent = float(np.max(hi - lo))
    tip = g.tips[100].astype(np.float64)
    runs = []  # each choice of the kernels: parallel or not
    monkeypatch.setattr(local, "parallel_for", lambda n, f=local.parallel_for: runs.append(f(n)) or runs[-1])
    results = []
    for n, serial_below in ((1, 0), (2, 0), (2, 10**9)):
        threads(n)
        monkeypatch.setattr(local, "SERIAL_BELOW", serial_below)
        runs.clear()
        pipe = FrozenPipeline(g, FrozenParams(keep_lengths=True))
        for k in range(4):
            pipe.align(tip + 0.04 * extent * np.array([np.cos(k), np.sin(k), 0.0]), 0.12 * extent, 0.8)
        assert pipe.clump_redone < 1.0
        assert runs and set(runs) == {serial_below == 0}  # the parallel kernels ran, or their twins
        results.append(pipe.result.points.copy())
    assert same_bytes(*results[:2]) and same_bytes(*results[1:])


def test_undo_and_redo_bring_back_the_moves_result_and_a_replay_runs_in_full():
    g = samples.scalp(300, 10, seed=2)
    pipe = FrozenPipeline(g)
    lo, hi = g.bounds
    extent = float(np.max(hi - lo))
    before, snap = pipe.result.points.copy(), pipe.snapshot()
    pipe.align(g.tips[50].astype(np.float64) + 0.05 * extent, 0.15 * extent, 0.8)
    moved, moved_snap = pipe.result.points.copy(), pipe.snapshot()
    assert pipe.clump_redone < 1.0
    assert same_bytes(pipe.restore(snap).points, before)
    assert same_bytes(pipe.restore(moved_snap).points, moved)
    other = FrozenPipeline(g)
    other.apply_samples(pipe.strokes, local=False)
    assert other.clump_redone == 1.0 and same_bytes(other.result.points, full_run(other))
    # a full run of the same strokes: the same bytes (the local move redid all it could change)
    assert same_bytes(other.aligned.points, pipe.aligned.points)
    assert same_bytes(other.result.points, moved)


def test_delete_and_parameter_changes_run_in_full_and_moves_go_local_again():
    g = samples.scalp(300, 10, seed=2)
    pipe = FrozenPipeline(g)
    tip = g.tips[20].astype(np.float64)
    lut = tuple(falloff_lut("constant").tolist())
    root = tuple(map(float, g.roots[20]))
    pipe.brush(BrushSample("delete", root, (0.0, 0.0, 0.0), 0.05, 1.0, lut))
    assert pipe.clump_redone == 1.0 and pipe.changed is None and pipe.result.strand_count < 300
    pipe.align(tip, 0.2, 0.8)
    assert pipe.clump_redone < 1.0
    pipe.set_params(pipe.params.replace(clump_iterations=2))
    assert pipe.clump_redone == 1.0
    out = pipe.align(tip + 0.02, 0.2, 0.8)
    assert pipe.clump_redone < 1.0 and np.all(np.isfinite(out.points))


def test_the_region_lists_have_room_for_the_full_runs_longest_list_from_the_first_move():
    """Lists longer than the grid's room run again wider: the first move to meet the densest
    vertex used to pay twice (80 ms against 35 on the bear)."""
    g = bundles(spacing=0.6, per_side=8)  # dense bundles: every vertex has many neighbours
    pipe = FrozenPipeline(g, FrozenParams(clump_radius=1.0))
    grid, longest = pipe.local_clump.grid, int(pipe._workspace.neighbours.cnt.max())
    assert longest > 0 and grid.capacity > longest + 1
    before = grid.capacity
    ids = np.arange(g.vertex_count)
    held = pipe._moves.grid_points  # the points the grid and the full run's list were made of
    _, cnt, _ = grid.lists(held, ids, pipe.local_clump.radius, list_frame(held, pipe.local_clump.radius))
    assert int(cnt.max()) == longest and grid.capacity == before


def test_strokes_prepared_ahead_give_the_same_bytes_and_the_first_move_uses_the_room():
    """prepare_strokes (the studio's idle step after an open) computes the scalp's normals and
    centre and makes the region lists' room, touched, before the first move needs them."""
    g = bundles(3.0)
    plain, prepared = (FrozenPipeline(g, FrozenParams(clump_radius=1.0, keep_lengths=True)) for _ in range(2))
    prepared.prepare_strokes(region_share=0.5)
    grid = prepared.local_clump.grid
    room = grid._flat
    assert room.size >= 0.5 * g.vertex_count * grid.capacity
    assert prepared._root_normals is not None and prepared._scalp_centre is not None
    tip = g.tips[3].astype(np.float64)
    for pipe in (plain, prepared):
        for k in range(3):
            pipe.brush(comb(tip + np.array([0.1 * k, 0.0, 0.0]), (1.0, 0.0, 0.0), 0.6))
        assert pipe.clump_redone < 0.5
    assert same_bytes(plain.result.points, prepared.result.points)
    assert grid._flat is room  # the moves' lists fitted the room made ahead
