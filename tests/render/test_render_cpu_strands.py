"""Strands rasterized on the CPU in the GL frame: the GL methods' pixels and colours, the mesh
in front, exports, the automatic choice on llvmpipe."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from app.render.camera import Camera
from app.render.offscreen import read_rgba, render_image
from app.render.ramps import RAMPS
from app.render.strands import RASTER_ENV, StrandRenderer, is_software_gl
from hairtool import samples
from hairtool.errors import ParameterError
from hairtool.groom import Groom

SIZE = (160, 120)
BG = (0.0, 0.0, 0.0, 1.0)


def _plain_fbo(ctx, size=SIZE):
    """A single-sampled framebuffer, like the viewport's (the CPU path blits into it)."""
    return ctx.framebuffer([ctx.renderbuffer(size, 4)], ctx.depth_renderbuffer(size))


def _draw(renderer, ctx, camera, *, raster, samples=0, size=SIZE):
    """``(H, W, 4)`` uint8, top row first, drawn with ``strand_raster = raster``."""
    renderer.strand_raster = raster
    if samples:
        return read_rgba(ctx, renderer, camera, size)
    fbo = _plain_fbo(ctx, size)
    try:
        renderer.render(fbo, camera, size)
        data = fbo.read(components=4)
    finally:
        fbo.release()
    return np.frombuffer(data, np.uint8).reshape(size[1], size[0], 4)[::-1]


def _lit(img):
    return img[..., :3].astype(int).max(axis=2) > 30


def _near(mask):
    """The pixels within one pixel (8-neighbourhood) of ``mask``."""
    grown = mask.copy()
    for dy in (-1, 0, 1):
        for dx in (-1, 0, 1):
            grown |= np.roll(np.roll(mask, dy, axis=0), dx, axis=1)
    return grown


def _groom_and_camera():
    g = samples.scalp(strands=150, vertices=10, seed=5)
    return g, Camera.for_groom(g, aspect=SIZE[0] / SIZE[1])


def test_auto_rasterizes_on_the_cpu_on_llvmpipe_and_can_be_overridden(renderer, gl_ctx, monkeypatch):
    assert "llvmpipe" in gl_ctx.info["GL_RENDERER"] and is_software_gl(gl_ctx)
    assert renderer.strand_raster == "auto" and renderer.line_method() == "cpu"
    renderer.line_width = 1.0
    assert renderer.line_method() == "cpu" and renderer.gl_line_method() == "thin"
    renderer.strand_raster = "gl"
    assert renderer.line_method() == "thin"
    renderer.line_width = 2.0
    assert renderer.line_method() == "geometry"
    renderer.strand_raster, renderer.software_gl = "auto", False  # a hardware driver
    assert renderer.line_method() == "geometry"
    renderer.strand_raster = "cpu"
    assert renderer.line_method() == "cpu"
    renderer.strand_raster = "gpu"
    with pytest.raises(ParameterError, match="strand_raster"):
        renderer.line_method()
    for value, method in (("gl", "geometry"), ("CPU", "cpu"), ("auto", "cpu"), ("", "cpu")):
        monkeypatch.setenv(RASTER_ENV, value)
        other = StrandRenderer(gl_ctx)
        try:
            assert other.line_method() == method, value
        finally:
            other.release()
    monkeypatch.setenv(RASTER_ENV, "fast")
    with pytest.raises(ParameterError, match=RASTER_ENV):
        StrandRenderer(gl_ctx)


