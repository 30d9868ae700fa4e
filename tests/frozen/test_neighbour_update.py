"""A neighbour list brought up to date where strands moved is the list a build gives: every
vertex's entries, in the same order, on sparse scalps and dense real grooms; an update declines
where a build must follow; a clump run on an updated list gives the build's bytes."""

from __future__ import annotations

from unittest import mock

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from hairtool import samples
from hairtool.frozen import neighbour_update
from hairtool.frozen.clump import ClumpWorkspace, clump_points
from hairtool.frozen.neighbour_update import moved_vertices, moved_vertices_reference, update_list
from hairtool.frozen.spatial import NeighbourList
from hairtool.frozen.strand_clumps import auto_clump_radius
from hairtool.groom import Groom
from hairtool.io import read_groom


def forward_entries(nl: NeighbourList) -> np.ndarray:
    """Every vertex's forward entries in order, concatenated (the layout in aflat aside)."""
    first = np.repeat(nl.aoff - np.cumsum(np.r_[0, nl.acnt[:-1]]), nl.acnt)
    return nl.aflat[first + np.arange(int(nl.acnt.sum()))]


def assert_same_lists(a: NeighbourList, b: NeighbourList) -> None:
    for name in ("order", "x", "y", "z", "strand", "skip", "acnt", "bstart"):
        assert np.array_equal(getattr(a, name), getattr(b, name)), name
    assert np.array_equal(a.start, b.start)
    assert np.array_equal(forward_entries(a), forward_entries(b))
    n = int(a.bstart[-1])
    assert np.array_equal(a.bflat[:n], b.bflat[:n])
    # each backward entry names the same one of its finder's forward entries
    assert np.array_equal(a.bmap[:n] - a.aoff[a.bflat[:n]], b.bmap[:n] - b.aoff[b.bflat[:n]])
    assert a.forward_entries == b.forward_entries


def stroke(points, strand, is_root, centre, reach, shift):
    """The strands with a vertex within ``reach`` of ``centre`` moved as a comb moves them: by
    ``shift`` times the share of the way from root to tip (roots stay)."""
    near = np.unique(strand[np.linalg.norm(points - centre, axis=1) < reach])
    vid = np.flatnonzero(np.isin(strand, near))
    step = np.zeros(len(points))
    for s in near:  # 0 at the root, 1 at the tip
        v = vid[strand[vid] == s]
        step[v] = np.linspace(0.0, 1.0, len(v))
    out = points.copy()
    out[vid] += (step[vid, None] * np.asarray(shift)[None]).astype(points.dtype)
    out[is_root] = points[is_root]
    return out


def lists_of(groom):
    r = 1.1 * float(auto_clump_radius(groom))
    strand = np.asarray(groom.topology.strand_index, np.int64)
    is_root = np.zeros(groom.vertex_count, bool)
    is_root[groom.topology.root_indices] = True
    return r, strand, is_root


# How many of the six strokes update (the rest build, where update_pays says a build costs
# less): a stroke on the mohawk moves strands that run the length of the grid's slowest axis, so
# the rows between its first and last moved vertex are most of the groom.
@pytest.mark.parametrize(
    "name, updates",
    [("scalp", 4), ("bear", 5), ("ratboy_mohawk", 3), ("ponytail_front_top", 4), ("sintel_hair", 3)],
)
def test_strokes_update_the_list_to_the_one_a_build_gives(grooms_dir, name, updates):
    g = samples.scalp(2000, 12, seed=4) if name == "scalp" else read_groom(grooms_dir / f"{name}.tfx")
    r, strand, is_root = lists_of(g)
    nl = NeighbourList()
    pts = g.points.copy()
    nl.build(pts, strand, is_root, r)
    rng = np.random.default_rng(7)
    ext = float(np.max(pts.max(0) - pts.min(0)))
    updated = 0
    for k in range(6):
        centre = pts[rng.integers(len(pts))]
        reach = (0.03 if k % 2 else 0.08) * ext
        new = stroke(pts, strand, is_root, centre, reach, rng.normal(size=3) * 3 * r)
        moved = moved_vertices(new, pts)
        assert np.array_equal(moved, moved_vertices_reference(new, pts))
        if update_list(nl, new, pts, strand, is_root, moved):
            updated += 1
        else:
            nl.build(new, strand, is_root, r)
        built = NeighbourList()
        built.build(new, strand, is_root, r)
        assert_same_lists(nl, built)
        pts = new
    assert updated >= updates


def always_pays():
    """The update runs wherever it can, paying or not (its result is what is under test)."""
    return mock.patch.object(neighbour_update, "update_pays", lambda *_: True)


