"""The GL strand renderer, headless through EGL: pixels where strands, roots and tips project."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from app.render.camera import Camera
from app.render.offscreen import read_rgba, render_image
from app.render.ramps import RAMPS
from app.render.shaders import stage_sources
from app.render.strands import RESTART_INDEX, strip_indices, strip_indices_reference
from hairtool import samples
from hairtool.errors import GroomError, ParameterError
from hairtool.groom import Groom

SIZE = (160, 160)
BG = (0.0, 0.0, 0.0, 1.0)
ROOT = RAMPS["root-tip"][0] * 255
TIP = RAMPS["root-tip"][-1] * 255


def _distances(pixels: np.ndarray, rgb: np.ndarray) -> np.ndarray:
    return np.abs(pixels[:, :3].astype(np.float64) - rgb).max(axis=1)


def _closest_distance(pixels: np.ndarray, rgb: np.ndarray) -> float:
    return float(_distances(pixels, rgb).min())


def _count_like(pixels: np.ndarray, rgb: np.ndarray, tol: float = 40.0) -> int:
    return int((_distances(pixels, rgb) < tol).sum())


def test_strip_indices_match_the_loop_definition():
    g = Groom.from_strands([np.zeros((n, 3)) for n in (2, 5, 3, 7)])
    idx = strip_indices(g.topology)
    np.testing.assert_array_equal(idx, strip_indices_reference(g.topology))
    assert idx.dtype == np.uint32 and len(idx) == g.vertex_count + g.strand_count
    assert np.flatnonzero(idx == RESTART_INDEX).tolist() == [2, 8, 12, 20]


def test_shader_files_define_their_stages():
    strands = stage_sources("strands")
    assert set(strands) == {"vertex_shader", "geometry_shader", "fragment_shader"}
    assert strands["vertex_shader"].startswith("#version 330 core\n#define VERTEX_SHADER\n")
    assert set(stage_sources("mesh")) == {"vertex_shader", "fragment_shader"}
    with pytest.raises(ParameterError, match="shader"):
        stage_sources("no_such_program")


@pytest.mark.parametrize("make", [samples.comb, samples.portrait], ids=["comb", "portrait"])
def test_roots_have_the_root_colour_and_tips_the_tip_colour(make, pixel_window):
    g = make(strands=16, vertices=12)
    cam = Camera.for_groom(g, aspect=1.0)
    img = render_image(g, size=SIZE, camera=cam, line_width=3.0, background=BG)
    roots = cam.project(g.roots, *SIZE)
    tips = cam.project(g.tips, *SIZE)
    for s in range(g.strand_count):
        near_root = pixel_window(img, roots[s], 1)
        near_tip = pixel_window(img, tips[s], 1)
        assert _closest_distance(near_root, ROOT) < 40, f"strand {s} root"
        assert _closest_distance(near_tip, TIP) < 40, f"strand {s} tip"
        # Other strands may cross a window, but root colour dominates at roots and tip colour at tips.
        assert _count_like(near_root, ROOT) > _count_like(near_root, TIP), f"strand {s} root"
        assert _count_like(near_tip, TIP) > _count_like(near_tip, ROOT), f"strand {s} tip"
    # Far from every strand the background stays.
    assert np.all(img[2, 2, :3] == 0) and np.all(img[..., 3] == 255)


def test_planar_grooms_get_an_orthographic_front_view():
    g = samples.portrait(strands=20, vertices=10)
    assert g.is_planar
    cam = Camera.for_groom(g, aspect=1.0)
    assert cam.ortho and cam.yaw == 0.0 and cam.pitch == 0.0
    # Orthographic: moving a point along z (toward the eye) does not move its pixel.
    p = g.points[:5].astype(np.float64)
    q = p + np.array([0.0, 0.0, 0.3])
    np.testing.assert_allclose(cam.project(p, *SIZE), cam.project(q, *SIZE), atol=1e-9)
    assert not Camera.for_groom(samples.scalp(strands=10, vertices=4)).ortho


def test_update_points_redraws_without_rebuilding(renderer, gl_ctx):
    g = samples.comb(strands=9, vertices=8)
    renderer.set_groom(g)
    cam = Camera.for_bounds(np.array([-0.2, -0.6, -0.2]), np.array([0.4, 0.1, 0.4]))
    before = read_rgba(gl_ctx, renderer, cam, SIZE)
    kept = (
        renderer.vao,
        renderer.index_buffer,
        renderer.param_buffer,
        renderer.color_buffer,
        renderer.position_buffer,
        renderer.program,
    )
    glid = renderer.index_buffer.glo
    moved = g.points + np.array([0.15, 0.0, 0.0], dtype=np.float32)
    renderer.update_points(moved)
    after = read_rgba(gl_ctx, renderer, cam, SIZE)
    assert (
        renderer.vao,
        renderer.index_buffer,
        renderer.param_buffer,
        renderer.color_buffer,
        renderer.position_buffer,
        renderer.program,
    ) == kept
    assert renderer.index_buffer.glo == glid
    assert np.abs(before.astype(int) - after.astype(int)).sum(axis=2).astype(bool).mean() > 0.01
    # Drawing the moved groom from scratch gives the same picture.
    renderer.set_groom(g.with_points(moved))
    np.testing.assert_array_equal(read_rgba(gl_ctx, renderer, cam, SIZE), after)
    with pytest.raises(GroomError):
        renderer.update_points(moved[:-1])
    with pytest.raises(GroomError):
        renderer.update_points(np.full_like(moved, np.nan))


def test_transparent_background_is_alpha_zero_where_no_hair():
    g = samples.comb(strands=4, vertices=6)
    cam = Camera.for_groom(g)
    img = render_image(g, size=SIZE, camera=cam, transparent=True, line_width=3.0)
    assert img[0, 0, 3] == 0 and img[-1, -1, 3] == 0
    mid = cam.project(g.points[2:3], *SIZE)[0]
    assert img[int(mid[1]), int(mid[0]), 3] == 255
    coverage = (img[..., 3] > 0).mean()
    assert 0.005 < coverage < 0.3


def test_vertex_colors_override_the_ramp(pixel_window):
    g = samples.comb(strands=4, vertices=6)
    cam = Camera.for_groom(g)
    red = np.tile(np.float32([1.0, 0.0, 0.0]), (g.vertex_count, 1))
    img = render_image(g, size=SIZE, camera=cam, colors=red, background=BG, line_width=3.0)
    mid = cam.project(g.points[[2, 8, 14, 20]], *SIZE)
    for xy in mid:
        assert _closest_distance(pixel_window(img, xy, 1), np.array([255.0, 0, 0])) < 10
    with pytest.raises(ParameterError, match="colors"):
        render_image(g, size=SIZE, colors=red[:-1])


def test_line_width_is_in_pixels():
    # 160 px show 4 units: the line at y = −1/80 runs through the middle of pixel row 80.
    g = Groom.from_strands([[[-1.0, -0.0125], [1.0, -0.0125]]])
    cam = Camera(ortho=True, ortho_height=4.0)
    cam.set_scene((-1, -1, 0), (1, 1, 0))
    for width in (1.0, 3.0, 8.0):
        img = render_image(g, size=SIZE, camera=cam, line_width=width, background=BG, ramp="grey")
        column = img[:, SIZE[0] // 2, :3].max(axis=1)
        covered = column.astype(np.float64).sum() / column.max()
        assert covered == pytest.approx(width, abs=0.3)
        assert column[80] == column.max()


def test_mesh_is_drawn_shaded_and_hides_hair_behind_it(renderer, gl_ctx):
    # A square facing the camera at z = 0 and a strand behind it at z = −1: only the mesh shows.
    mesh = SimpleNamespace(
        vertices=np.float32([[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]]),
        faces=np.int32([[0, 1, 2], [0, 2, 3]]),
        normals=None,
    )
    hidden = Groom.from_strands([[[-0.5, 0.0, -1.0], [0.5, 0.0, -1.0]]])
    renderer.set_groom(hidden)
    renderer.set_mesh(mesh)
    renderer.background = BG
    renderer.line_width = 5.0
    cam = Camera(distance=5.0)
    cam.set_scene((-1, -1, -1), (1, 1, 0))
    img = read_rgba(gl_ctx, renderer, cam, SIZE)
    centre = img[SIZE[1] // 2, SIZE[0] // 2, :3].astype(int)
    assert centre.sum() > 100  # lit mesh, not background
    row = img[SIZE[1] // 2 + 20, SIZE[0] // 2, :3].astype(int)
    np.testing.assert_allclose(centre, row, atol=3)  # no strand colour across the middle
    renderer.set_mesh(None)
    img = read_rgba(gl_ctx, renderer, cam, SIZE)
    assert img[SIZE[1] // 2 + 20, SIZE[0] // 2, :3].sum() == 0
    assert img[SIZE[1] // 2, SIZE[0] // 2, :3].sum() > 100  # the strand, now visible
    with pytest.raises(ParameterError, match="mesh"):
        renderer.set_mesh(object())


def test_overlay_circle_draws_a_ring_at_the_cursor(renderer, gl_ctx):
    renderer.background = BG
    cam = Camera()
    # A viewport of logical size 80×80 drawn into a 160×160 framebuffer (device pixel ratio 2).
    renderer.set_overlay_circle((40.0, 20.0), 10.0, (80, 80))
    img = read_rgba(gl_ctx, renderer, cam, SIZE)
    lit = img[..., :3].sum(axis=2) > 60
    ys, xs = np.nonzero(lit)
    r = np.hypot(xs + 0.5 - 80.0, ys + 0.5 - 40.0)
    assert len(r) > 50 and np.all(np.abs(r - 20.0) < 3.0)
    renderer.set_overlay_circle(None)
    assert read_rgba(gl_ctx, renderer, cam, SIZE)[..., :3].max() == 0


def test_ramp_switch_and_bad_ramp(renderer, gl_ctx, pixel_window):
    g = samples.comb(strands=1, vertices=4)
    renderer.set_groom(g)
    renderer.background = BG
    renderer.line_width = 4.0
    cam = Camera.for_groom(g)
    renderer.set_ramp("heat")
    img = read_rgba(gl_ctx, renderer, cam, SIZE)
    tip = cam.project(g.tips, *SIZE)[0]
    assert _closest_distance(pixel_window(img, tip, 1), RAMPS["heat"][-1] * 255) < 40
    with pytest.raises(ParameterError, match="ramp"):
        renderer.set_ramp("nope")


def test_render_image_rejects_bad_arguments():
    g = samples.comb(strands=2, vertices=3)
    with pytest.raises(ParameterError, match="size"):
        render_image(g, size=(0, 10))
    with pytest.raises(ParameterError, match="line_width"):
        render_image(g, size=(10, 10), line_width=float("nan"))
    with pytest.raises(ParameterError, match="background"):
        render_image(g, size=(10, 10), background=(2, 0, 0))


def test_repeated_offscreen_renders_leave_the_context_without_gl_errors(gl_ctx):
    g = samples.comb(strands=4, vertices=6)
    gl_ctx.error  # noqa: B018 -- reading it clears the flag
    for size in ((32, 32), (48, 40), (32, 32)):
        render_image(g, size=size)
    assert gl_ctx.error == "GL_NO_ERROR"
