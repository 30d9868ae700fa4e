"""The three GL ways of drawing strands: thin LINE_STRIP, instanced quads, geometry-shader quads
(pinned with ``strand_raster = "gl"``: on llvmpipe the renderer would rasterize on the CPU)."""

from __future__ import annotations

import numpy as np
import pytest

from app.render.camera import Camera
from app.render.offscreen import read_rgba
from app.render.shaders import stage_sources
from app.render.strands import THIN_MAX_WIDTH
from hairtool import samples
from hairtool.errors import ParameterError
from hairtool.groom import Groom

SIZE = (160, 160)
BG = (0.0, 0.0, 0.0, 1.0)


def _draw(renderer, gl_ctx, groom, camera, *, width, method, ghost=None):
    renderer.strand_raster = "gl"
    renderer.set_groom(groom)
    renderer.background = BG
    renderer.line_width = width
    renderer.fast_lines = method == "thin"
    renderer.wide_lines = "geometry" if method == "geometry" else "quads"
    renderer.set_ghost_points(ghost, (0.2, 0.9, 0.4, 0.5))
    assert renderer.line_method() == method
    return read_rgba(gl_ctx, renderer, camera, SIZE)


def test_line_method_follows_width_and_fast_lines(renderer):
    renderer.strand_raster = "gl"
    renderer.line_width = THIN_MAX_WIDTH
    assert renderer.line_method() == "thin"
    renderer.line_width = 2.0
    assert renderer.line_method() == "geometry"
    renderer.fast_lines = True
    assert renderer.line_method() == "thin"
    renderer.fast_lines = False
    renderer.wide_lines = "quads"
    assert renderer.line_method() == "quads"
    renderer.wide_lines = "splines"
    with pytest.raises(ParameterError, match="wide_lines"):
        renderer.line_method()
    # The fast programs have no geometry stage.
    assert set(stage_sources("strands_thin")) == {"vertex_shader", "fragment_shader"}
    assert set(stage_sources("strands_quads")) == {"vertex_shader", "fragment_shader"}


@pytest.mark.parametrize("width", [2.0, 3.0, 8.0])
@pytest.mark.parametrize(
    "make",
    [
        lambda: samples.portrait(strands=30, vertices=12, seed=1),
        lambda: samples.scalp(strands=120, vertices=10, seed=2),
        lambda: samples.scalp(strands=450, vertices=11, seed=3),  # two texture rows
    ],
    ids=["portrait", "scalp", "scalp-rows"],
)
def test_instanced_quads_draw_what_the_geometry_shader_draws(renderer, gl_ctx, make, width):
    g = make()
    cam = Camera.for_groom(g, aspect=1.0)
    quads = _draw(renderer, gl_ctx, g, cam, width=width, method="quads")
    geometry = _draw(renderer, gl_ctx, g, cam, width=width, method="geometry")
    diff = np.abs(quads.astype(int) - geometry.astype(int)).max(axis=2)
    assert (diff > 8).mean() < 0.002, f"{(diff > 8).mean():.2%} of the pixels differ"
    assert (quads[..., :3].sum(axis=2) > 0).mean() > 0.02  # hair was drawn


def test_quads_clip_segments_behind_the_eye_like_the_geometry_shader(renderer, gl_ctx):
    # A strand from in front of the camera to behind it, and one wholly behind it.
    cam = Camera(distance=2.0)
    cam.set_scene((-1, -1, -1), (1, 1, 1))
    g = Groom.from_strands([[[0.2, 0.0, 0.0], [0.2, 0.0, 6.0]], [[-0.3, 0.1, 5.0], [0.3, 0.1, 7.0]]])
    quads = _draw(renderer, gl_ctx, g, cam, width=4.0, method="quads")
    geometry = _draw(renderer, gl_ctx, g, cam, width=4.0, method="geometry")
    diff = np.abs(quads.astype(int) - geometry.astype(int)).max(axis=2)
    assert (diff > 8).mean() < 0.002
    assert quads[..., :3].max() > 0