def test_an_update_declines_when_the_grid_moves_or_a_build_costs_less():
    g = samples.scalp(2000, 10, seed=2)
    r, strand, is_root = lists_of(g)
    nl = NeighbourList()
    nl.build(g.points, strand, is_root, r)
    tip = g.topology.offsets[1] - 1
    near = g.points.copy()
    near[tip] += np.float32(0.1 * r)
    assert update_list(nl, near, g.points, strand, is_root, np.array([tip]))  # one vertex: it pays
    most = near + np.float32(0.01)
    most[is_root] = near[is_root]
    assert not update_list(nl, most, near, strand, is_root, moved_vertices(most, near))
    assert not neighbour_update.update_pays(0.2, 0.0, 10**6)  # a fifth of the groom
    assert not neighbour_update.update_pays(0.0, 0.5, 5000)  # a small groom's long stretch
    nl.build(g.points, strand, is_root, r)
    far = g.points.copy()
    far[tip] += 100.0  # the box, and so the grid, grows
    with always_pays():
        assert not update_list(nl, far, g.points, strand, is_root, np.array([tip]))
        assert update_list(nl, g.points.copy(), g.points, strand, is_root, np.zeros(0, np.int64))  # no move
        hashed = NeighbourList()
        hashed.build(g.points, strand, is_root, r, dense=False)
        assert not update_list(hashed, near, g.points, strand, is_root, np.array([tip]))


