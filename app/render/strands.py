"""The GL strand renderer, shared by the Qt viewport and offscreen export.

It takes a ``moderngl.Context`` and draws into whatever framebuffer it is handed, so the same
code serves the widget (Qt's framebuffer, looked up again every paint) and tests/exports.

Two update speeds (as pygfx does): :meth:`StrandRenderer.update_points` rewrites the position
buffer in place while a brush drags; :meth:`StrandRenderer.set_groom` rebuilds the buffers only
when the topology changes. All strands are one ``LINE_STRIP`` draw: a ``u4`` index buffer with
the primitive-restart index 0xFFFFFFFF after each strand; ``shaders/strands.glsl`` widens the
segments into screen-space quads (core-profile GL, as Qt creates it, allows only 1-px lines).
"""

from __future__ import annotations

from typing import Any

import moderngl
import numpy as np
from numpy.typing import ArrayLike, NDArray

from app.render.camera import Camera
from app.render.mesh_layer import MeshLayer
from app.render.overlay import CircleOverlay
from app.render.ramps import DEFAULT_RAMP, ramp_stops, ramp_texture
from app.render.shaders import load_program
from hairtool.errors import GroomError, ParameterError
from hairtool.groom import Groom, Topology

RESTART_INDEX = 0xFFFFFFFF
RAMP_TEXELS = 256
DEFAULT_BACKGROUND = (0.16, 0.17, 0.19, 1.0)


def strip_indices(topology: Topology) -> NDArray[np.uint32]:
    """``(V + S,)`` u4: each strand's vertex indices followed by the restart index.

    Vertex i of strand s lands at position i + s, so the restarts fall at offsets[s+1] + s.
    """
    idx = np.full(topology.vertex_count + topology.strand_count, RESTART_INDEX, dtype=np.uint32)
    v = np.arange(topology.vertex_count, dtype=np.int64)
    idx[v + topology.strand_index] = v
    return idx


def strip_indices_reference(topology: Topology) -> NDArray[np.uint32]:
    """Loop over strands: the plain definition :func:`strip_indices` is tested against."""
    parts = []
    for s in range(topology.strand_count):
        parts.append(np.arange(topology.offsets[s], topology.offsets[s + 1]))
        parts.append([RESTART_INDEX])
    return np.concatenate(parts).astype(np.uint32)


