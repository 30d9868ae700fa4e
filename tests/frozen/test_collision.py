"""Surface collision: with a head surface, brushed strands end with no vertex inside it (a plane
under a flat comb; a harsh fold whose walls a brush presses strands into; Sintel's head under
aggressive strokes of every moving brush), roots fixed and lengths kept; off per stroke, strands pass
through; the face grid finds the brute force's closest points bit for bit; logs record the
option and replay with --scalp to the same bytes."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from hairtool import io, samples
from hairtool.cli import main
from hairtool.frozen.brushes import BrushSample, falloff_lut, root_normals
from hairtool.frozen.pipeline import FrozenParams, FrozenPipeline
from hairtool.frozen.strokes import read_strokes, strokes_from_log, write_strokes
from hairtool.groom import Groom, vertex_ids_of
from hairtool.guides.surface import SERIAL_POINTS, MeshSurface, closest_points
from hairtool.io.obj import read_mesh

DATA = Path(__file__).resolve().parents[1] / "data" / "grooms"
PLAIN = FrozenParams(freeze=False, clump=False)
LUT = tuple(falloff_lut("smooth").tolist())


@pytest.fixture(scope="module")
def sintel():
    return io.read_groom(DATA / "sintel_hair.tfx"), MeshSurface(read_mesh(DATA / "sintel_head.obj"))


def lengths(g):
    d = np.linalg.norm(np.diff(g.points.astype(np.float64), axis=0), axis=1)
    inner = np.ones(len(d), bool)
    inner[g.offsets[1:-1] - 1] = False
    return d[inner]


def moved_vertices(before, after):
    moved = np.any(after.points != before.points, axis=1)
    strands = np.flatnonzero(np.logical_or.reduceat(moved, before.offsets[:-1]))
    v = vertex_ids_of(before.topology, strands)
    return v[before.topology.index_in_strand[v] > 0]


def test_the_face_grid_finds_the_brute_forces_closest_points(sintel):
    groom, surface = sintel
    rng = np.random.default_rng(1)
    lo, hi = surface.mesh.vertices.min(axis=0), surface.mesh.vertices.max(axis=0)
    pts = np.concatenate([groom.points[::7], rng.uniform(lo - 2, hi + 2, (400, 3))]).astype(np.float64)
    q, face = surface.nearest(pts)
    inside_box = face >= 0
    assert inside_box.sum() > 300 and (~inside_box).sum() > 0
    q2, face2 = closest_points(surface.mesh, pts[inside_box])
    np.testing.assert_array_equal(q[inside_box], q2)
    np.testing.assert_array_equal(face[inside_box], face2)
    sd, _, _ = surface.signed_distance(pts)
    assert np.all(np.isinf(sd[~inside_box]))
    few = SERIAL_POINTS - 1  # a small ask runs on the calling thread: the same bytes
    assert len(pts) > SERIAL_POINTS
    q3, face3 = surface.nearest(pts[-few:])
    np.testing.assert_array_equal(q3, q[-few:])
    np.testing.assert_array_equal(face3, face[-few:])


def test_a_comb_up_through_a_plane_stops_at_it(plane):
    comb = samples.comb(36, 12)
    surface = MeshSurface(plane)
    c = comb.points[comb.offsets[14] + 8].astype(np.float64)
    results = {}
    for collide in (True, False):
        pipe = FrozenPipeline(comb, PLAIN, surface)
        for _ in range(4):
            pipe.brush(BrushSample("comb", tuple(c), (0.0, 0.4, 0.1), 0.3, 1.0, LUT, collide=collide))
        results[collide] = pipe.result
    on, off = results[True], results[False]
    v = moved_vertices(comb, on)
    assert v.size > 50
    assert np.any(off.points[:, 1] > 1e-3)  # without collision tips pass through the plane
    assert np.all(on.points[v, 1] <= 0.0)  # with it no vertex is above (inside)
    np.testing.assert_array_equal(on.roots, comb.roots)
    np.testing.assert_allclose(lengths(on), lengths(comb), atol=1e-6)


@pytest.mark.parametrize("brush", ["comb", "pinch"])
def test_on_sintel_brushed_strands_stay_outside_the_head(sintel, brush):
    groom, surface = sintel
    n = root_normals(groom)
    k = 40
    c = groom.points[groom.offsets[k] + 16].astype(np.float64)
    out = {}
    for collide in (True, False):
        pipe = FrozenPipeline(groom, PLAIN, surface)
        for _ in range(4):  # pinch toward a point inside the head, comb into it
            cc = c - 3.0 * n[k] if brush == "pinch" else c
            strength = 1.0 if brush == "comb" else 0.5
            pipe.brush(BrushSample(brush, tuple(cc), tuple(-3.0 * n[k]), 6.0, strength, LUT, collide=collide))
        out[collide] = pipe.result
    v = moved_vertices(groom, out[True])
    assert v.size > 100
    inside_off = surface.signed_distance(out[False].points[v].astype(np.float64))[0] < 0
    sd, _, _ = surface.signed_distance(out[True].points[v].astype(np.float64))
    assert inside_off.sum() >= 3 and np.all(sd >= 0)
    np.testing.assert_array_equal(out[True].roots, groom.roots)
    np.testing.assert_allclose(lengths(out[True]), lengths(groom), atol=5e-5)


def test_logs_record_collision_and_replay_with_scalp(sintel, tmp_path):
    groom, surface = sintel
    io.write(tmp_path / "g.npz", groom)
    n = root_normals(groom)
    c = groom.points[groom.offsets[40] + 16].astype(np.float64)
    pipe = FrozenPipeline(groom, FrozenParams(seed=3, clump_iterations=1), surface)
    pipe.brush(BrushSample("comb", tuple(c), tuple(-2.0 * n[40]), 6.0, 1.0, LUT))
    pipe.brush(BrushSample("comb", tuple(c), tuple(-2.0 * n[40]), 6.0, 1.0, LUT, collide=False))
    pipe.align(c - 3 * n[40], 4.0, 0.5)
    strokes = strokes_from_log(pipe.strokes)
    assert [s.collision for s in strokes] == [True, False, True]
    write_strokes(tmp_path / "s.json", strokes)
    raw = json.loads((tmp_path / "s.json").read_text())
    assert "collision" not in raw[0] and raw[1]["collision"] is False
    assert read_strokes(tmp_path / "s.json") == strokes
    args = ["freeze", str(tmp_path / "g.npz"), str(tmp_path / "o.npz"), "--seed", "3"]
    args += ["--clump-iterations", "1"]
    args += ["--strokes", str(tmp_path / "s.json")]
    assert main([*args, "--scalp", str(DATA / "sintel_head.obj")]) == 0
    # (the stroke released: a brush-local move's clumping settles into the full run's)
    np.testing.assert_array_equal(io.read(tmp_path / "o.npz").points, pipe.settle().points)


FOLD_SLOPE = 4.0  # as tests/frozen/conftest.py's fold


def in_the_crease(strands=24, n=12, length=0.6) -> Groom:
    """Straight strands hanging down the fold's wedge from roots just outside its crease."""
    rng = np.random.default_rng(5)
    x = rng.uniform(-0.04, 0.04, strands)
    roots = np.column_stack([x, -FOLD_SLOPE * np.abs(x) - 1e-3, np.linspace(-0.5, 0.5, strands)])
    t = np.linspace(0.0, length, n)
    pts = roots[:, None, :] - t[None, :, None] * np.array([0.0, 1.0, 0.0])
    return Groom(pts.reshape(-1, 3).astype(np.float32), np.full(strands, n))


