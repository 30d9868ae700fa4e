"""ClumpWithGaps among each guide's children: the whole-groom run on each clump's children alone
(numba path and numpy twin) is the oracle; an update after a stroke redoes only the clumps it
touched, with a fresh run's bytes; bad input gets one clear error."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from hairtool import io, samples
from hairtool.errors import ParameterError
from hairtool.guides.binding import bind_roots, bind_scalp
from hairtool.guides.child_clumps import (
    ChildClumps,
    clump_children,
    clump_children_reference,
    clump_jobs,
    clump_of_children,
    clump_seeds,
)
from hairtool.guides.render import ChildClump, RenderHair
from hairtool.io.obj import read_mesh

RESOURCES = Path(__file__).resolve().parents[2] / "resources"


@pytest.fixture(scope="module")
def sintel_children():
    guides = io.read_groom(RESOURCES / "sintel_hair.tfx")
    b = bind_scalp(guides, read_mesh(RESOURCES / "sintel_head.obj"), 1500, seed=2)
    lo, hi = guides.bounds
    push = np.float32(0.05 * float(np.max(hi - lo)))
    swung = guides.points + push * guides.topology.vertex_param[:, None] * np.array([1, 0, 0.3], np.float32)
    moved = guides.with_points(swung)
    return guides, b, b.build(moved), RenderHair(b, ChildClump()).clump_radius


@pytest.mark.slow(seconds=4)
@pytest.mark.parametrize("gap_mode", ["printed", "text", "off"])
@pytest.mark.parametrize("keep_lengths", [True, False])
def test_each_clump_is_the_whole_groom_run_on_its_children(sintel_children, gap_mode, keep_lengths):
    guides, b, kids, h = sintel_children
    got = clump_children(kids, b.guide_ids, guides.strand_count, h, 3, None, gap_mode, 4, keep_lengths)
    want = clump_children_reference(
        kids, b.guide_ids, guides.strand_count, h, 3, None, gap_mode, 4, keep_lengths, numpy=False
    )
    assert np.abs(got - kids.points).max() > 0.05 * h  # it does clump
    np.testing.assert_allclose(got, want, rtol=0, atol=1e-6 * h)


@pytest.mark.parametrize("gap_mode", ["printed", "off"])
def test_the_numpy_twin_agrees(sintel_children, gap_mode):
    guides, b, kids, h = sintel_children
    got = clump_children(kids, b.guide_ids, guides.strand_count, h, 2, None, gap_mode, 0, False)
    want = clump_children_reference(kids, b.guide_ids, guides.strand_count, h, 2, None, gap_mode, 0, False)
    np.testing.assert_allclose(got, want, rtol=0, atol=1e-6 * h)


def test_a_dense_scalp_with_a_given_step_agrees_too():
    guides = samples.scalp(60, 12, seed=3)
    b = bind_roots(guides, count=1200, seed=4)
    kids = b.build()
    h = 0.08
    got = clump_children(kids, b.guide_ids, 60, h, 4, 0.01, "printed", 9, True)
    want = clump_children_reference(kids, b.guide_ids, 60, h, 4, 0.01, "printed", 9, True, numpy=False)
    assert np.abs(got - kids.points).max() > 1e-3
    np.testing.assert_allclose(got, want, rtol=0, atol=1e-6 * h)


def test_children_of_other_guides_do_not_pull(sintel_children):
    """One clump moved far away changes no other clump's bytes."""
    guides, b, kids, h = sintel_children
    start, members = clump_of_children(b.guide_ids, guides.strand_count)
    g = int(np.argmax(np.diff(start)))
    kids_of_g = members[start[g] : start[g + 1]]
    rows = np.concatenate([np.arange(kids.offsets[c], kids.offsets[c + 1]) for c in kids_of_g])
    away = kids.points.copy()
    away[rows] += np.float32(0.3 * h)  # a shift within reach of its neighbours
    base = clump_children(kids, b.guide_ids, guides.strand_count, h)
    shifted = clump_children(kids.with_points(away), b.guide_ids, guides.strand_count, h)
    others = np.ones(kids.vertex_count, bool)
    others[rows] = False
    assert shifted[others].tobytes() == base[others].tobytes()


