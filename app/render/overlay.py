"""Screen-space overlays over the 3-D scene: the brush circle and the outline of the symmetry
plane (program ``shaders/overlay.glsl``)."""

from __future__ import annotations

import math

import moderngl
import numpy as np

from app.render.shaders import load_program
from hairtool.errors import ParameterError

CIRCLE_SEGMENTS = 96
RING_WIDTH_PX = 1.5
CIRCLE_COLOR = (1.0, 0.55, 0.1, 0.95)
OUTLINE_COLOR = (0.8, 0.45, 1.0, 0.7)  # the X-symmetry plane: a violet no ramp or guide uses
MAX_OUTLINE = 16  # corners of an outline


def ring_strip(center: tuple[float, float], radius: float, width: float, segments: int) -> np.ndarray:
    """``(2·(segments+1), 2)`` float32 TRIANGLE_STRIP vertices of a ring, in pixels."""
    a = np.linspace(0.0, 2.0 * math.pi, segments + 1)
    unit = np.column_stack([np.cos(a), np.sin(a)])
    inner = np.asarray(center) + unit * max(radius - width / 2.0, 0.0)
    outer = np.asarray(center) + unit * (radius + width / 2.0)
    return np.stack([inner, outer], axis=1).reshape(-1, 2).astype(np.float32)


class _ScreenOverlay:
    """Triangles in pixels over the scene, straight alpha, no depth test (program ``overlay``)."""

    def __init__(self, ctx: moderngl.Context, reserve_vertices: int, color: tuple) -> None:
        self.ctx = ctx
        self.program = load_program(ctx, "overlay")
        self.vbo = ctx.buffer(reserve=reserve_vertices * 2 * 4, dynamic=True)
        self.vao = ctx.vertex_array(self.program, [(self.vbo, "2f", "in_px")])
        self.color = color
        self.viewport_size = (1.0, 1.0)

    def _draw(self, mode: int, vertices: int = -1) -> None:
        self.program["u_viewport_size"].value = self.viewport_size
        self.program["u_color"].value = self.color
        self.ctx.disable(moderngl.DEPTH_TEST)
        self.ctx.enable(moderngl.BLEND)
        # Straight alpha over the scene; alpha itself accumulates (transparent exports stay correct).
        self.ctx.blend_func = (
            moderngl.SRC_ALPHA,
            moderngl.ONE_MINUS_SRC_ALPHA,
            moderngl.ONE,
            moderngl.ONE_MINUS_SRC_ALPHA,
        )
        self.vao.render(mode, vertices=vertices)
        self.ctx.disable(moderngl.BLEND)

    def release(self) -> None:
        self.vao.release()
        self.vbo.release()
        self.program.release()


class CircleOverlay(_ScreenOverlay):
    """A ring of ``radius_px`` at ``center_px`` (pixels of a viewport of ``viewport_size``, y down)."""

    def __init__(self, ctx: moderngl.Context) -> None:
        super().__init__(ctx, 2 * (CIRCLE_SEGMENTS + 1), CIRCLE_COLOR)
        self.visible = False

    def set(
        self, center_px: tuple[float, float] | None, radius_px: float, viewport_size: tuple[float, float]
    ) -> None:
        if center_px is None:
            self.visible = False
            return
        c = tuple(float(x) for x in center_px)
        r = float(radius_px)
        w, h = (float(x) for x in viewport_size)
        if not (math.isfinite(r) and r >= 0):
            raise ParameterError("radius_px", radius_px, "a finite radius >= 0 in pixels")
        if not (w > 0 and h > 0 and all(math.isfinite(x) for x in c)):
            raise ParameterError("viewport_size", viewport_size, "a positive (width, height)")
        self.vbo.write(ring_strip(c, r, RING_WIDTH_PX, CIRCLE_SEGMENTS).tobytes())
        self.viewport_size = (w, h)
        self.visible = True

    def render(self) -> None:
        if self.visible:
            self._draw(moderngl.TRIANGLE_STRIP)


def outline_triangles(corners: np.ndarray, width: float) -> np.ndarray:
    """``(6·n, 2)`` float32 TRIANGLES vertices of the closed polygon through ``corners`` ``(n, 2)``
    drawn ``width`` pixels wide (one quad per edge)."""
    a = np.asarray(corners, np.float64)
    b = np.roll(a, -1, axis=0)
    d = b - a
    n = np.column_stack([-d[:, 1], d[:, 0]])
    n /= np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-9)
    n *= width / 2.0
    quads = np.stack([a - n, a + n, b + n, a - n, b + n, b - n], axis=1)
    return quads.reshape(-1, 2).astype(np.float32)


class OutlineOverlay(_ScreenOverlay):
    """A closed polygon outline in pixels (the symmetry plane's edges), hidden until set."""

    def __init__(self, ctx: moderngl.Context) -> None:
        super().__init__(ctx, 6 * MAX_OUTLINE, OUTLINE_COLOR)
        self.count = 0

    def set(self, corners_px: np.ndarray | None, viewport_size: tuple[float, float] = (1, 1)) -> None:
        """``(n, 2)`` corners (n ≤ :data:`MAX_OUTLINE`, finite) or None to hide."""
        if corners_px is None or len(corners_px) < 2 or not np.all(np.isfinite(corners_px)):
            self.count = 0
            return
        tris = outline_triangles(np.asarray(corners_px)[:MAX_OUTLINE], RING_WIDTH_PX)
        self.vbo.write(tris.tobytes())
        self.count = len(tris)
        self.viewport_size = (float(viewport_size[0]), float(viewport_size[1]))

    def render(self) -> None:
        if self.count:
            self._draw(moderngl.TRIANGLES, self.count)
