"""The vertex nearest the mouse on screen (a press's): one parallel pass against the numpy twin
through Camera.project, front faces only (by root normal or by sight) or not, and nothing found
outside the brush."""

from __future__ import annotations

import numpy as np
import pytest

from app.render.camera import Camera
from app.render.screen_pick import nearest_in_sight, nearest_on_screen, nearest_on_screen_reference
from hairtool.frozen.brushes import facing_away, root_normals
from hairtool.frozen.brushes.sight import hidden_points
from hairtool.guides.planting import HeadSurface
from hairtool.io import read_groom
from hairtool.io.obj import read_mesh


@pytest.mark.parametrize("name", ["sintel_hair", "bear"])
def test_the_pick_is_the_numpy_twins_on_real_grooms(grooms_dir, name):
    g = read_groom(grooms_dir / f"{name}.tfx")
    lo, hi = g.bounds
    cam = Camera()
    cam.frame(lo.astype(np.float64), hi.astype(np.float64))
    size = (800.0, 600.0)
    rng = np.random.default_rng(1)
    strand = g.topology.strand_index
    picks = 0
    for k in range(12):
        cam.yaw, cam.pitch = rng.uniform(-3.0, 3.0), rng.uniform(-1.0, 1.0)
        cursor = tuple(rng.uniform([100.0, 100.0], [700.0, 500.0]))
        radius = float(rng.choice([3.0, 30.0, 400.0]))
        skip = facing_away(root_normals(g), cam.forward()) if k % 2 else None
        got = nearest_on_screen(g.points, cam.view_projection(*size), size, cursor, radius, strand, skip)
        want = nearest_on_screen_reference(cam, g.points, size, cursor, radius, strand, skip)
        if got != want:  # only where two vertices are as near to within rounding
            xy = cam.project(g.points[[got, want]], *size)
            d = ((xy - cursor) ** 2).sum(axis=1)
            assert got >= 0 and want >= 0 and abs(d[0] - d[1]) < 1e-9 * max(d[1], 1.0)
        picks += got >= 0
        if skip is not None and got >= 0:
            assert not skip[strand[got]]
    assert 3 <= picks < 12  # some presses find hair, the tiny brush off the groom does not


def test_nothing_within_the_brush_is_minus_one_and_ties_go_to_the_lower_index():
    cam = Camera()
    pts = np.array([[0.0, 0.0, 0.0], [0.0, 0.0, 0.0], [0.1, 0.0, 0.0]], np.float32)
    strand = np.array([0, 1, 1])
    size = (200.0, 200.0)
    vp = cam.view_projection(*size)
    centre = tuple(cam.project(pts[:1], *size)[0])
    assert nearest_on_screen(pts, vp, size, centre, 2.0, strand) == 0
    assert nearest_on_screen(pts, vp, size, centre, 2.0, strand, np.array([True, False])) == 1
    assert nearest_on_screen(pts, vp, size, (centre[0] + 90.0, centre[1]), 2.0, strand) == -1


def test_a_press_in_sight_never_starts_on_a_vertex_the_head_hides(grooms_dir):
    """Front faces only by sight (hairtool.frozen.brushes.sight): the press skips the strands
    whose nearest vertex lies behind the head, where the plain nearest would start there."""
    g = read_groom(grooms_dir / "sintel_hair.tfx")
    grid = HeadSurface(read_mesh(grooms_dir / "sintel_head.obj")).face_grid
    lo, hi = g.bounds
    cam = Camera()
    cam.frame(lo.astype(np.float64), hi.astype(np.float64))
    size, strand = (800.0, 600.0), g.topology.strand_index
    rng = np.random.default_rng(3)
    behind = 0
    for _ in range(16):
        cam.yaw, cam.pitch = rng.uniform(-3.0, 3.0), rng.uniform(-1.0, 1.0)
        view, vp = cam.forward(), cam.view_projection(*size)
        cursor = tuple(rng.uniform([250.0, 150.0], [550.0, 450.0]))
        hides = lambda p: bool(hidden_points(p[None], view, grid)[0])  # noqa: B023, E731
        got = nearest_in_sight(g.points, vp, size, cursor, 60.0, strand, hides)
        plain = nearest_on_screen(g.points, vp, size, cursor, 60.0, strand)
        assert got == -1 or not hides(g.points[got])
        if plain >= 0 and hides(g.points[plain]):
            behind += 1
            assert got != plain
    assert behind >= 1  # the plain pick does start behind the head
