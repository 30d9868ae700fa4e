"""Children from guides: equal to the reference, a dense groom given back to the bit, only the
children of a moved guide move, roots on the scalp, lengths within the variation, the same
bytes at 1 and 2 threads, and one clear error for bad input."""

from __future__ import annotations

from pathlib import Path

import numba
import numpy as np
import pytest

from hairtool import io, samples
from hairtool.errors import HairtoolError, ParameterError
from hairtool.groom import Groom
from hairtool.guides.binding import bind_dense, bind_roots, bind_scalp, bind_to_guides, choose_guides
from hairtool.guides.children import (
    build_points,
    build_points_reference,
    moved_guides,
    moved_guides_reference,
)
from hairtool.guides.render import ChildClump, RenderHair
from hairtool.guides.surface import closest_points
from hairtool.io.obj import Mesh, read_mesh
from hairtool.rotation import axis_angle_matrix

RESOURCES = Path(__file__).resolve().parents[2] / "resources"


@pytest.fixture(scope="module")
def sintel():
    return io.read_groom(RESOURCES / "sintel_hair.tfx"), read_mesh(RESOURCES / "sintel_head.obj")


@pytest.fixture
def threads():
    before = numba.get_num_threads()
    yield lambda n: numba.set_num_threads(min(n, numba.config.NUMBA_NUM_THREADS))
    numba.set_num_threads(before)


def _bits(a: np.ndarray) -> np.ndarray:
    return np.ascontiguousarray(a, np.float32).view(np.uint32)


def test_children_of_untouched_guides_equal_the_reference(sintel):
    guides, head = sintel
    b = bind_scalp(guides, head, 400, seed=3, frizz=0.05)
    np.testing.assert_allclose(build_points(b, guides), build_points_reference(b, guides), rtol=0, atol=1e-5)
    loose = bind_roots(guides, count=300, seed=1, vertices=20)  # guides resampled from 32 to 20
    np.testing.assert_allclose(build_points(loose, guides), build_points_reference(loose, guides), atol=1e-5)


def test_a_dense_groom_bound_to_its_guides_comes_back_to_the_bit(grooms_dir):
    dense = io.read_groom(grooms_dir / "ratboy_mohawk.tfx")
    guides, b = bind_dense(dense, 150, seed=2)
    assert guides.strand_count == 150
    assert np.array_equal(_bits(b.build().points), _bits(dense.points))
    np.testing.assert_allclose(build_points_reference(b, guides), dense.points, atol=0)
    # Varying vertex counts, and a planar groom (z = 0 stays 0).
    rng = np.random.default_rng(0)
    mixed = Groom.from_strands([rng.normal(size=(int(n), 3)).cumsum(axis=0) for n in rng.integers(3, 12, 80)])
    _g2, b2 = bind_dense(mixed, 12, k=3, seed=1)
    assert np.array_equal(_bits(b2.build().points), _bits(mixed.points))
    comb = samples.comb(60, 10)
    _g3, b3 = bind_dense(comb, 8, seed=0)
    assert np.array_equal(_bits(b3.build().points), _bits(comb.points))


def test_moving_one_guide_moves_only_the_children_that_weight_it(sintel, grooms_dir):
    guides, head = sintel
    b = bind_scalp(guides, head, 2000, seed=5)
    before = b.build().points.reshape(b.child_count, -1, 3)
    g = 17
    pts = guides.points.copy()
    a, e = guides.offsets[g], guides.offsets[g + 1]
    pts[a + 1 : e] += (
        np.array([0.5, -0.3, 0.2], np.float32) * np.linspace(0, 1, e - a - 1, dtype=np.float32)[:, None]
    )
    after = b.build(guides.with_points(pts)).points.reshape(b.child_count, -1, 3)
    uses = np.any(b.guide_ids == g, axis=1)
    weighs = np.any((b.guide_ids == g) & (b.weights > 0), axis=1)
    moved = np.any(after != before, axis=(1, 2))
    assert weighs.sum() > 10
    assert not np.any(moved & ~uses)
    assert np.all(moved[weighs])
    assert np.all(after[:, 0] == before[:, 0])  # roots stay
    dense = io.read_groom(grooms_dir / "ponytail_tail.tfx")
    dg, db = bind_dense(dense, 40, seed=0)
    pts = dg.points.copy()
    pts[dg.offsets[3] + 2 : dg.offsets[4]] += 0.3
    out = db.build(dg.with_points(pts)).points.reshape(-1, 3)
    changed = np.unique(db.topology.strand_index[np.any(out != dense.points, axis=1)])
    assert set(changed) <= set(np.flatnonzero(np.any(db.guide_ids == 3, axis=1)))
    assert len(changed) > 0