@pytest.mark.parametrize("method", ["thin", "quads", "geometry"])
def test_no_line_joins_one_strand_to_the_next(renderer, gl_ctx, method):
    # Strand 0 ends at the top right, strand 1 starts at the bottom left: nothing in between.
    g = Groom.from_strands([[[-0.8, 0.8, 0.0], [0.8, 0.8, 0.0]], [[-0.8, -0.8, 0.0], [0.8, -0.8, 0.0]]])
    cam = Camera(ortho=True, ortho_height=2.5)
    cam.set_scene((-1, -1, 0), (1, 1, 0))
    img = _draw(renderer, gl_ctx, g, cam, width=1.0 if method == "thin" else 4.0, method=method)
    lit = img[..., :3].max(axis=2) > 20
    rows = np.flatnonzero(lit.any(axis=1))
    assert len(rows) > 0
    centre = lit[SIZE[1] // 2 - 20 : SIZE[1] // 2 + 20]
    assert not centre.any(), "a segment joins the tip of strand 0 to the root of strand 1"


def test_thin_lines_are_one_pixel_and_coloured_root_to_tip(renderer, gl_ctx):
    g = Groom.from_strands([[[-1.0, -0.0125, 0.0], [1.0, -0.0125, 0.0]]])
    cam = Camera(ortho=True, ortho_height=4.0)
    cam.set_scene((-1, -1, 0), (1, 1, 0))
    renderer.set_ramp("grey")
    for width in (0.5, 1.0, THIN_MAX_WIDTH, 6.0):  # fast lines ignore the width
        img = _draw(renderer, gl_ctx, g, cam, width=width, method="thin")
        column = img[:, SIZE[0] // 2, :3].max(axis=1).astype(np.float64)
        assert column.sum() / column.max() == pytest.approx(1.0, abs=0.3)
        assert column[80] == column.max()
    renderer.set_ramp("root-tip")
    img = _draw(renderer, gl_ctx, g, cam, width=1.0, method="thin")
    left, right = img[80, 45, :3].astype(int), img[80, 115, :3].astype(int)
    assert np.abs(left - right).sum() > 60  # the ramp runs along the strand


@pytest.mark.parametrize("method", ["thin", "quads", "geometry"])
def test_ghost_is_drawn_by_every_method(renderer, gl_ctx, method):
    g = samples.comb(strands=6, vertices=8)
    cam = Camera.for_groom(g, aspect=1.0)
    width = 1.0 if method == "thin" else 3.0
    plain = _draw(renderer, gl_ctx, g, cam, width=width, method=method)
    moved = g.points + np.float32([0.05, 0.0, 0.0])
    ghosted = _draw(renderer, gl_ctx, g, cam, width=width, method=method, ghost=moved)
    changed = np.abs(ghosted.astype(int) - plain.astype(int)).max(axis=2) > 10
    assert changed.mean() > 0.002
    greenish = ghosted[changed][:, 1].astype(int) > ghosted[changed][:, 0].astype(int)
    assert greenish.mean() > 0.5


def test_segment_indices_match_the_loop_definition():
    from app.render.strand_gpu import line_indices, quad_indices, segment_indices_reference

    g = Groom.from_strands([np.zeros((n, 3)) for n in (2, 5, 3, 7)])
    np.testing.assert_array_equal(line_indices(g.topology), segment_indices_reference(g.topology, "lines"))
    np.testing.assert_array_equal(quad_indices(g.topology), segment_indices_reference(g.topology, "quads"))
    assert len(line_indices(g.topology)) == 2 * (g.vertex_count - g.strand_count)


def test_points_stay_current_in_every_form_while_the_method_changes(renderer, gl_ctx):
    # More vertices than one texture row (4096), and not a whole number of rows.
    g = samples.scalp(strands=450, vertices=11, seed=3)
    assert g.vertex_count > 4096 and g.vertex_count % 4096
    cam = Camera.for_groom(g, aspect=1.0)
    moved = g.points * np.float32(0.9)
    fresh = {}
    for method in ("thin", "quads", "geometry"):
        fresh[method] = _draw(renderer, gl_ctx, g.with_points(moved), cam, width=3.0, method=method)
    renderer.set_groom(g)
    renderer.line_width, renderer.fast_lines, renderer.wide_lines = 3.0, False, "quads"
    assert renderer.line_method() == "quads"
    read_rgba(gl_ctx, renderer, cam, SIZE)  # quads: the texture is the form in use
    renderer.update_points(moved)
    on_gpu = np.frombuffer(renderer.position_buffer.read(), dtype=np.float32).reshape(-1, 3)
    np.testing.assert_array_equal(on_gpu, moved)  # asked for, the vertex buffer is current too
    for method in ("geometry", "quads", "thin", "quads"):  # the stale form is refreshed first
        renderer.fast_lines = method == "thin"
        renderer.wide_lines = "geometry" if method == "geometry" else "quads"
        np.testing.assert_array_equal(read_rgba(gl_ctx, renderer, cam, SIZE), fresh[method])
    # Vertex colours reach the quads' colour texture too.
    red = np.tile(np.float32([1.0, 0.0, 0.0]), (g.vertex_count, 1))
    renderer.set_vertex_colors(red)
    img = read_rgba(gl_ctx, renderer, cam, SIZE)
    lit = img[..., :3].max(axis=2) > 40
    assert lit.mean() > 0.01 and np.all(img[lit][:, 1] < 40)
    # ... and the colour vertex buffer, uploaded only when a draw that reads it comes.
    green = np.tile(np.float32([0.0, 1.0, 0.0]), (g.vertex_count, 1))
    renderer.set_vertex_colors(green)
    for method in ("thin", "geometry"):
        renderer.fast_lines = method == "thin"
        renderer.wide_lines = "geometry"
        img = read_rgba(gl_ctx, renderer, cam, SIZE)
        lit = img[..., :3].max(axis=2) > 40
        assert lit.mean() > 0.01 and np.all(img[lit][:, 0] < 40), method