@pytest.mark.parametrize("width", [1.0, 2.0, 3.0])
@pytest.mark.parametrize("samples", [0, 4], ids=["blit", "multisampled"])
def test_cpu_strands_cover_the_pixels_gl_draws(renderer, gl_ctx, width, samples):
    g, cam = _groom_and_camera()
    renderer.set_groom(g)
    renderer.background = BG
    renderer.line_width = width
    gl = _draw(renderer, gl_ctx, cam, raster="gl", samples=samples)
    cpu = _draw(renderer, gl_ctx, cam, raster="cpu", samples=samples)
    gl_lit, cpu_lit = _lit(gl), _lit(cpu)
    assert 0.02 < cpu_lit.mean() < 0.5
    assert (cpu_lit & _near(gl_lit)).sum() >= 0.9 * cpu_lit.sum()
    assert (gl_lit & _near(cpu_lit)).sum() >= 0.9 * gl_lit.sum()
    assert np.all(cpu[..., 3] == 255)
    if samples == 0:  # (multisampled, GL blends its thin lines' edges with the background)
        # Where both drew a strand the colours agree (the same ramp, sampled alike), but for
        # the odd pixel where another strand won.
        both = gl_lit & cpu_lit
        diff = np.abs(gl[both, :3].astype(int) - cpu[both, :3].astype(int)).max(axis=1)
        assert np.median(diff) <= 2 and (diff > 60).mean() < 0.01


@pytest.mark.parametrize("make", [samples.comb, samples.portrait], ids=["comb", "portrait"])
def test_cpu_roots_have_the_root_colour_and_tips_the_tip_colour(renderer, gl_ctx, make, pixel_window):
    g = make(strands=16, vertices=12)
    cam = Camera.for_groom(g, aspect=SIZE[0] / SIZE[1])
    renderer.set_groom(g)
    renderer.background = BG
    renderer.line_width = 3.0
    img = _draw(renderer, gl_ctx, cam, raster="cpu")
    root, tip = RAMPS["root-tip"][0] * 255, RAMPS["root-tip"][-1] * 255
    for s, (r, t) in enumerate(zip(cam.project(g.roots, *SIZE), cam.project(g.tips, *SIZE), strict=True)):
        near_root = pixel_window(img, r, 1)[:, :3].astype(float)
        near_tip = pixel_window(img, t, 1)[:, :3].astype(float)
        assert np.abs(near_root - root).max(axis=1).min() < 30, f"strand {s} root"
        assert np.abs(near_tip - tip).max(axis=1).min() < 30, f"strand {s} tip"


@pytest.mark.parametrize("samples", [0, 4], ids=["blit", "multisampled"])
def test_a_mesh_in_front_hides_cpu_strands(renderer, gl_ctx, samples):
    # A square facing the camera at z = 0, one strand behind it and one in front of it.
    mesh = SimpleNamespace(
        vertices=np.float32([[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]]),
        faces=np.int32([[0, 1, 2], [0, 2, 3]]),
        normals=None,
    )
    g = Groom.from_strands([[[-0.5, 0.3, -1.0], [0.5, 0.3, -1.0]], [[-0.5, -0.3, 0.5], [0.5, -0.3, 0.5]]])
    renderer.set_groom(g)
    renderer.set_vertex_colors(np.tile(np.float32([0.0, 1.0, 0.0]), (4, 1)))
    renderer.set_mesh(mesh)
    renderer.background = BG
    renderer.line_width = 5.0
    cam = Camera(distance=5.0)
    cam.set_scene((-1, -1, -1), (1, 1, 1))
    img = _draw(renderer, gl_ctx, cam, raster="cpu", samples=samples)
    (_, behind), (_, front) = cam.project([[0.0, 0.3, -1.0], [0.0, -0.3, 0.5]], *SIZE).astype(int)
    x = SIZE[0] // 2
    greenish = img[:, x, 1].astype(int) - img[:, x, 0].astype(int) > 100
    assert greenish[front - 1 : front + 2].any()  # the strand in front of the mesh
    assert not greenish[behind - 3 : behind + 4].any()  # the mesh hides the one behind it
    assert img[behind, x, :3].astype(int).sum() > 100  # lit mesh there
    renderer.set_mesh(None)
    img = _draw(renderer, gl_ctx, cam, raster="cpu", samples=samples)
    assert (img[behind - 3 : behind + 4, x, 1] > 200).any()  # without the mesh it shows


