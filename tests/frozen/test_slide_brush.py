"""The slide brush: on a flat plane the strands under the brush translate along it by the drag's
in-plane part, shapes bit-for-bit the same offsets; on Sintel's head the slid roots lie on the
mesh and each strand keeps its shape in its root frame; the kernel equals its twin; without a
surface it is refused by name; the CLI replays slide strokes with --scalp to the same bytes."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from hairtool import io, samples
from hairtool.cli import main
from hairtool.errors import ParameterError
from hairtool.frozen.brushes import BrushSample, falloff_lut, root_normals
from hairtool.frozen.brushes.slide import _turn_reference, slide, slide_reference
from hairtool.frozen.pipeline import FrozenParams, FrozenPipeline
from hairtool.frozen.strokes import strokes_from_log, write_strokes
from hairtool.guides.surface import MeshSurface
from hairtool.io.obj import read_mesh

DATA = Path(__file__).resolve().parents[1] / "data" / "grooms"
PLAIN = FrozenParams(freeze=False, clump=False)


@pytest.fixture(scope="module")
def flat():
    return samples.comb(36, 12)


@pytest.fixture(scope="module")
def sintel():
    return io.read_groom(DATA / "sintel_hair.tfx"), MeshSurface(read_mesh(DATA / "sintel_head.obj"))


def sample(cursor, radius, strength, direction, falloff="smooth", view=None):
    lut = tuple(falloff_lut(falloff).tolist())
    v = None if view is None else tuple(map(float, view))
    c, d = tuple(map(float, cursor)), tuple(map(float, direction))
    return BrushSample("slide", c, d, radius, strength, lut, v)


def test_on_a_plane_strands_translate_along_it_by_the_weighted_drag(flat, plane):
    surface = MeshSurface(plane)
    c = flat.roots[14].astype(np.float64)
    s = sample(c, 0.08, 0.8, (0.1, 0.4, 0.0), falloff="linear")  # the y part leaves the plane
    out = slide(flat, s, np.zeros(flat.strand_count, bool), surface)
    w = 0.8 * np.maximum(0.0, 1.0 - np.linalg.norm(flat.roots - c, axis=1) / 0.08)
    moved = w > 0
    assert moved.sum() == 9
    shift = (out.roots - flat.roots).astype(np.float64)
    np.testing.assert_allclose(shift, w[:, None] * [0.1, 0.0, 0.0], atol=1e-6)
    p0, p1 = flat.points.reshape(36, 12, 3), out.points.reshape(36, 12, 3)
    np.testing.assert_allclose(p1 - p1[:, :1], p0 - p0[:, :1], atol=1e-6)  # shapes as they were
    np.testing.assert_array_equal(p1[~moved], p0[~moved])


def test_on_sintel_roots_land_on_the_head_and_shapes_keep_their_root_frames(sintel):
    groom, surface = sintel
    pipe = FrozenPipeline(groom, PLAIN, surface)
    normals = root_normals(groom)
    k = 40
    c = groom.roots[k].astype(np.float64)
    drag = np.cross(normals[k], [0.0, 1.0, 0.0])
    drag = 1.5 * drag / np.linalg.norm(drag)
    locked = pipe.locked
    pipe.brush(sample(c, 2.0, 1.0, drag, view=-normals[k]))
    out = pipe.result
    moved = np.flatnonzero(np.any(out.roots != groom.roots, axis=1))
    assert k in moved and 2 <= moved.size < 40
    on, n1 = surface.project(out.roots[moved].astype(np.float64))
    np.testing.assert_allclose(out.roots[moved], on, atol=1e-4)  # on the surface
    _, n0 = surface.project(groom.roots[moved].astype(np.float64))
    for j, s in enumerate(moved):
        before, after = groom.strand(s).astype(np.float64), out.strand(s).astype(np.float64)
        back = _turn_reference(after - after[0], n1[j], n0[j])  # into the old root frame
        np.testing.assert_allclose(back, before - before[0], atol=1e-4)
    assert np.linalg.norm(out.roots[k] - groom.roots[k]) > 0.5  # it slid
    away = normals @ -normals[k] > 0  # behind the head from that camera: untouched
    assert not np.isin(np.flatnonzero(away), moved).any()
    assert not locked.any()


@pytest.mark.parametrize("where", ["flat", "sintel"])
def test_the_slide_kernel_matches_its_twin(where, flat, sintel, plane):
    if where == "flat":
        g, surface = flat, MeshSurface(plane)
    else:
        g, surface = sintel
    locked = np.zeros(g.strand_count, bool)
    locked[::4] = True
    size = float(np.ptp(g.roots, axis=0).max())
    s = sample(g.roots[g.strand_count // 3], 0.3 * size, 0.9, (0.1 * size, 0.05 * size, -0.08 * size))
    ours, twin = slide(g, s, locked, surface), slide_reference(g, s, locked, surface)
    assert np.any(ours.points != g.points)
    np.testing.assert_array_equal(ours.points, twin.points)


def test_without_a_surface_slide_is_refused_by_name(flat, plane):
    pipe = FrozenPipeline(flat, PLAIN)
    with pytest.raises(ParameterError, match="scalp"):
        pipe.brush(sample(flat.roots[0], 0.1, 1.0, (0.1, 0, 0)))
    assert pipe.strokes == ()
    pipe.set_surface(MeshSurface(plane))
    assert np.any(pipe.brush(sample(flat.roots[0], 0.1, 1.0, (0.1, 0, 0))).roots != flat.roots)
    with pytest.raises(ParameterError, match="scalp"):
        pipe.set_surface(None)  # the slide stroke needs one
    assert pipe.surface is not None


def test_slide_strokes_replay_in_the_cli_with_scalp(sintel, tmp_path):
    groom, surface = sintel
    io.write(tmp_path / "groom.npz", groom)
    pipe = FrozenPipeline(groom, FrozenParams(seed=2, clump_iterations=1), surface)
    c = groom.roots[40].astype(np.float64)
    for k in range(3):
        pipe.brush(sample(c + np.array([0.3 * k, 0, 0]), 2.0, 0.7, (0.3, 0.1, 0.0)))
    write_strokes(tmp_path / "s.json", strokes_from_log(pipe.strokes))
    assert json.loads((tmp_path / "s.json").read_text())[0]["brush"] == "slide"
    args = ["freeze", str(tmp_path / "groom.npz"), str(tmp_path / "o.npz"), "--seed", "2",
            "--clump-iterations", "1", "--strokes", str(tmp_path / "s.json")]  # fmt: skip
    assert main(args) == 2 and not (tmp_path / "o.npz").exists()  # no --scalp: refused
    assert main([*args, "--scalp", str(DATA / "sintel_head.obj")]) == 0
    np.testing.assert_array_equal(io.read(tmp_path / "o.npz").points, pipe.result.points)
