"""Hair shading (Kajiya-Kay from the strand tangent, the light tied to the camera): the kernel
against its numpy twin, the look it gives, and the GL and CPU pictures of shaded hair agreeing."""

from __future__ import annotations

import numpy as np
import pytest

from app.render.camera import Camera
from app.render.hair_shading import HairLook, light_and_eye, shade, shade_reference
from app.render.ramps import ramp_colors
from hairtool import samples
from hairtool.errors import ParameterError

SIZE = (200, 150)


def _near(mask):
    """The pixels within one pixel (8-neighbourhood) of ``mask``."""
    grown = mask.copy()
    for dy in (-1, 0, 1):
        for dx in (-1, 0, 1):
            grown |= np.roll(np.roll(mask, dy, axis=0), dx, axis=1)
    return grown


def _inputs(seed=3):
    g = samples.scalp(strands=80, vertices=12, seed=seed)
    base = ramp_colors(g.vertex_param)
    cam = Camera.for_groom(g, aspect=SIZE[0] / SIZE[1])
    light, eye = light_and_eye(*cam.basis())
    return g, base, cam, light, eye


def test_the_kernel_equals_its_numpy_twin():
    g, base, _cam, light, eye = _inputs()
    for look in (HairLook(), HairLook(0.1, 0.9, 0.8, 7.0)):
        got = shade(g.points, g.topology.offsets, base, light, eye, look)
        want = shade_reference(g.points, g.topology.offsets, base, light, eye, look)
        np.testing.assert_allclose(got, want, rtol=0, atol=1e-6)
        assert got.dtype == np.float32 and got.min() >= 0.0 and got.max() <= 1.0


@pytest.mark.parametrize("exponent", [48.0, 126.0, 128.0, 7.0])  # squarings, and pow() above or between
def test_short_and_empty_strands_shade_as_the_numpy_twin(exponent):
    rng = np.random.default_rng(2)
    offsets = np.array([0, 1, 1, 3, 6, 6, 10])  # one vertex, none, two, three, none, four
    pts = rng.normal(size=(10, 3)).astype(np.float32)
    pts[7] = pts[6]  # a zero-length segment: a one-sided tangent of zero
    base = rng.random((10, 3)).astype(np.float32)
    light, eye = light_and_eye(np.array([1.0, 0, 0]), np.array([0, 1.0, 0]), np.array([0, 0, -1.0]))
    look = HairLook(exponent=exponent)
    got = shade(pts, offsets, base, light, eye, look)
    np.testing.assert_allclose(got, shade_reference(pts, offsets, base, light, eye, look), rtol=0, atol=1e-6)


def test_diffuse_follows_the_angle_to_the_light_and_the_highlight_the_half_vector():
    # two one-segment strands: one across the light (lit fully), one along it (ambient only)
    light, eye = np.array([0.0, 0.0, 1.0]), np.array([0.0, 0.0, 1.0])
    pts = np.array([[0, 0, 0], [1, 0, 0], [0, 0, 0], [0, 0, 1]], np.float32)
    base = np.full((4, 3), 0.5, np.float32)
    look = HairLook(ambient=0.2, diffuse=0.6, specular=0.25, exponent=10.0)
    c = shade(pts, np.array([0, 2, 4]), base, light, eye, look)
    np.testing.assert_allclose(c[:2], 0.5 * 0.8 + 0.25, atol=1e-6)  # sin = 1 to L and to H
    np.testing.assert_allclose(c[2:], 0.5 * 0.2, atol=1e-6)  # along L: no diffuse, no highlight


def test_the_light_turns_with_the_camera():
    g, base, cam, light, eye = _inputs()
    before = shade(g.points, g.topology.offsets, base, light, eye)
    cam.orbit(200.0, 0.0)
    after = shade(g.points, g.topology.offsets, base, *light_and_eye(*cam.basis()))
    assert np.abs(after - before).max() > 0.1