def test_cpu_exports_at_other_sizes_keep_a_transparent_background():
    g = samples.comb(strands=5, vertices=6)
    for size in ((37, 91), (200, 64)):
        cam = Camera.for_groom(g, aspect=size[0] / size[1])
        cpu = render_image(g, size=size, camera=cam, transparent=True, line_width=3.0, strand_raster="cpu")
        gl = render_image(g, size=size, camera=cam, transparent=True, line_width=3.0, strand_raster="gl")
        assert cpu.shape == (size[1], size[0], 4)
        drawn = cpu[..., 3] > 0
        assert 0.01 < drawn.mean() < 0.5 and np.all(cpu[drawn, 3] == 255)
        assert (drawn & _near(gl[..., 3] > 128)).sum() >= 0.9 * drawn.sum()
        assert cpu[0, 0, 3] == 0 and cpu[-1, -1, 3] == 0


def test_textures_and_images_are_kept_between_frames_and_points_stay_on_the_cpu(renderer, gl_ctx):
    g, cam = _groom_and_camera()
    renderer.set_groom(g)
    first = _draw(renderer, gl_ctx, cam, raster="cpu")
    layer = renderer.raster
    kept = (layer.color_texture.glo, layer.depth_texture.glo, layer.raster.rgba, layer.raster.depth)
    buffer_before = renderer.position_buffer.read()
    moved = g.points + np.float32([0.05, 0.0, 0.0])
    renderer.update_points(moved)
    assert renderer._main._stale["buffer"]  # a CPU draw last: nothing uploaded while dragging
    second = _draw(renderer, gl_ctx, cam, raster="cpu")
    assert renderer.raster is layer
    assert (layer.color_texture.glo, layer.depth_texture.glo, layer.raster.rgba, layer.raster.depth) == kept
    assert np.abs(first.astype(int) - second.astype(int)).max(axis=2).astype(bool).mean() > 0.01
    # Asked for, the vertex buffer is current; a GL draw afterwards sees the moved strands too.
    assert renderer.position_buffer.read() != buffer_before
    np.testing.assert_array_equal(
        np.frombuffer(renderer.position_buffer.read(), np.float32).reshape(-1, 3), moved
    )
    _draw(renderer, gl_ctx, cam, raster="cpu", size=(100, 90))
    assert layer.size == (100, 90) and layer.raster.rgba.shape == (90, 100, 4)


def test_frames_redrawn_in_part_are_the_frames_drawn_afresh(renderer, gl_ctx):
    # A brush-like edit: a few tips move each frame. The raster redraws the tiles they touch and
    # only those rows and columns go to the texture; the frame must be what a new renderer draws.
    g, cam = _groom_and_camera()
    size = (320, 240)
    cam = Camera.for_groom(g, aspect=size[0] / size[1])
    renderer.set_groom(g)
    renderer.background = BG
    renderer.line_width = 2.0
    _draw(renderer, gl_ctx, cam, raster="cpu", size=size)
    rng = np.random.default_rng(3)
    points = g.points.copy()
    partial = 0
    for _ in range(4):
        for s in rng.choice(g.strand_count, size=3, replace=False):
            points[g.offsets[s + 1] - 3 : g.offsets[s + 1]] += rng.normal(scale=0.03, size=(3, 3)).astype(
                np.float32
            )
        renderer.update_points(points)
        frame = _draw(renderer, gl_ctx, cam, raster="cpu", size=size)
        partial += renderer.raster.raster.tiles_redrawn > 0
        fresh = StrandRenderer(gl_ctx)
        try:
            fresh.set_groom(g.with_points(points))
            fresh.background, fresh.line_width = BG, 2.0
            np.testing.assert_array_equal(frame, _draw(fresh, gl_ctx, cam, raster="cpu", size=size))
        finally:
            fresh.release()
    assert partial == 4