def test_children_of_the_moved_guides_alone_built_again_give_the_bytes_of_a_full_build(sintel, grooms_dir):
    # As the studio does per mouse move: into the last frame's points, the children of the guides
    # that moved since (bit for bit); guides moved back count as moved too.
    guides, head = sintel
    dense = io.read_groom(grooms_dir / "ratboy_mohawk.tfx")
    for g0, b in (
        (guides, bind_scalp(guides, head, 1500, seed=5, frizz=0.05)),
        bind_dense(dense, 60, seed=1),
    ):
        rng = np.random.default_rng(2)
        out = build_points(b, g0)
        last = np.array(g0.points)
        pts = np.array(g0.points)
        for step in range(5):
            for s in rng.choice(g0.strand_count, size=3, replace=False):
                a, e = g0.offsets[s], g0.offsets[s + 1]
                pts[a + 1 : e] += rng.normal(scale=0.02, size=(e - a - 1, 3)).astype(np.float32)
            if step == 3:
                pts[:] = g0.points  # all back at rest
            now = g0.with_points(pts)
            moved = moved_guides(now, last)
            np.testing.assert_array_equal(moved, moved_guides_reference(now, last))
            assert 0 < moved.sum() < g0.strand_count
            build_points(b, now, out=out, moved=moved)
            np.testing.assert_array_equal(_bits(out), _bits(build_points(b, now)))
            last = pts.copy()
        assert not moved_guides(now, last).any()
        assert moved_guides(now, last[:-1]).all()  # another shape: nothing is known
    signed = np.array(g0.points)  # one coordinate of guide 2 negated (0 → −0: other bits)
    signed[g0.offsets[2] + 1, 0] = -signed[g0.offsets[2] + 1, 0] if signed[g0.offsets[2] + 1, 0] else -0.0
    assert moved_guides(g0.with_points(signed), np.array(g0.points)).tolist() == [
        s == 2 for s in range(g0.strand_count)
    ]


def test_roots_lie_on_the_scalp_in_the_default_region(sintel):
    guides, head = sintel
    b = bind_scalp(guides, head, 3000, seed=8)
    on, _ = closest_points(head, b.roots)
    lo, hi = head.vertices.min(axis=0), head.vertices.max(axis=0)
    size = float(np.linalg.norm(hi - lo))
    assert np.linalg.norm(on - b.roots, axis=1).max() <= 1e-5 * size
    built = b.build()
    assert np.linalg.norm(closest_points(head, built.roots)[0] - built.roots, axis=1).max() <= 1e-5 * size
    assert built.roots[:, 1].min() > guides.roots[:, 1].min() - 2.0  # not down the neck
    face = (built.roots[:, 2] > 7.0) & (built.roots[:, 1] < 38.0)  # her forehead and face
    assert not np.any(face)


@pytest.mark.parametrize("variation", [0.0, 0.2])
def test_children_keep_the_guide_lengths_within_the_variation(sintel, variation):
    guides, head = sintel
    b = bind_scalp(guides, head, 1500, seed=4, length_variation=variation, frizz=0.0)
    kids = b.build()
    expected = (b.weights * guides.strand_lengths[b.guide_ids]).sum(axis=1)
    ratio = kids.strand_lengths / expected
    np.testing.assert_allclose(ratio, b.scale, rtol=1e-5)
    assert ratio.min() >= 1 - variation - 1e-5 and ratio.max() <= 1 + variation + 1e-5
    frizzy = bind_scalp(guides, head, 1500, seed=4, length_variation=variation, frizz=0.01)
    ratio = frizzy.build().strand_lengths / expected
    assert np.abs(ratio / frizzy.scale - 1).max() <= 0.01  # frizz 0.01 changes a length by < 1 %


def test_guides_that_turn_carry_their_children(sintel):
    guides, head = sintel
    b = bind_scalp(guides, head, 500, seed=6, frizz=0.0)
    rest = b.build().points.reshape(500, -1, 3).astype(np.float64)
    r = axis_angle_matrix([0.3, 0.2, 0.9], 0.6)
    p = guides.points.reshape(guides.strand_count, -1, 3).astype(np.float64)
    turned = p[:, :1] + (p - p[:, :1]) @ r.T  # every guide turned about its own root
    out = b.build(guides.with_points(turned.reshape(-1, 3))).points.reshape(500, -1, 3)
    want = rest[:, :1] + (rest - rest[:, :1]) @ r.T
    np.testing.assert_allclose(out, want, atol=2e-3)  # float32 guides; the tips move by ~6 units