def test_a_chunk_that_outgrows_its_room_leaves_the_list_to_a_build():
    g = samples.scalp(1500, 12, seed=5)
    r, strand, is_root = lists_of(g)
    nl = NeighbourList()
    nl.build(g.points, strand, is_root, r)
    nl.limit = nl.base + 1  # as if each chunk had room for one entry
    pts = g.points
    new = stroke(pts, strand, is_root, pts[len(pts) // 2], 0.1, (0.0, 0.0, 3 * r))
    with always_pays():
        assert not update_list(nl, new, pts, strand, is_root, moved_vertices(new, pts))
        assert nl.chunks is None  # half rewritten: nothing updates it again
        assert not update_list(nl, new, pts, strand, is_root, moved_vertices(new, pts))


def test_a_clump_run_on_an_updated_list_gives_the_bytes_of_a_fresh_one(grooms_dir):
    g = read_groom(grooms_dir / "bear.tfx")
    h = float(auto_clump_radius(g))
    ws = ClumpWorkspace()
    clump_points(g, h, 3, None, "printed", 1, ws)
    _, strand, is_root = lists_of(g)
    new = stroke(g.points, strand, is_root, g.points[1234], 0.05 * np.ptp(g.points[:, 0]), (0, 2 * h, h))
    moved_g = g.with_points(new)
    got = clump_points(moved_g, h, 3, None, "printed", 1, ws)
    assert (ws.builds, ws.updates) == (1, 1)
    fresh = clump_points(moved_g, h, 3, None, "printed", 1, ClumpWorkspace())
    assert got.tobytes() == fresh.tobytes()


def test_a_full_run_after_a_stroke_on_the_bear_updates_its_list_to_a_build_s_bytes(grooms_dir):
    from hairtool.frozen.brushes import BrushSample, falloff_lut
    from hairtool.frozen.pipeline import FrozenParams, FrozenPipeline

    g = read_groom(grooms_dir / "bear.tfx")
    lut = tuple(falloff_lut("smooth").tolist())
    ext = float(np.ptp(g.points[:, 0]))
    tip = g.tips[500].astype(np.float64)
    at = [tuple(map(float, tip + np.array([0.01 * k * ext, 0.0, 0.0]))) for k in range(4)]
    moves = [[BrushSample("comb", c, (0.01 * ext, 0.0, 0.0), 0.05 * ext, 0.8, lut)] for c in at]
    updated, built = FrozenPipeline(g, FrozenParams(seed=3)), FrozenPipeline(g, FrozenParams(seed=3))
    for batch in moves:
        updated.apply_samples(batch)
        built.apply_samples(batch)
    assert updated.unsettled and updated.neighbour_builds == 1
    released = updated.settle().points.copy()
    built._workspace.invalidate()  # its full run builds the list from scratch
    a, b = updated.update().points, built.update().points
    assert (updated.neighbour_builds, updated.neighbour_updates) == (1, 1)
    assert built.neighbour_builds == 2
    assert a.tobytes() == b.tobytes() == released.tobytes()


@pytest.mark.parametrize("which", ["holds the box's extreme", "grows the box"])
def test_the_box_after_an_update_is_the_box_of_the_points(which):
    """An update finds the new box from the moved points alone, unless one of them held an
    extreme of the old one; either way the list is a build's and its box the points' box."""
    from hairtool.bounds import box

    g = samples.scalp(1500, 12, seed=8)
    r, strand, is_root = lists_of(g)
    nl = NeighbourList()
    nl.build(g.points, strand, is_root, r)
    new = g.points.copy()
    tip = int(np.argmax(np.where(is_root, -np.inf, g.points[:, 0])))  # the non-root vertex of largest x
    assert g.points[tip, 0] == g.points[:, 0].max()  # it holds the box's largest x
    new[tip, 0] += np.float32(-0.3 * r if which == "holds the box's extreme" else 0.2 * r)
    with always_pays():
        updated = update_list(nl, new, g.points, strand, is_root, np.array([tip]))
    if not updated:
        nl.build(new, strand, is_root, r)
    built = NeighbourList()
    built.build(new, strand, is_root, r)
    assert_same_lists(nl, built)
    lo, hi = box(new)
    assert np.array_equal(nl.raw_box[0], lo) and np.array_equal(nl.raw_box[1], hi)
    assert updated


def test_undoing_and_redoing_a_stroke_on_the_bear_give_back_its_results_on_an_updated_list(grooms_dir):
    from hairtool.frozen.brushes import BrushSample, falloff_lut
    from hairtool.frozen.pipeline import FrozenParams, FrozenPipeline

    g = read_groom(grooms_dir / "bear.tfx")
    lut = tuple(falloff_lut("smooth").tolist())
    ext = float(np.ptp(g.points[:, 0]))
    pipe = FrozenPipeline(g, FrozenParams(seed=5))
    before, shown = pipe.snapshot(), pipe.result.points.copy()
    c = tuple(map(float, g.tips[900]))
    pipe.apply_samples([BrushSample("comb", c, (0.02 * ext, 0.01 * ext, 0.0), 0.05 * ext, 0.9, lut)])
    pipe.settle()
    stroked = pipe.snapshot()
    after = pipe.result.points.copy()
    assert not np.array_equal(after, shown)
    assert pipe.restore(before).points.tobytes() == shown.tobytes()  # undo
    assert pipe.restore(stroked).points.tobytes() == after.tobytes()  # redo
    # the release runs nothing; the undo finds the list as it was built, the redo updates it
    assert pipe.neighbour_builds == 1 and pipe.neighbour_updates == 1


# Any moves of the vertices in a ball: points on a coarse lattice (exact ties in x, so that rows
# order by index, and vertices exactly r apart), moved a little or far, some onto other vertices,
# roots too. Whatever the update accepts must be the build's list.
MOVES = settings(derandomize=True, max_examples=60, deadline=None)


@MOVES
@given(
    seed=st.integers(0, 2**32 - 1),
    ball=st.sampled_from([0.5, 1.0, 2.0]),
    reach=st.sampled_from([0.3, 1.0, 4.0]),
)
def test_any_moves_update_to_the_list_a_build_gives(seed, ball, reach):
    rng = np.random.default_rng(seed)
    strands, per = 150, 6
    r = 0.5
    pts = (rng.integers(0, 24, size=(strands * per, 3)) * 0.25).astype(np.float32)  # ties on a 0.25 lattice
    pts[0] = (0.0, 0.0, 0.0)  # the box: moves inside it keep the grid
    pts[1] = (6.0, 6.0, 6.0)
    g = Groom(pts, np.full(strands, per))
    strand = np.asarray(g.topology.strand_index, np.int64)
    is_root = np.zeros(len(pts), bool)
    is_root[g.topology.root_indices] = True
    nl = NeighbourList()
    nl.build(pts, strand, is_root, r, dense=True)
    centre = rng.random(3) * 6.0
    moved = np.flatnonzero(np.linalg.norm(pts - centre, axis=1) < ball)
    moved = moved[moved > 1]
    new = pts.copy()
    step = rng.normal(size=(moved.size, 3)) * reach * r
    onto = rng.random(moved.size) < 0.2  # some exactly onto another vertex
    step[onto] = pts[rng.integers(2, len(pts), onto.sum())] - pts[moved[onto]]
    new[moved] = np.clip(pts[moved] + step, 0.0, 6.0).astype(np.float32)
    moved = moved_vertices(new, pts)
    with always_pays():
        if not update_list(nl, new, pts, strand, is_root, moved):
            nl.build(new, strand, is_root, r, dense=True)
    built = NeighbourList()
    built.build(new, strand, is_root, r, dense=True)
    assert_same_lists(nl, built)
