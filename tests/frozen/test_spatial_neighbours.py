"""The uniform-grid neighbour list, the auto clump radius and clump components."""

from __future__ import annotations

import numpy as np
import pytest

from hairtool import samples
from hairtool.frozen.pipeline import FrozenPipeline
from hairtool.frozen.spatial import neighbour_list, pairs_within_reference
from hairtool.frozen.strand_clumps import (
    auto_clump_radius,
    median_root_spacing,
    median_root_spacing_reference,
    strand_clumps,
    strand_clumps_reference,
    strand_components,
    strand_components_reference,
)
from hairtool.groom import Groom
from hairtool.io import read_groom


def _pairs_of(nl) -> set[tuple[int, int]]:
    out = set()
    for k in range(len(nl.order)):
        for j in nl.of(k):
            out.add((int(nl.order[k]), int(nl.order[j])))
    return out


def _brute_pairs(p, strand, r):
    d = np.linalg.norm(p[:, None].astype(np.float64) - p[None], axis=-1)
    i, j = np.nonzero((d < r) & (strand[:, None] != strand[None]))
    return set(zip(i.tolist(), j.tolist(), strict=True))


@pytest.mark.parametrize("dense", [True, False, None])
def test_neighbour_list_finds_exactly_the_pairs_within_radius(dense):
    g = samples.scalp(150, 12, seed=3)
    strand = g.topology.strand_index
    r = 0.15
    nl = neighbour_list(g.points, strand, r, dense=dense)
    expect = _brute_pairs(g.points, strand, r)
    assert _pairs_of(nl) == expect
    i, j = pairs_within_reference(g.points, strand, r)
    assert set(zip(i.tolist(), j.tolist(), strict=True)) == expect
    assert len(expect) > 100


@pytest.mark.parametrize("dense", [True, False])
def test_neighbour_list_grows_its_capacity(dense):
    # 200 strands through one point: every vertex there has 199 neighbours
    pts = np.zeros((200, 2, 3))
    pts[:, 1, 1] = np.linspace(1, 2, 200)
    g = Groom(pts.reshape(-1, 3), np.full(200, 2))
    nl = neighbour_list(g.points, g.topology.strand_index, 0.5, dense=dense)
    assert int(nl.cnt.max()) == 199
    assert dense or nl.capacity >= 199
    assert _pairs_of(nl) == _brute_pairs(g.points, g.topology.strand_index, 0.5)
    # The same list object rebuilt for a sparse groom of the same size shrinks its reserve
    # and still finds exactly the pairs (float32 points, as a groom holds them: float64 ones would
    # compile the kernels once more for this test alone).
    shift = np.repeat(np.linspace(0, 50, 200), 2)[:, None] * np.float32([1, 0, 0])
    spread = (g.points + shift).astype(np.float32)
    nl.build(spread, g.topology.strand_index, np.zeros(400, bool), 0.5, dense)
    assert _pairs_of(nl) == _brute_pairs(spread, g.topology.strand_index, 0.5)


def test_auto_clump_radius_is_twice_the_median_root_spacing():
    g = samples.comb(100, 5, spacing=0.05)
    assert median_root_spacing(g) == pytest.approx(0.05)
    assert auto_clump_radius(g) == pytest.approx(0.1)
    # one strand: no spacing, falls back to segment lengths
    one = g.subset([0])
    assert auto_clump_radius(one) == pytest.approx(2 * float(np.median(one.segment_lengths)))


@pytest.mark.parametrize("name", ["bear.tfx", "ratboy_mohawk.tfx", "sintel_hair.tfx", "ponytail_tail.tfx"])
def test_the_median_root_spacing_kernel_matches_its_numpy_twin(grooms_dir, name):
    g = read_groom(grooms_dir / name)
    assert median_root_spacing(g) == median_root_spacing_reference(g) > 0.0


def test_the_median_root_spacing_on_render_hair_roots_and_awkward_grooms():
    from hairtool.guides.binding import bind_roots

    guides = samples.scalp(strands=40, vertices=6)
    roots = guides.points[guides.topology.offsets[:-1]].astype(np.float64)
    rng = np.random.default_rng(3)
    kids = bind_roots(guides, roots[rng.integers(0, 40, 3000)] + rng.normal(0, 1e-3, (3000, 3)), k=3, seed=0)
    children = kids.build(guides)
    assert median_root_spacing(children) == median_root_spacing_reference(children) > 0.0
    same_place = Groom(np.zeros((8, 3), np.float32), np.full(4, 2))  # every root in one place
    assert median_root_spacing(same_place) == median_root_spacing_reference(same_place) == 0.0
    pairs = samples.comb(6, 3, spacing=0.05)  # few strands: the radius doubles until they meet
    pairs = pairs.subset([0, 5])
    assert median_root_spacing(pairs) == median_root_spacing_reference(pairs) > 0.0


