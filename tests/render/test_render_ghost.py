"""StrandRenderer.set_ghost_points: the groom's strands a second time, flat and translucent, under it."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from app.render.camera import Camera
from app.render.offscreen import read_rgba, unpremultiply
from hairtool.errors import GroomError, ParameterError
from hairtool.groom import Groom

SIZE = (160, 160)
BG = (0.0, 0.0, 0.0, 1.0)
GHOST = (1.0, 0.5, 0.0, 0.5)
SHIFT = np.float32([0.0, -1.0, 0.0])


def _setup(renderer, width: float = 5.0):
    # Two horizontal strands (4 vertices each) at y ≈ 0.5 and y ≈ −0.5; 40 px per unit.
    x = np.linspace(-1.0, 1.0, 4)
    strands = [np.column_stack([x, np.full(4, y), np.zeros(4)]) for y in (0.4875, -0.5125)]
    g = Groom.from_strands(strands)
    renderer.set_groom(g)
    renderer.set_ramp("grey")
    renderer.background = BG
    renderer.line_width = width
    cam = Camera(ortho=True, ortho_height=4.0)
    cam.set_scene((-1, -1, 0), (1, 1, 0))
    return g, cam


def _row(cam, y: float) -> int:
    return int(cam.project(np.array([[0.0, y, 0.0]]), *SIZE)[0, 1])


def test_ghost_is_a_flat_translucent_copy_drawn_under_the_strands(renderer, gl_ctx):
    g, cam = _setup(renderer)
    plain = read_rgba(gl_ctx, renderer, cam, SIZE)
    ghost = g.points + SHIFT  # strand 0 lands on strand 1, strand 1 below everything
    renderer.set_ghost_points(ghost, rgba=GHOST)
    img = read_rgba(gl_ctx, renderer, cam, SIZE)
    col = SIZE[0] // 2
    # Below every strand only the ghost: the flat colour blended over the background.
    alone = img[_row(cam, -1.5125), col, :3].astype(float)
    expected = np.array(GHOST[:3]) * GHOST[3] * 255 + np.array(BG[:3]) * (1 - GHOST[3]) * 255
    np.testing.assert_allclose(alone, expected, atol=3)
    # Where a strand lies on the ghost the strand is drawn over it, unchanged.
    r1 = _row(cam, -0.5125)
    np.testing.assert_array_equal(img[r1, col], plain[r1, col])
    assert plain[r1, col, :3].max() > 100
    # The ghost draws nothing else: rows away from it are as without it.
    r0 = _row(cam, 0.4875)
    np.testing.assert_array_equal(img[: r0 + 8], plain[: r0 + 8])
    # Moving the ghost rewrites the positions only; None removes it and gives the plain picture back.
    buffer = renderer.ghost_buffer
    renderer.set_ghost_points(ghost + 2 * SHIFT, rgba=GHOST)  # out of the view (y < −2)
    assert renderer.ghost_buffer is buffer
    np.testing.assert_array_equal(read_rgba(gl_ctx, renderer, cam, SIZE), plain)
    renderer.set_ghost_points(ghost, rgba=GHOST)
    np.testing.assert_array_equal(read_rgba(gl_ctx, renderer, cam, SIZE), img)
    renderer.set_ghost_points(None)
    np.testing.assert_array_equal(read_rgba(gl_ctx, renderer, cam, SIZE), plain)


def test_ghost_alpha_on_a_transparent_background(renderer, gl_ctx):
    g, cam = _setup(renderer)
    renderer.background = (0.0, 0.0, 0.0, 0.0)
    renderer.set_ghost_points(g.points + SHIFT, rgba=GHOST)
    img = unpremultiply(read_rgba(gl_ctx, renderer, cam, SIZE))
    pixel = img[_row(cam, -1.5125), SIZE[0] // 2].astype(float)
    np.testing.assert_allclose(pixel, [255, 127.5, 0, 127.5], atol=3)
    assert img[2, 2, 3] == 0


def test_ghost_follows_line_width_and_mesh_hides_it(renderer, gl_ctx):
    g, cam = _setup(renderer, width=8.0)
    renderer.set_ghost_points(g.points + SHIFT, rgba=(1.0, 1.0, 1.0, 1.0))
    img = read_rgba(gl_ctx, renderer, cam, SIZE)
    column = img[:, SIZE[0] // 2, 0].astype(float)
    band = column[_row(cam, -1.5125) - 10 : _row(cam, -1.5125) + 10]
    assert band.sum() / 255.0 == pytest.approx(8.0, abs=0.3)
    # A square in front (z = 0.5, facing the camera) hides the ghost behind it.
    mesh = SimpleNamespace(
        vertices=np.float32([[-2, -2, 0.5], [2, -2, 0.5], [2, -1, 0.5], [-2, -1, 0.5]]),
        faces=np.int32([[0, 1, 2], [0, 2, 3]]),
        normals=None,
    )
    renderer.set_mesh(mesh)
    img = read_rgba(gl_ctx, renderer, cam, SIZE)
    renderer.set_mesh(None)
    r = _row(cam, -1.5125)
    assert img[r, SIZE[0] // 2, :3].tolist() == img[r + 12, SIZE[0] // 2, :3].tolist()


def test_set_groom_keeps_the_ghost_only_for_the_same_topology(renderer):
    g, _ = _setup(renderer)
    renderer.set_ghost_points(g.points + SHIFT, rgba=GHOST)
    renderer.set_groom(g.with_points(g.points * 2))
    assert renderer.ghost_buffer is not None and renderer.ghost_rgba == GHOST
    np.testing.assert_array_equal(renderer.ghost_points, g.points + SHIFT)
    renderer.set_groom(Groom.from_strands([np.zeros((3, 3)), np.ones((5, 3))]))
    assert renderer.ghost_buffer is None and renderer.ghost_points is None


def test_ghost_rejects_bad_arguments(renderer, gl_ctx):
    with pytest.raises(GroomError, match="set_groom"):
        renderer.set_ghost_points(np.zeros((8, 3)))
    renderer.set_ghost_points(None)  # removing nothing is fine
    g, _ = _setup(renderer)
    with pytest.raises(GroomError, match="shape"):
        renderer.set_ghost_points(g.points[:-1])
    with pytest.raises(GroomError, match="non-finite"):
        renderer.set_ghost_points(np.full_like(g.points, np.nan))
    for bad in ((1.0, 0.0, 0.0), (1.0, 0.0, 0.0, 1.5), "red"):
        with pytest.raises(ParameterError, match="rgba"):
            renderer.set_ghost_points(g.points, rgba=bad)
    assert renderer.ghost_points is None
    gl_ctx.error  # noqa: B018 -- reading it clears the flag
    renderer.set_ghost_points(g.points)
    read_rgba(gl_ctx, renderer, Camera(), (16, 16))
    renderer.set_ghost_points(None)
    assert gl_ctx.error == "GL_NO_ERROR"