FOLD_STROKES = {  # (brush, cursor, direction, strength): each pushes the strands into a wall
    "comb": ((0.0, -0.3, 0.0), (1.0, 1.0, 0.0), 1.0),
    "pinch": ((0.6, 0.2, 0.0), (0.0, 0.0, 0.0), 1.0),
    "snake_hook": ((0.0, -0.6, 0.0), (0.1, 0.25, 0.0), 1.0),
}


@pytest.mark.parametrize("brush", ["comb", "pinch", "snake_hook"])
def test_in_a_harsh_fold_no_vertex_ends_inside(fold, brush):
    hair = in_the_crease()
    surface = MeshSurface(fold)
    cursor, direction, strength = FOLD_STROKES[brush]
    const = tuple(falloff_lut("constant").tolist())
    out = {}
    for collide in (True, False):
        pipe = FrozenPipeline(hair, PLAIN, surface)
        c = np.array(cursor)
        for i in range(6):
            if brush == "snake_hook":
                c = c + np.array(direction)
            s = BrushSample(brush, tuple(c), direction, 2.0, strength, const, start=i == 0, collide=collide)
            pipe.brush(s)
        out[collide] = pipe.result
    p = out[True].points.astype(np.float64)
    inner = hair.topology.index_in_strand > 0
    depth = p[:, 1] + FOLD_SLOPE * np.abs(p[:, 0])  # > 0: inside the head (exactly, from the fold's shape)
    q = out[False].points.astype(np.float64)
    assert np.sum((q[:, 1] + FOLD_SLOPE * np.abs(q[:, 0]))[inner] > 1e-3) > 20  # the stroke goes in
    assert depth[inner].max() <= 1e-6
    assert np.all(surface.signed_distance(p[inner])[0] >= 0)
    np.testing.assert_array_equal(out[True].roots, hair.roots)
    np.testing.assert_allclose(lengths(out[True]), lengths(hair), atol=1e-5)