def test_an_update_after_a_stroke_redoes_only_the_touched_clumps(sintel_children):
    guides, b, _, _ = sintel_children
    rh = RenderHair(b, ChildClump(iterations=2))
    rh.update_points(guides)
    stroke = guides.points.copy()
    near = np.argsort(np.linalg.norm(guides.roots - guides.roots[0], axis=1))[:10]  # under a brush
    for s in near:
        a, e = guides.offsets[s], guides.offsets[s + 1]
        stroke[a:e] += np.float32(0.2) * guides.topology.vertex_param[a:e, None]
    got = rh.update_points(guides.with_points(stroke)).copy()
    assert 0 < rh.clumps.clumps_run < guides.strand_count / 4
    fresh = RenderHair(b, ChildClump(iterations=2)).update(guides.with_points(stroke)).points
    assert got.tobytes() == fresh.tobytes()
    assert rh.update_points(guides.with_points(stroke)).tobytes() == fresh.tobytes()  # nothing moved
    assert rh.clumps.clumps_run == 0


def test_clump_seeds_differ_per_guide_and_follow_the_seed():
    a, b = clump_seeds(0, 50), clump_seeds(1, 50)
    assert len(set(a.tolist())) == 50 and not np.array_equal(a, b)
    assert np.array_equal(a, clump_seeds(0, 50)) and a.min() >= 0 and a.max() < 2**53


def test_bad_input_gives_one_clear_error(sintel_children):
    guides, b, kids, h = sintel_children
    with pytest.raises(ParameterError, match="clump_radius"):
        ChildClumps(b.guide_ids, guides.strand_count, -1.0)
    with pytest.raises(ParameterError, match="gap_mode"):
        clump_children(kids, b.guide_ids, guides.strand_count, h, gap_mode="wet")
    with pytest.raises(ParameterError, match="seed"):
        ChildClumps(b.guide_ids, guides.strand_count, h, seed=-1)


def test_clump_jobs_deal_every_clump_once_and_balance_the_work():
    work = np.random.default_rng(3).uniform(0, 3000, 40)
    clumps = np.arange(0, 40, 3)
    jobs, start = clump_jobs(work, clumps, 2)
    assert sorted(jobs.tolist()) == clumps.tolist() and start[0] == 0 and start[-1] == clumps.size
    loads = [work[jobs[start[j] : start[j + 1]]].sum() + 64 * (start[j + 1] - start[j]) for j in range(2)]
    assert abs(loads[0] - loads[1]) <= work[clumps].max() + 64  # greedy: within one clump
    for j in range(2):
        assert np.all(np.diff(jobs[start[j] : start[j + 1]]) > 0)  # each job in increasing order
    one, s1 = clump_jobs(work, np.array([4]), 2)
    assert one.tolist() == [4] and s1.tolist() == [0, 1]  # never more jobs than clumps


def test_the_bytes_are_the_same_at_one_and_two_threads(sintel_children):
    import numba

    guides, b, kids, h = sintel_children
    before = numba.get_num_threads()
    got = []
    try:
        for n in (1, min(2, numba.config.NUMBA_NUM_THREADS)):
            numba.set_num_threads(n)
            run = ChildClumps(b.guide_ids, guides.strand_count, h, 2)
            whole = run.run(kids.points, kids.topology).copy()
            redo = np.zeros(guides.strand_count, bool)
            redo[::7] = True
            shifted = kids.points + np.float32(0.01) * kids.topology.vertex_param[:, None]
            got.append(
                (whole.tobytes(), run.run(shifted, kids.topology, redo).tobytes(), run.stats.tobytes())
            )
    finally:
        numba.set_num_threads(before)
    assert got[0] == got[-1]
