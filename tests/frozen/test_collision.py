"""Surface collision: with a head surface, brushed strands end with no vertex inside it (a plane
under a flat comb; Sintel's head), roots fixed and lengths kept; off per stroke, strands pass
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
from hairtool.groom import vertex_ids_of
from hairtool.guides.surface import MeshSurface, closest_points
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
    np.testing.assert_array_equal(io.read(tmp_path / "o.npz").points, pipe.result.points)