class StrandRenderer:
    """Draws one groom (plus an optional head mesh and the brush circle) with a :class:`Camera`."""

    def __init__(self, ctx: moderngl.Context) -> None:
        self.ctx = ctx
        self.program = load_program(ctx, "strands")
        self.line_width = 2.0
        self.background: tuple[float, float, float, float] = DEFAULT_BACKGROUND
        self.ramp = DEFAULT_RAMP
        self.ramp_texture = ctx.texture((RAMP_TEXELS, 1), 3, dtype="f4")
        self.ramp_texture.filter = (moderngl.LINEAR, moderngl.LINEAR)
        self.ramp_texture.repeat_x = False
        self.ramp_texture.write(ramp_texture(self.ramp, RAMP_TEXELS).tobytes())
        self.mesh = MeshLayer(ctx)
        self.overlay = CircleOverlay(ctx)
        self.topology: Topology | None = None
        self.bounds: tuple[NDArray[np.float32], NDArray[np.float32]] | None = None
        self.position_buffer: moderngl.Buffer | None = None
        self.param_buffer: moderngl.Buffer | None = None
        self.color_buffer: moderngl.Buffer | None = None
        self.index_buffer: moderngl.Buffer | None = None
        self.vao: moderngl.VertexArray | None = None
        self.use_vertex_colors = False

    # -- content ---------------------------------------------------------------------
    def set_groom(self, groom: Groom) -> None:
        """Upload a groom: positions, t = i/(N_s−1), the strip index buffer (and the groom's colours)."""
        top = groom.topology
        self._free_groom()
        self.topology = top
        v = top.vertex_count
        self.position_buffer = self.ctx.buffer(np.ascontiguousarray(groom.points, np.float32), dynamic=True)
        self.param_buffer = self.ctx.buffer(np.ascontiguousarray(top.vertex_param, np.float32))
        self.color_buffer = self.ctx.buffer(reserve=v * 12, dynamic=True)
        self.index_buffer = self.ctx.buffer(strip_indices(top))
        self.vao = self.ctx.vertex_array(
            self.program,
            [
                (self.position_buffer, "3f", "in_position"),
                (self.param_buffer, "1f", "in_t"),
                (self.color_buffer, "3f", "in_color"),
            ],
            index_buffer=self.index_buffer,
            index_element_size=4,
        )
        self.bounds = groom.bounds
        self.set_vertex_colors(groom.colors)

    def update_points(self, points: ArrayLike) -> None:
        """Rewrite only the positions (same strands), e.g. every mouse move of a brush stroke."""
        if self.topology is None or self.position_buffer is None:
            raise GroomError("update_points needs a groom: call set_groom first")
        p = np.ascontiguousarray(points, dtype=np.float32)
        v = self.topology.vertex_count
        if p.shape != (v, 3):
            raise GroomError(f"points must have shape ({v}, 3) like the groom, got {p.shape}")
        if not np.all(np.isfinite(p)):
            raise GroomError("points have a non-finite coordinate")
        self.position_buffer.write(p)
        self.bounds = (p.min(axis=0), p.max(axis=0))

    def set_vertex_colors(self, colors: ArrayLike | None) -> None:
        """``(V, 3)`` RGB in [0, 1] per vertex, or None to colour by the ramp along t."""
        if colors is None:
            self.use_vertex_colors = False
            return
        if self.topology is None or self.color_buffer is None:
            raise GroomError("set_vertex_colors needs a groom: call set_groom first")
        c = np.ascontiguousarray(colors, dtype=np.float32)
        v = self.topology.vertex_count
        if c.shape != (v, 3):
            raise ParameterError("colors", c.shape, f"shape ({v}, 3) (one RGB per vertex)")
        if not np.all(np.isfinite(c)):
            raise ParameterError("colors", "non-finite", "finite RGB values in [0, 1]")
        self.color_buffer.write(np.clip(c, 0.0, 1.0))
        self.use_vertex_colors = True

    def set_ramp(self, name: str) -> None:
        """Colour ramp used while no vertex colours are set (see :data:`app.render.ramps.RAMPS`)."""
        ramp_stops(name)  # validates the name
        if name != self.ramp:
            self.ramp_texture.write(ramp_texture(name, RAMP_TEXELS).tobytes())
            self.ramp = name

    def set_mesh(self, mesh: Any | None) -> None:
        """A head mesh (``vertices``, ``faces``, optional ``normals``) drawn shaded; None removes it."""
        self.mesh.set_mesh(mesh)

    def set_overlay_circle(
        self,
        center_px: tuple[float, float] | None,
        radius_px: float = 0.0,
        viewport_size: tuple[float, float] = (1, 1),
    ) -> None:
        """Brush circle in widget pixels (y down) of a viewport ``viewport_size``; None hides it."""
        self.overlay.set(center_px, radius_px, viewport_size)

    def scene_bounds(self) -> tuple[NDArray[np.float32], NDArray[np.float32]] | None:
        """Box around the groom and the mesh, for :meth:`Camera.frame`."""
        boxes = [b for b in (self.bounds, self.mesh.bounds) if b is not None]
        if not boxes:
            return None
        return np.min([b[0] for b in boxes], axis=0), np.max([b[1] for b in boxes], axis=0)

    # -- drawing ---------------------------------------------------------------------
    def render(self, fbo: moderngl.Framebuffer, camera: Camera, size: tuple[int, int]) -> None:
        """Clear ``fbo`` to the background and draw mesh, strands and overlay at ``size`` pixels."""
        w, h = int(size[0]), int(size[1])
        if w <= 0 or h <= 0:
            return
        width = float(self.line_width)
        if not np.isfinite(width) or width <= 0:
            raise ParameterError("line_width", self.line_width, "a positive width in pixels")
        ctx = self.ctx
        fbo.use()
        ctx.viewport = (0, 0, w, h)
        fbo.clear(*self.background, depth=1.0)
        ctx.enable(moderngl.DEPTH_TEST)
        ctx.disable(moderngl.BLEND | moderngl.CULL_FACE)
        view = camera.view_matrix()
        mvp = (view @ camera.projection_matrix(w / h)).astype(np.float32)
        self.mesh.render(mvp, view)
        if self.vao is not None:
            prog = self.program
            prog["u_mvp"].write(mvp.tobytes())
            prog["u_viewport"].value = (float(w), float(h))
            prog["u_width"].value = width
            prog["u_use_vertex_color"].value = self.use_vertex_colors
            self.ramp_texture.use(location=0)
            prog["u_ramp"].value = 0
            self.vao.render(moderngl.LINE_STRIP)
        self.overlay.render()
        ctx.disable(moderngl.DEPTH_TEST)

    def _free_groom(self) -> None:
        for name in ("vao", "index_buffer", "color_buffer", "param_buffer", "position_buffer"):
            obj = getattr(self, name)
            if obj is not None:
                obj.release()
                setattr(self, name, None)
        self.topology = None
        self.bounds = None
        self.use_vertex_colors = False

    def release(self) -> None:
        """Free every GL object this renderer made (call with its context current)."""
        self._free_groom()
        self.mesh.release()
        self.overlay.release()
        self.ramp_texture.release()
        self.program.release()