def test_ghost_under_cpu_strands_is_drawn_by_gl(renderer, gl_ctx):
    g = samples.comb(strands=6, vertices=8)
    cam = Camera.for_groom(g, aspect=SIZE[0] / SIZE[1])
    renderer.set_groom(g)
    renderer.background = BG
    renderer.line_width = 3.0
    plain = _draw(renderer, gl_ctx, cam, raster="cpu")
    renderer.set_ghost_points(g.points + np.float32([0.05, 0.0, 0.0]), (0.2, 0.9, 0.4, 0.5))
    ghosted = _draw(renderer, gl_ctx, cam, raster="cpu")
    changed = np.abs(ghosted.astype(int) - plain.astype(int)).max(axis=2) > 10
    assert changed.mean() > 0.002
    assert (ghosted[changed][:, 1].astype(int) > ghosted[changed][:, 0].astype(int)).mean() > 0.5
    strands = _lit(plain)
    np.testing.assert_array_equal(ghosted[strands], plain[strands])  # strands drawn over the ghost


def _head(radius: float = 0.6):
    """A coarse sphere of ``radius`` at the origin, standing in for a head mesh."""
    u, v = np.meshgrid(np.linspace(0, np.pi, 7), np.linspace(0, 2 * np.pi, 9), indexing="ij")
    vertices = radius * np.stack([np.sin(u) * np.cos(v), np.cos(u), np.sin(u) * np.sin(v)], -1).reshape(-1, 3)
    i = np.arange(6)[:, None] * 9 + np.arange(8)
    faces = np.concatenate([np.stack([i, i + 9, i + 10], -1), np.stack([i, i + 10, i + 1], -1)])
    return SimpleNamespace(
        vertices=vertices.astype(np.float32), faces=faces.reshape(-1, 3).astype(np.int32), normals=None
    )


@settings(max_examples=6, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(
    steps=st.lists(
        st.tuples(st.sampled_from(["move", "orbit", "colour", "ghost", "mesh"]), st.integers(0, 2**16)),
        min_size=1,
        max_size=5,
    )
)
def test_frames_over_a_kept_head_are_the_frames_drawn_afresh(gl_ctx, steps):
    """Over a head mesh, a frame whose camera, size and mesh are the last frame's starts from the
    kept image of the head instead of drawing and reading it back (an animation scrubbed): every
    frame, byte for byte, what a renderer with no history draws; the head is drawn once per key."""
    g = samples.scalp(strands=60, vertices=8, seed=2)
    cam = Camera.for_groom(g, aspect=SIZE[0] / SIZE[1])
    head = _head()
    points, ghost = g.points, None
    kept = StrandRenderer(gl_ctx)
    heads = []
    kept.mesh.render = lambda mvp, view, draw=kept.mesh.render: (heads.append(1), draw(mvp, view))
    try:
        kept.set_mesh(head)
        kept.set_groom(g)
        kept.background, kept.line_width = BG, 3.0
        _draw(kept, gl_ctx, cam, raster="cpu")
        _draw(kept, gl_ctx, cam, raster="cpu")
        assert len(heads) == 1  # the same camera and head: drawn once
        for what, seed in [("move", 0), *steps]:
            rng = np.random.default_rng(seed)
            if what == "move":
                points = (points + rng.normal(0.0, 0.02, points.shape)).astype(np.float32)
                kept.update_points(points)
            elif what == "orbit":
                cam.orbit(float(rng.uniform(-20, 20)), float(rng.uniform(-10, 10)))
            elif what == "colour":
                kept.mesh.color = tuple(float(c) for c in rng.uniform(0.2, 1.0, 3))
            elif what == "ghost":
                ghost = None if ghost is not None else points + np.float32(0.03)
                kept.set_ghost_points(ghost)
            else:
                head = _head(float(rng.uniform(0.4, 0.7)))
                kept.set_mesh(head)
            image = _draw(kept, gl_ctx, cam, raster="cpu")
            fresh = StrandRenderer(gl_ctx)
            try:
                fresh.set_mesh(head)
                fresh.set_groom(Groom(points, g.topology))
                fresh.background, fresh.line_width, fresh.mesh.color = BG, 3.0, kept.mesh.color
                if ghost is not None:
                    fresh.set_ghost_points(ghost)
                np.testing.assert_array_equal(image, _draw(fresh, gl_ctx, cam, raster="cpu"), what)
            finally:
                fresh.release()
    finally:
        kept.release()