def test_on_sintel_aggressive_strokes_of_every_moving_brush_leave_no_vertex_inside(sintel):
    groom, surface = sintel
    n = root_normals(groom)
    const = tuple(falloff_lut("constant").tolist())
    rng = np.random.default_rng(0)
    inside_off = 0
    for trial in range(10):
        k = int(rng.integers(groom.strand_count))
        brush = ["comb", "pinch", "snake_hook", "comb", "smooth"][trial % 5]
        c = groom.points[groom.offsets[k] + 16].astype(np.float64)
        moves = [(-4.0 * n[k] + rng.normal(0, 2, 3)) for _ in range(6)]
        out = {}
        for collide in (True, False):
            pipe = FrozenPipeline(groom, PLAIN, surface)
            for i, d in enumerate(moves):  # into the head, 8 units wide, full strength
                cc = c - 3.0 * n[k] if brush == "pinch" else c + i * d * (brush == "snake_hook")
                s = BrushSample(brush, tuple(cc), tuple(d), 8.0, 1.0, const, start=i == 0, collide=collide)
                pipe.brush(s)
            out[collide] = pipe.result
        v = moved_vertices(groom, out[True])
        inside_off += int(np.sum(surface.signed_distance(out[False].points[v].astype(np.float64))[0] < 0))
        sd, _, _ = surface.signed_distance(out[True].points[v].astype(np.float64))
        assert np.all(sd >= 0), (trial, brush, np.sort(sd)[:3])
        np.testing.assert_array_equal(out[True].roots, groom.roots)
        np.testing.assert_allclose(lengths(out[True]), lengths(groom), atol=5e-5)
    assert inside_off > 100


def test_the_inside_test_reads_a_fold_by_its_edge_normal(fold):
    """The fold's hard crease, its vertex normals one wall's: a point inside the head beside
    the crease, whose closest point is the crease, reads as outside by the vertex normals
    blended there; the edge's pseudo-normal reads it right."""
    hard = MeshSurface(fold)
    inside = np.array([[-0.01, 0.02, 0.1]])  # y > −4·|x|: in the head, the crease the closest
    q, smooth = hard.project(inside)
    np.testing.assert_allclose(q, [[0.0, 0.0, 0.1]], atol=1e-7)
    assert float((inside - q)[0] @ smooth[0]) > 0  # the blended normals: outside
    assert hard.signed_distance(inside)[0][0] < 0
    for outside in ([0.01, -0.06, 0.1], [-0.01, -0.06, 0.1], [0.0, -0.5, 0.0]):
        assert hard.signed_distance(np.array([outside]))[0][0] > 0


