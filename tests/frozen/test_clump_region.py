"""ClumpWithGaps redone only near what changed: the bytes of a full run, edit after edit."""

from __future__ import annotations

import numba
import numpy as np
import pytest

from hairtool import samples
from hairtool.frozen.align import align
from hairtool.frozen.clump import ClumpWorkspace, clump_points
from hairtool.frozen.clump_region import clump_points_interactive
from hairtool.frozen.spatial import NeighbourList
from hairtool.frozen.strand_clumps import auto_clump_radius
from hairtool.groom import Groom


@pytest.fixture
def threads():
    before = numba.get_num_threads()
    yield lambda n: numba.set_num_threads(min(n, numba.config.NUMBA_NUM_THREADS))
    numba.set_num_threads(before)


def _brush_drag(g: Groom, moves: int, seed: int, depth: float = 0.02, brush: float = 0.2):
    """Aligned grooms of a drag with a brush ``brush`` × the groom wide, circling a middle tip
    (and wandering in z by ``depth`` of its width)."""
    lo, hi = g.bounds
    extent = float(np.max(hi - lo))
    tips = g.tips.astype(np.float64)
    tip = tips[np.argmin(np.linalg.norm(tips - (lo + hi) / 2, axis=1))]
    rng = np.random.default_rng(seed)
    for k in range(moves):
        a = 2 * np.pi * k / moves
        cursor = tip + 0.5 * brush * extent * np.array([np.cos(a), np.sin(a), rng.normal(scale=depth)])
        g = align(g, cursor, brush * extent, 0.8)
        yield g


def _same_bytes(a: np.ndarray, b: np.ndarray) -> bool:
    return np.array_equal(a.view(np.uint32), b.view(np.uint32))


@pytest.mark.parametrize(
    ("gap_mode", "iterations", "step"),
    [("printed", 3, None), ("text", 2, None), ("off", 1, 0.004), ("printed", 4, 0.003)],
)
@pytest.mark.parametrize("n_threads", [1, 2])
def test_a_drag_gives_the_bytes_of_full_runs(gap_mode, iterations, step, n_threads, threads):
    threads(n_threads)
    g = samples.scalp(strands=500, vertices=12, seed=3)
    h = auto_clump_radius(g)
    ws = ClumpWorkspace()
    for aligned in _brush_drag(g, 8, seed=1):
        got = clump_points_interactive(aligned, h, iterations, step, gap_mode, 11, ws)
        full = ClumpWorkspace()
        want = clump_points(aligned, h, iterations, step, gap_mode, 11, full)
        assert _same_bytes(got, want)
        assert ws.step == full.step and ws.mean_neighbours == full.mean_neighbours
    assert ws.region.updates == 7  # all but the first redone in a region
    assert 0.0 < ws.region.fraction < 0.8


def test_vertices_thrown_far_outside_the_groom_and_back(threads):
    g = samples.scalp(strands=300, vertices=10, seed=8)
    h = auto_clump_radius(g)
    ws = ClumpWorkspace()
    clump_points_interactive(g, h, 3, None, "printed", 0, ws)
    points = g.points.copy()
    rng = np.random.default_rng(2)
    for k in range(6):
        s = int(rng.integers(g.strand_count))
        tip = g.offsets[s + 1]
        if k % 2 == 0:  # far off: the grid of this update does not reach where they went
            points[tip - 4 : tip] += np.float32([40.0, -30.0, 25.0])
        else:
            points[tip - 4 : tip] = g.points[tip - 4 : tip] + rng.normal(scale=h, size=(4, 3)).astype(
                np.float32
            )
        moved = g.with_points(points)
        got = clump_points_interactive(moved, h, 3, None, "printed", 0, ws)
        assert _same_bytes(got, clump_points(moved, h, 3, None, "printed", 0, ClumpWorkspace()))
    assert ws.region.updates >= 4


