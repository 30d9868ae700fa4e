"""The groom shapes the bundled grooms lack (a ponytail gathered into a tie, curls, a straight
cut, several hair systems): each well formed and seeded, and a brush move on each changes only
the strands it reaches, as its numpy twin says, through the brush-local path (not the whole
groom). Small versions of the shapes ``hairtool bench freeze --sizes shapes`` measures."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, Phase, given, settings
from hypothesis import strategies as st

from hairtool.errors import ParameterError
from hairtool.frozen.brushes import BrushSample, falloff_lut
from hairtool.frozen.clump import clump_points
from hairtool.frozen.local import clump_region_reference, reach_reference
from hairtool.frozen.noise import draw_seed
from hairtool.frozen.pipeline import FrozenParams, FrozenPipeline
from hairtool.groom import vertex_ids_of
from hairtool.guides import shapes
from hairtool.prims import split

SMALL = {"ponytail": (700, 12), "curls": (500, 16), "straight": (300, 8), "systems": (800, 8)}


def small(name: str, seed: int = 0):
    return shapes.shape(name, *SMALL[name], seed=seed)


@pytest.mark.parametrize("name", list(shapes.SHAPES))
def test_each_shape_is_seeded_rooted_on_the_head_and_outside_it(name):
    g = small(name)
    assert (g.strand_count, g.vertex_count) == (SMALL[name][0], SMALL[name][0] * SMALL[name][1])
    assert g.points.tobytes() == small(name).points.tobytes()
    assert g.points.tobytes() != small(name, seed=1).points.tobytes()
    assert np.all(np.isfinite(g.points))
    assert np.allclose(np.linalg.norm(g.roots, axis=1), 1.0, atol=1e-5)
    assert np.all(np.linalg.norm(g.points, axis=1) >= 1.0 - 1e-5)
    assert np.all(g.segment_lengths > 0)


def test_the_ponytail_converges_into_one_tie_and_the_curls_turn():
    g = small("ponytail")
    half = SMALL["ponytail"][1] // 2
    strands = g.points.reshape(g.strand_count, -1, 3)
    tie = strands[:, half - 1]
    assert np.max(np.linalg.norm(tie - [0.0, 0.55, -1.15], axis=1)) <= 0.08 + 1e-5  # every strand in the tie
    assert np.ptp(g.roots, axis=0).max() > 1.0  # from all over the back of the head
    curls = small("curls")
    c = curls.points.reshape(curls.strand_count, -1, 3)
    assert np.all(curls.strand_lengths > 1.4 * np.linalg.norm(c[:, -1] - c[:, 0], axis=1))  # coiled


def test_the_hair_systems_are_three_prims_apart():
    g = small("systems")
    paths = [c.path for c in g.metadata.curves]
    assert paths == ["/Head/Hair", "/Head/Brows", "/Head/Beard"]
    parts = split(g)
    assert sum(p.strand_count for p in parts) == g.strand_count
    brows = parts[1]
    assert np.max(brows.strand_lengths) < 0.1  # short, apart from the hair


def test_unknown_shapes_and_sizes_are_refused_by_name():
    with pytest.raises(ParameterError, match="shape"):
        shapes.shape("mullet")
    with pytest.raises(ParameterError, match="vertices"):
        shapes.shape("curls", 10, 2)
    with pytest.raises(ParameterError, match="strands"):
        shapes.shape("systems", 3, 8)


def full_run(pipe: FrozenPipeline) -> np.ndarray:
    p = pipe.params
    return clump_points(
        pipe.aligned, pipe.clump_radius, p.clump_iterations, pipe.clump_step, p.gap_mode,
        draw_seed(p.seed, 0), None, p.keep_lengths, pipe.clump_strength,
    )  # fmt: skip


def _comb(cursor, direction, radius):
    lut = tuple(falloff_lut("smooth").tolist())
    return BrushSample(
        "comb", tuple(map(float, cursor)), tuple(map(float, direction)), float(radius), 0.8, lut
    )


@pytest.mark.parametrize("name", list(shapes.SHAPES))
@settings(
    max_examples=3,
    deadline=None,
    derandomize=True,
    phases=[Phase.explicit, Phase.generate],
    suppress_health_check=[HealthCheck.too_slow],
)
@given(pick=st.floats(0.0, 1.0), angle=st.floats(0.0, 2 * np.pi))
def test_a_move_on_each_shape_changes_only_the_strands_it_reaches(name, pick, angle):
    g = small(name)
    pipe = FrozenPipeline(g, FrozenParams(seed=4))
    lo, hi = g.bounds
    extent = float(np.max(hi - lo))
    radius = 0.05 * extent
    tips = g.tips.astype(np.float64)
    tip = tips[min(int(pick * g.strand_count), g.strand_count - 1)]
    rec = pipe._workspace.recorded  # the full run's trajectories, which the rest is held to
    iterates, forces, result = rec.iterates.copy(), rec.forces.copy(), rec.result.copy()
    best = rec.best.copy()
    shown = pipe.result.points.copy()
    before = pipe.aligned.points.copy()
    step = 0.05 * extent * np.array([np.cos(angle), np.sin(angle), 0.0])
    out = pipe.brush(_comb(tip, step, radius))
    region = pipe.changed
    assert region is not None and 0 < pipe.clump_redone < 1.0  # the brush-local path, not the groom
    inside = vertex_ids_of(g.topology, region)
    brushed = np.flatnonzero(np.any(pipe.aligned.points != before, axis=1))
    assert brushed.size > 0 and np.isin(brushed, inside).all()  # what the brush moved is redone
    hit = np.unique(g.topology.strand_index[brushed])
    under = np.linalg.norm(before - tip, axis=1) <= radius * (1 + 1e-6)
    assert np.logical_or.reduceat(under, g.offsets[:-1])[hit].all()  # only strands under the brush
    local = pipe.local_clump  # redone: every vertex whose clumping the brushed ones can change, no other
    strand = g.topology.strand_index
    reach = reach_reference(before, pipe.aligned.points, strand, brushed, local.radius, best, "printed")
    assert np.array_equal(local.vertices, reach)
    sv = np.asarray(pipe.clump_strength)[g.topology.strand_index]
    want = clump_region_reference(
        pipe.aligned.points, g.topology, local.vertices, iterates, forces, result, sv,
        pipe.clump_radius, 3, pipe.clump_step, "printed", draw_seed(4, 0),
    )  # fmt: skip
    # the twin sums the pulls in another order (np.bincount): float32 results agree to an ulp or two
    np.testing.assert_allclose(out.points[inside], want[inside], rtol=0, atol=2e-6 * extent)
    outside = np.ones(g.vertex_count, bool)
    outside[inside] = False
    assert outside.any()
    assert out.points[outside].tobytes() == shown[outside].tobytes()  # the rest untouched, bit for bit
    assert out.points.tobytes() == full_run(pipe).tobytes()  # and all of it a full run's bytes