def test_auto_clump_radius_on_real_grooms(grooms_dir):
    g = read_groom(grooms_dir / "ponytail_tail.tfx")
    roots = g.roots.astype(np.float64)
    d = np.linalg.norm(roots[:, None] - roots[None], axis=-1)
    d[d <= 1e-9 * d.max()] = np.inf
    assert auto_clump_radius(g) == pytest.approx(2 * np.median(d.min(axis=1)), rel=1e-6)


@pytest.mark.parametrize("radius", [0.02, 0.06, 0.2])
def test_strand_components_match_numpy_twin(radius):
    g = samples.scalp(300, 10, seed=2)
    a = strand_components(g, radius)
    b = strand_components_reference(g, radius)
    np.testing.assert_array_equal(a, b)
    assert a[0] == 0 and a.max() + 1 == len(np.unique(a))


def test_strand_components_of_separated_groups():
    a = np.linspace([0, 0, 0], [0, -1, 0], 5)
    strands = [a + np.array([dx, 0.0, 0.0]) for dx in (0.0, 0.01, 3.0, 3.01, 9.0)]
    ids = strand_components(Groom.from_strands(strands), 0.05)
    np.testing.assert_array_equal(ids, [0, 0, 1, 1, 2])


@pytest.mark.parametrize(
    "make",
    [
        lambda: samples.scalp(300, 10, seed=2),
        lambda: samples.portrait(200, 12),
        lambda: samples.comb(120, 8, seed=1),
    ],
    ids=["scalp", "portrait", "comb"],
)
def test_strand_clumps_match_numpy_twin(make):
    g = make()
    for radius in (0.5, 1.0, 2.0):
        h = radius * auto_clump_radius(g)
        np.testing.assert_array_equal(strand_clumps(g, h), strand_clumps_reference(g, h))


def test_strand_clumps_of_separated_groups():
    # Three tight groups of three strands, far apart: three clumps, numbered by first strand.
    a = np.linspace([0, 0, 0], [0, -1, 0], 6)
    strands = [a + np.array([gx + dx, 0.0, 0.0]) for gx in (0.0, 5.0, 10.0) for dx in (0.0, 0.02, 0.04)]
    ids = strand_clumps(Groom.from_strands(strands), 0.05)
    np.testing.assert_array_equal(ids, [0, 0, 0, 1, 1, 1, 2, 2, 2])


@pytest.mark.parametrize(
    "name", ["sintel_hair.tfx", "ratboy_mohawk.tfx", "ponytail_back.tfx", "ponytail_front_top.tfx"]
)
def test_real_grooms_give_many_clumps_of_sensible_size(grooms_dir, name):
    # The studio colours the pipeline's result by clump: it must not be one colour (connected
    # components at h percolate through the roots into one clump) nor one colour per strand.
    g = read_groom(grooms_dir / name)
    pipe = FrozenPipeline(g)
    ids = pipe.clump_ids()
    np.testing.assert_array_equal(ids, strand_clumps_reference(pipe.result, pipe.clump_radius))
    sizes = np.bincount(ids)
    assert len(sizes) >= max(10, g.strand_count // 60), f"{len(sizes)} clumps"
    assert sizes.max() <= 0.25 * g.strand_count, f"largest clump {sizes.max()} of {g.strand_count}"
    assert np.median(sizes) >= 3
    assert np.mean(sizes == 1) <= 0.15
    # What the old membership gave: one component holding (nearly) everything.
    components = np.bincount(strand_components(pipe.result, pipe.clump_radius))
    assert components.max() >= 0.5 * g.strand_count


@pytest.mark.parametrize("name", ["bear", "sintel_hair", "ponytail_back"])
def test_the_backward_lists_are_the_numpy_twins(grooms_dir, name):
    """The parallel transpose (each chunk counting into a window of its own) gives every vertex
    the vertices that found it in increasing order, as the numpy twin does, and each backward
    entry's pair among the forward entries."""
    from hairtool.frozen import spatial

    g = read_groom(grooms_dir / f"{name}.tfx")
    nl = neighbour_list(g.points, g.topology.strand_index, 1.1 * auto_clump_radius(g))
    v = len(nl.order)
    finder = np.repeat(np.arange(v), nl.acnt)  # forward entries: i (sorted position) found j
    first = np.repeat(nl.aoff - np.cumsum(np.r_[0, nl.acnt[:-1]]), nl.acnt)
    entry = first + np.arange(finder.size)
    found = nl.aflat[entry].astype(np.int64)
    assert np.all(found > finder) and finder.size > v
    bstart, bflat, bmap = spatial.transpose_reference(finder, found, entry, v)
    n = bstart[-1]
    assert np.array_equal(nl.bstart, bstart) and np.array_equal(nl.bflat[:n], bflat)
    assert np.array_equal(nl.bmap[:n], bmap) and np.array_equal(
        nl.aflat[bmap], np.repeat(np.arange(v), np.diff(bstart))
    )