@pytest.mark.parametrize(
    ("width", "taper", "wide"),
    [(1.0, 0.0, "geometry"), (2.0, 0.0, "geometry"), (3.0, 0.75, "geometry"), (3.0, 0.75, "quads")],
)
def test_shaded_gl_and_cpu_pictures_agree(renderer, gl_ctx, width, taper, wide):
    """Both draws interpolate the same per-vertex shade, so the pictures agree to within the
    rasterizers' own difference (stated: the pixels either draw lie within one pixel of the
    other's, and 98 % of those both draw are within 3 levels of 255 of each other)."""
    g, _base, cam, _l, _e = _inputs(seed=11)
    renderer.set_groom(g)
    renderer.background = (0.0, 0.0, 0.0, 1.0)
    renderer.line_width = width
    renderer.taper, renderer.wide_lines = taper, wide
    renderer.set_hair_shading(True)
    pictures = {}
    for raster in ("gl", "cpu"):
        renderer.strand_raster = raster
        fbo = gl_ctx.framebuffer([gl_ctx.renderbuffer(SIZE, 4)], gl_ctx.depth_renderbuffer(SIZE))
        try:
            renderer.render(fbo, cam, SIZE)
            pictures[raster] = np.frombuffer(fbo.read(components=4), np.uint8).reshape(SIZE[1], SIZE[0], 4)
        finally:
            fbo.release()
    gl, cpu = (pictures[k][..., :3].astype(int) for k in ("gl", "cpu"))
    diff = np.abs(gl - cpu).max(axis=2)
    lit_gl, lit_cpu = gl.max(axis=2) > 0, cpu.max(axis=2) > 0
    both = lit_gl & lit_cpu
    assert both.sum() > 500
    assert (lit_gl <= _near(lit_cpu)).all() and (lit_cpu <= _near(lit_gl)).all()
    assert (diff[both] <= 3).mean() > 0.98
    lit = lit_cpu
    # and it is shaded, not the flat ramp: the same strands unshaded differ
    renderer.set_hair_shading(False)
    renderer.strand_raster = "cpu"
    fbo = gl_ctx.framebuffer([gl_ctx.renderbuffer(SIZE, 4)], gl_ctx.depth_renderbuffer(SIZE))
    try:
        renderer.render(fbo, cam, SIZE)
        flat = np.frombuffer(fbo.read(components=4), np.uint8).reshape(SIZE[1], SIZE[0], 4)[..., :3]
    finally:
        fbo.release()
    assert np.abs(flat.astype(int) - cpu).max(axis=2)[lit].mean() > 10


def test_a_tapered_width_narrows_strands_to_the_tip_and_the_kernel_equals_its_reference(renderer, gl_ctx):
    from app.render.soft_raster import rasterize, rasterize_reference

    g, _base, cam, _l, _e = _inputs(seed=2)
    renderer.set_groom(g)
    renderer.taper = 0.75
    scale = renderer.segment_width_scale()
    starts = g.topology.segment_end - 1
    t = g.topology.vertex_param
    np.testing.assert_allclose(scale, 1.0 - 0.75 * 0.5 * (t[starts] + t[starts + 1]), atol=1e-6)
    mvp = (cam.view_matrix() @ cam.projection_matrix(SIZE[0] / SIZE[1])).astype(np.float32)
    colors = np.ones((g.vertex_count, 3), np.float32)
    got = rasterize(g.points, starts, colors, mvp, SIZE, 6.0, scale=scale)
    want = rasterize_reference(g.points, starts, colors, mvp, SIZE, 6.0, scale=scale)
    np.testing.assert_array_equal(got[0], want[0])
    np.testing.assert_array_equal(got[1], want[1])
    full = rasterize(g.points, starts, colors, mvp, SIZE, 6.0)[0][..., 0] > 0
    assert (got[0][..., 0] > 0).sum() < 0.8 * full.sum()  # narrower overall
    # the tip end of a strand covers fewer pixels than its root end
    root = rasterize(g.points, starts[::11], colors, mvp, SIZE, 6.0, scale=scale[::11])[0][..., 0] > 0
    tip = rasterize(g.points, starts[10::11], colors, mvp, SIZE, 6.0, scale=scale[10::11])[0][..., 0] > 0
    assert tip.sum() < root.sum()
    renderer.taper = 1.0
    with pytest.raises(ParameterError, match="taper"):
        renderer.segment_width_scale()


def test_the_shade_is_the_same_bytes_at_one_thread_and_at_all():
    import numba

    g, base, _cam, light, eye = _inputs()
    threads = numba.get_num_threads()
    every = shade(g.points, g.topology.offsets, base, light, eye)
    numba.set_num_threads(1)
    try:
        one = shade(g.points, g.topology.offsets, base, light, eye)
    finally:
        numba.set_num_threads(threads)
    np.testing.assert_array_equal(one, every)