def test_the_same_bytes_at_one_and_two_threads(sintel, grooms_dir, threads):
    guides, head = sintel
    dense = io.read_groom(grooms_dir / "ponytail_back.tfx")
    runs = []
    for n in (1, 2):
        threads(n)
        b = bind_scalp(guides, head, 2000, seed=9, frizz=0.02)
        moved = guides.with_points(guides.points + np.float32(0.1) * guides.topology.vertex_param[:, None])
        dg, db = bind_dense(dense, 60, seed=1)
        rh = RenderHair(b, ChildClump(iterations=2))
        runs.append(
            [b.build(moved).points, db.build(dg).points, choose_guides(dense, 60, 1), rh.update().points]
        )
    for a, c in zip(*runs, strict=True):
        assert a.tobytes() == c.tobytes()


def test_clumping_the_children_pulls_them_together_and_keeps_lengths(sintel):
    guides, head = sintel
    b = bind_scalp(guides, head, 3000, seed=2)
    plain = RenderHair(b).update()
    rh = RenderHair(b, ChildClump(iterations=3))
    clumped = rh.update()
    assert rh.clumps.mean_neighbours > 0
    np.testing.assert_array_equal(clumped.roots, plain.roots)
    assert np.abs(clumped.points - plain.points).max() > 1e-3
    np.testing.assert_allclose(clumped.segment_lengths, plain.segment_lengths, rtol=1e-4)


def test_bad_input_gives_one_clear_error(sintel):
    guides, head = sintel
    with pytest.raises(ParameterError, match="guides_per_child"):
        bind_scalp(guides, head, 100, k=229)
    with pytest.raises(ParameterError, match="count"):
        bind_scalp(guides, head, 0)
    empty = Mesh(head.vertices, np.zeros((0, 3), np.int32), head.normals)
    with pytest.raises(ParameterError, match="scalp"):
        bind_scalp(guides, empty, 100)
    nan_head = Mesh(np.full_like(head.vertices, np.nan), head.faces, head.normals)
    with pytest.raises(ParameterError, match="scalp"):
        bind_scalp(guides, nan_head, 100)
    with pytest.raises(ParameterError, match="density"):
        bind_scalp(guides, head, 100, density=-np.ones(len(head.vertices)))
    with pytest.raises(ParameterError, match="roots"):
        bind_roots(guides, np.array([[0.0, np.nan, 1.0]]))
    with pytest.raises(ParameterError, match="density"):
        bind_scalp(guides, head, 100, density=np.full(len(head.faces), np.nan))
    with pytest.raises(ParameterError, match="region"):
        bind_scalp(guides, head, 100, region=np.zeros(len(head.faces), bool))
    with pytest.raises(ParameterError, match="guides"):
        bind_dense(guides, 0)
    with pytest.raises(ParameterError, match="length_variation"):
        bind_roots(guides, count=10, length_variation=1.5)
    b = bind_roots(guides, count=10)
    with pytest.raises(ParameterError, match="guides"):
        b.build(guides.subset(np.arange(10)))
    with pytest.raises(HairtoolError):  # NaN in guides never reaches the kernels
        guides.with_points(np.full_like(guides.points, np.nan))


def test_a_face_set_of_the_mesh_file_selects_where_hair_grows(tmp_path):
    obj = tmp_path / "scalp.obj"
    grid = [f"v {x} 0 {z}" for z in range(4) for x in range(4)]
    quads = [(z * 4 + x + 1, z * 4 + x + 2, z * 4 + x + 6, z * 4 + x + 5) for z in range(3) for x in range(3)]
    lines = [*grid, "g scalp"]
    lines += [f"f {a} {b} {c} {d}" for a, b, c, d in quads[:3]]
    lines += ["g neck skin"] + [f"f {a} {b} {c} {d}" for a, b, c, d in quads[3:]]
    obj.write_text("\n".join(lines) + "\n")
    mesh = read_mesh(obj)
    assert set(mesh.groups) == {"scalp", "neck", "skin"}
    np.testing.assert_array_equal(mesh.groups["scalp"], np.arange(6))  # 3 quads, 6 triangles
    guides = Groom.from_strands(
        [[[x + 0.5, 0, z + 0.5], [x + 0.5, 1, z + 0.5]] for x in range(3) for z in range(3)]
    )
    b = bind_scalp(guides, mesh, 500, region="scalp", frizz=0.0)
    assert np.all(b.roots[:, 2] <= 1.0 + 1e-9) and np.all(np.isin(b.faces, mesh.groups["scalp"]))
    with pytest.raises(ParameterError, match="scalp, skin"):
        bind_scalp(guides, mesh, 10, region="hat")


