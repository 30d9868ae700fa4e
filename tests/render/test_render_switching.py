"""Switching between two sets of strands (the studio's drag share and full render hair): what
is kept between them is reused, and every frame is the frame a new renderer draws."""

from __future__ import annotations

import numpy as np
import pytest

from app.render.camera import Camera
from app.render.hair_shading import HAIR_TAPER
from app.render.soft_raster import StrandRaster, rasterize
from app.render.strands import StrandRenderer
from hairtool import samples
from hairtool.errors import ParameterError

SIZE = (160, 120)


def _frame(renderer, ctx, camera):
    fbo = ctx.framebuffer([ctx.renderbuffer(SIZE, 4)], ctx.depth_renderbuffer(SIZE))
    try:
        renderer.render(fbo, camera, SIZE)
        return np.frombuffer(fbo.read(components=4), np.uint8).reshape(SIZE[1], SIZE[0], 4)
    finally:
        fbo.release()


def _look(renderer, raster):
    renderer.strand_raster = raster
    renderer.line_width = 2.0
    renderer.set_hair_shading(True)
    renderer.taper = HAIR_TAPER


@pytest.mark.parametrize("raster", ["cpu", "gl"])
def test_strands_drawn_again_reuse_their_buffers_and_draw_what_a_new_renderer_draws(renderer, gl_ctx, raster):
    full = samples.scalp(strands=120, vertices=10, seed=2)
    share = full.subset(np.arange(0, 120, 10))
    cam = Camera.for_groom(full, aspect=SIZE[0] / SIZE[1])
    _look(renderer, raster)
    colours = np.random.default_rng(1).uniform(0.0, 1.0, (full.vertex_count, 3)).astype(np.float32)
    renderer.set_strands(full.points, full.topology, colours)
    _frame(renderer, gl_ctx, cam)
    made = renderer._gpu
    moved = full.points + np.float32([0.03, 0.0, 0.01])
    for points, top, c in ((share.points, share.topology, None), (moved, full.topology, colours * 0.5)):
        renderer.set_strands(points, top, c)
        got = _frame(renderer, gl_ctx, cam)
        fresh = StrandRenderer(gl_ctx)
        try:
            _look(fresh, raster)
            fresh.set_strands(points, top, c)
            np.testing.assert_array_equal(got, _frame(fresh, gl_ctx, cam))
        finally:
            fresh.release()
    assert renderer._gpu is made  # the full set's buffers came back, not new ones
    np.testing.assert_array_equal(renderer._main.points, moved)


def test_bad_points_and_colours_are_refused_with_one_clear_error(renderer):
    g = samples.scalp(strands=5, vertices=4, seed=1)
    renderer.set_strands(g.points, g.topology)
    bad = g.points.copy()
    bad[7, 1] = np.inf
    with pytest.raises(Exception, match="non-finite"):
        renderer.update_points(bad)
    colours = np.full((g.vertex_count, 3), 0.5, np.float32)
    colours[3, 2] = np.nan
    with pytest.raises(ParameterError, match="colors"):
        renderer.set_vertex_colors(colours)


def test_a_raster_drawing_large_small_large_draws_the_bytes_of_fresh_ones():
    # The segment table and last-frame copies live in memory kept at the largest size.
    g = samples.scalp(strands=60, vertices=8, seed=3)
    cam = Camera.for_groom(g, aspect=SIZE[0] / SIZE[1])
    mvp = (cam.view_matrix() @ cam.projection_matrix(SIZE[0] / SIZE[1])).astype(np.float64)
    colours = np.random.default_rng(2).uniform(0.0, 1.0, (g.vertex_count, 3)).astype(np.float32)
    starts = np.ascontiguousarray(g.topology.segment_end - 1)
    starts.flags.writeable = False  # as the renderer hands them: fixed, kept without a copy
    scale = np.linspace(1.0, 0.25, starts.size)
    scale.flags.writeable = False
    small = slice(0, starts.size // 3)
    raster = StrandRaster()
    points = g.points.copy()
    for k, part in enumerate((slice(None), small, slice(None), slice(None))):
        points[::7] += np.float32(0.01 * k)
        s, sc = (starts, scale) if part == slice(None) else (starts[part].copy(), scale[part].copy())
        rgba, depth = raster.draw(points, s, colours, mvp, SIZE, 2.0, scale=sc)
        ref_rgba, ref_depth = rasterize(points, s, colours, mvp, SIZE, 2.0, scale=sc)
        np.testing.assert_array_equal(rgba, ref_rgba)
        np.testing.assert_array_equal(depth, ref_depth)
    # The last frame moved every seventh vertex: most segments changed, so the next frame is drawn
    # in full without looking; then one vertex moved is redrawn in part (the fixed starts and
    # widths allow it), and every frame is the fresh one.
    redrawn = []
    for _ in range(2):
        points[5] += np.float32(0.02)
        rgba, _ = raster.draw(points, starts, colours, mvp, SIZE, 2.0, scale=scale)
        redrawn.append(raster.tiles_redrawn)
        np.testing.assert_array_equal(
            rgba, rasterize(points, starts, colours, mvp, SIZE, 2.0, scale=scale)[0]
        )
    assert redrawn[0] == -1 and redrawn[1] > 0


def test_the_studio_warm_up_compiles_the_raster_kernels_its_draws_use():
    # The renderer hands read-only arrays (its points, fixed starts and widths); the warm-up
    # draws writable ones. The kernels see read-only views either way, so the first paint in
    # the studio compiles nothing the warm-up process did not.
    from app.render import soft_raster
    from app.ui.kernel_warmup import _raster_step

    # its redraws go through the tiles, plain and told what moved (or nothing warms those)
    assert all(n > 0 for n in _raster_step())
    kernels = (
        soft_raster._setup_kernel,
        soft_raster._changed_vertices,
        soft_raster._changed_ends,
        soft_raster._changed_in_runs,
        soft_raster._setup_listed,
        soft_raster._mark_tiles,
        soft_raster._bin_segments,
        soft_raster._draw_tiles,
    )
    before = [set(k.signatures) for k in kernels]
    g = samples.scalp(strands=30, vertices=6, seed=1)
    points = g.points.copy()
    view = points.view()
    view.flags.writeable = False
    starts = np.ascontiguousarray(g.topology.segment_end - 1)
    starts.flags.writeable = False
    scale = np.linspace(1.0, 0.5, starts.size)
    scale.flags.writeable = False
    colours = np.full((g.vertex_count, 3), 0.5, np.float32)
    cam = Camera.for_groom(g, aspect=64 / 48)
    on_screen = (cam.view_matrix() @ cam.projection_matrix(64 / 48)).astype(np.float64)
    for mvp in (on_screen, np.eye(4)):  # the scalp's strands lie off the image of an identity mvp
        raster = StrandRaster()
        for _ in range(3):
            rgba, _ = raster.draw(view, starts, colours, mvp, (64, 48), 2.0, scale=scale)
            np.testing.assert_array_equal(
                rgba, rasterize(view, starts, colours, mvp, (64, 48), 2.0, scale=scale)[0]
            )
            points[3] += np.float32(0.01)
        rgba, _ = raster.draw(view, starts, colours, mvp, (64, 48), 2.0, scale=scale, changed=[[3, 4]])
        np.testing.assert_array_equal(
            rgba, rasterize(view, starts, colours, mvp, (64, 48), 2.0, scale=scale)[0]
        )
    assert [set(k.signatures) for k in kernels] == before
