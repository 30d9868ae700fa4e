"""The uniform-grid neighbour list, the auto clump radius and clump components."""

from __future__ import annotations

import numpy as np
import pytest

from hairtool import samples
from hairtool.groom import Groom
from hairtool.io import read_groom
from hairtool.spatial import neighbour_list, pairs_within_reference
from hairtool.strand_clumps import (
    auto_clump_radius,
    median_root_spacing,
    strand_components,
    strand_components_reference,
)


def _pairs_of(nl) -> set[tuple[int, int]]:
    out = set()
    for k in range(len(nl.order)):
        for n in range(nl.cnt[k]):
            out.add((int(nl.order[k]), int(nl.order[nl.nbr[k, n]])))
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


def test_neighbour_list_grows_its_capacity():
    # 200 strands through one point: every vertex there has 199 neighbours
    pts = np.zeros((200, 2, 3))
    pts[:, 1, 1] = np.linspace(1, 2, 200)
    g = Groom(pts.reshape(-1, 3), np.full(200, 2))
    nl = neighbour_list(g.points, g.topology.strand_index, 0.5)
    assert nl.capacity >= 199
    assert _pairs_of(nl) == _brute_pairs(g.points, g.topology.strand_index, 0.5)


def test_auto_clump_radius_is_twice_the_median_root_spacing():
    g = samples.comb(100, 5, spacing=0.05)
    assert median_root_spacing(g) == pytest.approx(0.05)
    assert auto_clump_radius(g) == pytest.approx(0.1)
    # one strand: no spacing, falls back to segment lengths
    one = g.subset([0])
    assert auto_clump_radius(one) == pytest.approx(2 * float(np.median(one.segment_lengths)))


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
