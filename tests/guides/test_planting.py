"""Planting builds new strands from only the strands they blend: the same bytes as building
them from the whole groom (what :meth:`HeadSurface.grow` did before it took the subset)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from hairtool import io
from hairtool.frozen.root_grid import nearest_root_reference
from hairtool.guides.binding import DEFAULT_K, bind_roots
from hairtool.guides.planting import HeadSurface
from hairtool.io.obj import read_mesh

DATA = Path(__file__).resolve().parents[1] / "data" / "grooms"
GROOM = io.read_groom(DATA / "sintel_hair.tfx")
HEAD = HeadSurface(read_mesh(DATA / "sintel_head.obj"))


def grown_from_the_whole_groom(groom, roots):
    k = min(DEFAULT_K, groom.strand_count)
    binding = bind_roots(groom, roots, k=k, length_variation=0.0, frizz=0.0)
    built = binding.build(groom)
    return built.subset(np.argsort(nearest_root_reference(roots, binding.roots)))


@settings(max_examples=6, deadline=None)
@given(st.integers(0, GROOM.strand_count - 1), st.floats(0.2, 4.0), st.integers(1, 300), st.integers(0, 99))
def test_grown_strands_are_those_the_whole_groom_builds(root, radius, count, seed):
    rng = np.random.default_rng(seed)
    near = GROOM.roots[root] + rng.uniform(-radius, radius, size=(count, 3))
    roots, _ = HEAD.project(near)
    new, want = HEAD.grow(GROOM, roots), grown_from_the_whole_groom(GROOM, roots)
    np.testing.assert_array_equal(new.counts, want.counts)
    assert new.points.tobytes() == want.points.tobytes()