def test_clumping_after_collision_pulls_no_strand_back_inside_the_head(sintel):
    """ClumpWithGaps pulls strands toward their clumps: on a curved head the pull can cut
    through it, so a strand the collision left outside ended inside once clumped (138 vertices
    here before clumping respected the head); now it clumps only as far as it stays out."""
    from hairtool.frozen.collide import KeepOut, keep_out

    groom, surface = sintel
    pipe = FrozenPipeline(groom, FrozenParams(freeze=False, keep_lengths=True), surface)
    constant = tuple(falloff_lut("constant").tolist())
    centre = groom.roots.mean(axis=0).astype(np.float64)
    for _ in range(5):  # everything combed toward the head's centre: collision keeps it out
        tips = pipe.aligned.tips.astype(np.float64).mean(axis=0)
        d = centre - tips
        pipe.brush(BrushSample("comb", tuple(tips), tuple(0.3 * d / np.linalg.norm(d)), 40.0, 1.0, constant))
    top = groom.topology
    deep = top.index_in_strand > 0
    was_in = np.logical_or.reduceat(
        (surface.signed_distance(pipe.aligned.points.astype(np.float64))[0] < 0) & deep, top.offsets[:-1]
    )
    now = (surface.signed_distance(pipe.result.points.astype(np.float64))[0] < 0) & deep
    assert not now[~np.repeat(was_in, top.counts)].any()  # no strand outside before clumping is inside
    assert was_in.sum() <= 3  # (the few the collision could not free stay as they were)
    np.testing.assert_array_equal(pipe.result.roots, groom.roots)
    np.testing.assert_allclose(lengths(pipe.result), lengths(groom), rtol=2e-4)  # lengths kept
    unclumped = FrozenPipeline(groom, FrozenParams(freeze=False, clump=False), surface)
    unclumped.apply_samples(pipe.strokes)
    assert np.abs(pipe.result.points - unclumped.result.points).max() > 0.1  # it still clumps
    raw = FrozenPipeline(groom, pipe.params, surface)  # clumping as it was: blind to the head
    raw._kept_out = lambda clumped: clumped
    raw.apply_samples(pipe.strokes)
    np.testing.assert_array_equal(raw.aligned.points, pipe.aligned.points)
    pulled = (surface.signed_distance(raw.result.points.astype(np.float64))[0] < 0) & deep
    assert pulled[~np.repeat(was_in, top.counts)].sum() > 20
    plain = keep_out(raw.aligned, raw.result, surface, 0.0)
    np.testing.assert_array_equal(plain.points, pipe.result.points)
    memo = KeepOut()  # the memory of the head's distances changes no byte
    for _ in range(2):
        np.testing.assert_array_equal(memo(raw.aligned, raw.result, surface, 0.0).points, plain.points)


def test_the_face_grids_empty_shells_are_their_numpy_twins(sintel):
    """The shells the closest-point search skips: each cell's distance in cells to one holding a
    face, the kernel's sweeps equal to the twin's dilations (Sintel's head and a lone triangle,
    whose far cells are many shells away)."""
    from hairtool.guides.surface import empty_rings_numpy
    from hairtool.io.obj import Mesh

    _, surface = sintel
    lone = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [20, 30, 5]], np.float32)
    normals = np.tile(np.array([0, 0, 1], np.float32), (4, 1))
    tiny = MeshSurface(Mesh(lone, np.array([[0, 1, 2]], np.int32), normals))
    for s in (surface, tiny):
        np.testing.assert_array_equal(s._rings, empty_rings_numpy(s._start, s.dims))
    assert tiny._rings.max() > 20
    far = np.array([[19.0, 29.0, 4.0], [10.0, 15.0, 2.5], [0.2, 0.2, 0.0]])
    q, face = tiny.nearest(far)
    np.testing.assert_array_equal(q, closest_points(tiny.mesh, far)[0])
    assert np.all(face == 0)


def test_head_distances_asked_ahead_give_the_same_bytes_and_spare_the_first_stroke(sintel, monkeypatch):
    """prepare_strokes (the studio's idle step after an open) asks the head about every point
    once, so the first comb move that collides asks about the strands it changed, not about the
    whole groom twice (70 ms of Sintel's first move on the 2-core VM)."""
    groom, surface = sintel
    params = FrozenParams(freeze=False, keep_lengths=True)
    plain, prepared = (FrozenPipeline(groom, params, surface) for _ in range(2))
    prepared.prepare_strokes()
    asked = []
    real = type(surface).signed_distance
    monkeypatch.setattr(
        type(surface), "signed_distance", lambda self, p: asked.append(len(p)) or real(self, p)
    )
    n = root_normals(groom)
    c = groom.points[groom.offsets[40] + 20].astype(np.float64)
    sample = BrushSample("comb", tuple(c), tuple(-2.0 * n[40]), 6.0, 1.0, LUT)
    prepared.brush(sample)
    assert asked and max(asked) < groom.vertex_count  # the changed points only
    asked.clear()
    plain.brush(sample)
    assert max(asked) == 2 * groom.vertex_count  # unprepared: every point, before and after
    np.testing.assert_array_equal(prepared.result.points, plain.result.points)