def test_a_subset_of_the_children_builds_to_the_same_points(sintel, grooms_dir):
    guides, head = sintel
    b = bind_scalp(guides, head, 1000, seed=1)
    moved = guides.with_points(guides.points + np.float32(0.2) * guides.topology.vertex_param[:, None])
    every_tenth = np.arange(0, 1000, 10)
    whole = b.build(moved).points.reshape(1000, -1, 3)
    part = b.subset(every_tenth).build(moved).points.reshape(100, -1, 3)
    assert part.tobytes() == whole[every_tenth].tobytes()
    dense = io.read_groom(grooms_dir / "ponytail_tail.tfx")
    _, db = bind_dense(dense, 30)
    ids = np.array([5, 2, 400])
    assert db.subset(ids).build().points.tobytes() == dense.subset(ids).points.tobytes()
    with pytest.raises(ParameterError, match="children"):
        b.subset([1000])


def test_dense_grooms_and_given_roots_bind_along_the_surface(sintel):
    guides, head = sintel
    dense = bind_scalp(guides, head, 1500, seed=3).build()  # a dense groom on her head
    _, db = bind_dense(dense, 120, seed=1, mesh=head)
    assert db.faces is not None and len(db.faces) == 1500
    assert db.build().points.tobytes() == dense.points.tobytes()
    _, flat = bind_dense(dense, 120, seed=1)  # the same guides, by distance in space
    assert np.any(flat.guide_ids != db.guide_ids)  # across her head, some neighbours differ
    given = bind_roots(guides, dense.roots[:300], mesh=head, frizz=0.0)
    np.testing.assert_allclose(build_points(given, guides), build_points_reference(given, guides), atol=1e-5)


def test_a_density_map_shares_the_roots_out_by_area_times_density(sintel):
    """Per face and per vertex: no root where the density is 0, and a face set at 4× the density
    of the rest receives 4× the roots per unit area (within sampling error)."""
    from hairtool.guides.scatter import default_region, face_areas, scatter_on_mesh

    guides, head = sintel
    region = default_region(head, guides)
    faces = np.flatnonzero(region)
    half = np.zeros(len(head.faces), bool)
    half[faces[: faces.size // 2]] = True
    density = np.where(half, 4.0, 1.0)
    density[faces[-20:]] = 0.0
    n = 40_000
    _, hit = scatter_on_mesh(head, n, seed=7, region=region, density=density)
    assert not np.isin(hit, faces[-20:]).any()
    area = face_areas(head) * region * (density > 0)
    want = 4.0 * area[half].sum() / (4.0 * area[half].sum() + area[~half].sum())
    got = np.isin(hit, np.flatnonzero(half)).mean()
    assert abs(got - want) < 4.0 * np.sqrt(want * (1 - want) / n)  # four standard errors
    per_vertex = np.zeros(len(head.vertices))
    per_vertex[np.unique(head.faces[faces[:50]])] = 1.0  # only triangles with a dense corner
    _, hit = scatter_on_mesh(head, 2_000, seed=7, region=region, density=per_vertex)
    assert np.all(per_vertex[head.faces[hit]].max(axis=1) > 0)


def test_hair_bound_to_guides_of_its_own_comes_back_and_follows_them(sintel):
    """Render hair read beside its guides (not strands of it): bound exactly, it builds back bit
    for bit, and a moved guide moves only the strands that weight it."""
    guides, head = sintel
    hair = bind_scalp(guides, head, 2000, seed=3, frizz=0.05).build(guides)
    b = bind_to_guides(hair, guides, k=3)
    assert b.build(guides).points.tobytes() == hair.points.tobytes()
    moved = guides.points.copy()
    on = guides.topology.strand_index == 17
    moved[on] += (0.5 * guides.topology.vertex_param[on, None]).astype(np.float32)  # its tip swung
    after = b.build(guides.with_points(moved)).points
    changed = np.unique(hair.topology.strand_index[np.any(after != hair.points, axis=1)])
    weighting = np.flatnonzero(np.any((b.guide_ids == 17) & (b.weights > 0), axis=1))
    assert weighting.size > 5
    np.testing.assert_array_equal(changed, weighting)
    with pytest.raises(ParameterError, match="guides_per_child"):
        bind_to_guides(hair, guides, k=229)