def test_what_runs_in_full_and_what_costs_nothing():
    g = samples.scalp(strands=300, vertices=10, seed=8)
    h = auto_clump_radius(g)
    ws = ClumpWorkspace()
    first = clump_points_interactive(g, h, 3, None, "printed", 0, ws)
    assert ws.region.fraction == 1.0 and ws.recorded.valid
    again = clump_points_interactive(g, h, 3, None, "printed", 0, ws)
    assert ws.region.fraction == 0.0 and _same_bytes(first, again)  # the same input: the last output
    for args in (
        (h * 1.1, 3, None, "printed", 0),
        (h, 2, None, "printed", 0),
        (h, 3, None, "text", 0),
        (h, 3, None, "printed", 1),
    ):
        clump_points_interactive(g, *args, ws)  # another parameter: a full run
        assert ws.region.fraction == 1.0
    everything = g.with_points(g.points + np.float32([0.01, 0.0, 0.0]))
    clump_points_interactive(everything, *args, ws)  # every vertex moved
    assert ws.region.fraction == 1.0
    np.testing.assert_array_equal(clump_points_interactive(g, h, 0, None, "printed", 0, ws), g.points)


def test_a_changed_automatic_step_runs_in_full():
    # A dense tuft: the mean kernel weight is above 1, so the automatic step follows the points.
    rng = np.random.default_rng(4)
    roots = rng.normal(scale=0.05, size=(60, 3))
    strands = [r + np.linspace([0, 0, 0], [0, -1, 0], 8) for r in roots]
    g = Groom.from_strands(strands)
    h = 0.3
    ws = ClumpWorkspace()
    clump_points_interactive(g, h, 3, None, "printed", 0, ws)
    step = ws.step
    assert step < 0.2 * h  # set by the weights, not the cap
    moved = g.points.copy()
    moved[g.offsets[1] - 3 : g.offsets[1]] += np.float32([0.05, 0.0, 0.0])
    got = clump_points_interactive(g.with_points(moved), h, 3, None, "printed", 0, ws)
    full = ClumpWorkspace()
    assert _same_bytes(got, clump_points(g.with_points(moved), h, 3, None, "printed", 0, full))
    assert ws.step == full.step != step and ws.region.fraction == 1.0


def test_a_planar_groom_is_redone_in_its_plane():
    # A fringe: 300 wavy strands side by side along x, in the plane z = 0.
    t = np.linspace(0.0, 1.0, 14)[:, None]
    g = Groom.from_strands(
        [np.hstack([x + 0.03 * np.sin(7 * t + x), -2.0 * t, 0 * t]) for x in np.linspace(0, 10, 300)]
    )
    assert g.is_planar
    h = auto_clump_radius(g)
    ws = ClumpWorkspace()
    for aligned in _brush_drag(g, 5, seed=0, depth=0.0, brush=0.05):
        assert aligned.is_planar
        got = clump_points_interactive(aligned, h, 3, None, "printed", 0, ws)
        assert _same_bytes(got, clump_points(aligned, h, 3, None, "printed", 0, ClumpWorkspace()))
        assert not np.any(got[:, 2])
    assert ws.region.updates >= 3


@pytest.mark.parametrize("every", [1, 7])
def test_region_lists_are_the_full_lists_in_their_order(every):
    g = samples.scalp(strands=400, vertices=12, seed=6)
    h = auto_clump_radius(g) * 1.1
    skip = np.zeros(g.vertex_count, bool)
    full = NeighbourList()
    full.build(g.points, g.topology.strand_index, skip, h)
    part = NeighbourList()
    assert part.sort(g.points, g.topology.strand_index, skip, h)
    np.testing.assert_array_equal(part.order, full.order)
    positions = np.arange(0, g.vertex_count, every)
    nbr, cnt = part.region_lists(positions, 4)  # too small for some: counted, cut
    assert cnt.max() >= 4
    nbr, cnt = part.region_lists(positions, int(cnt.max()) + 1)
    for n, k in enumerate(positions):
        np.testing.assert_array_equal(nbr[n, : cnt[n]], full.order[full.of(k)])
