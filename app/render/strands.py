"""The strand renderer, shared by the Qt viewport and offscreen export.

It takes a ``moderngl.Context`` and draws into whatever framebuffer it is handed, so the same
code serves the widget (Qt's framebuffer, looked up again every paint) and tests/exports.

Two update speeds (as pygfx does): :meth:`StrandRenderer.update_points` rewrites the positions in
place while a brush drags; :meth:`StrandRenderer.set_groom` rebuilds the buffers only when the
topology changes. The strands are drawn in one of four ways (:meth:`StrandRenderer.line_method`):

- ``"cpu"`` (on software GL: Mesa's llvmpipe, softpipe, swrast): rasterized on the CPU
  (:mod:`app.render.soft_raster`, the same pixels as the GL methods below to within a pixel) and
  put into the frame by :mod:`app.render.raster_layer`. llvmpipe's cost is per primitive, not
  per pixel, so a dense groom of short segments is several times faster this way.
  ``StrandRenderer.strand_raster`` chooses: ``"auto"`` (the default: "cpu" on software GL, else
  the GL methods), ``"gl"`` or ``"cpu"``; the environment variable ``HAIRTOOL_STRAND_RASTER``
  (``auto`` | ``gl`` | ``cpu``) sets the default;

or as one GL draw call, in one of three ways (:meth:`StrandRenderer.gl_line_method`):

- ``"thin"`` (widths up to 1.5 px, or ``fast_lines``): plain 1-px ``LINES``, two indices per
  segment (``shaders/strands_thin.glsl``) — the cheapest draw, about half the time of the wide
  ones on llvmpipe (5,000 × 20 strands at 1024 × 768: ≈ 40 ms against ≈ 80 ms);
- ``"geometry"`` (wider lines, the default): a geometry shader widens each segment of a
  ``LINE_STRIP`` (a primitive restart after each strand) into a screen-space quad of
  ``line_width`` pixels (``shaders/strands.glsl``);
- ``"quads"``: the same quads, pixel for pixel, without a geometry stage: four vertices per
  segment whose vertex shader pulls the segment's ends from a texture
  (``shaders/strands_quads.glsl``), for drivers without (fast) geometry shaders. On llvmpipe it
  is about 5 % slower than the geometry shader (one instance per segment was 1.5× slower).

Core-profile GL, as Qt creates it, allows only 1-px lines, hence the quads for wider ones.
On llvmpipe a draw costs about 0.2 µs per primitive (line or triangle) whatever the stages,
plus the pixels it covers: fewer primitives, not a cheaper shader, is what makes it faster.
An optional ghost (:meth:`StrandRenderer.set_ghost_points`) draws the same strands at other
positions first, in one flat translucent colour (always with a GL method).

The studio switches between two sets of strands on every stroke (a share of the render hair
while dragging, all of it on release): the renderer keeps the buffers of the strands it drew
last (:data:`KEEP_TOPOLOGIES`), so switching back to them rewrites positions into buffers that
exist rather than allocating and uploading everything again.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from typing import Any

import moderngl
import numpy as np
from numpy.typing import ArrayLike, NDArray

from app.render.camera import Camera
from app.render.character_skin import CharacterLayer
from app.render.drawn import Drawn
from app.render.hair_shading import DEFAULT_LOOK, HairLook, light_and_eye, shade
from app.render.mesh_layer import MeshLayer
from app.render.overlay import CircleOverlay, OutlineOverlay
from app.render.ramps import DEFAULT_RAMP, ramp_stops, ramp_texture, sample_linear
from app.render.raster_layer import RasterLayer
from app.render.shaders import load_program
from app.render.strand_gpu import (
    RESTART_INDEX,
    PointSet,
    StrandGPU,
    changed_strands,
    strand_rows,
    strip_indices,
    vertex_runs,
)
from hairtool.bounds import box
from hairtool.errors import GroomError, ParameterError
from hairtool.groom import Groom, Topology
from hairtool.sorted_ids import distinct, union

__all__ = [
    "RESTART_INDEX",
    "StrandRenderer",
    "default_strand_raster",
    "is_software_gl",
    "strip_indices",
    "strip_indices_reference",
]

THIN_MAX_WIDTH = 1.5  # px: up to this width strands are drawn as plain 1-px lines
WIDE_LINES = ("geometry", "quads")
_PROGRAMS = {"thin": "strands_thin", "quads": "strands_quads", "geometry": "strands"}
_INDEX_KIND = {"thin": "lines", "quads": "quads", "geometry": "strip"}
RAMP_TEXELS = 256
DEFAULT_BACKGROUND = (0.16, 0.17, 0.19, 1.0)
DEFAULT_GHOST_RGBA = (0.55, 0.75, 1.0, 0.35)
RASTER_ENV = "HAIRTOOL_STRAND_RASTER"
STRAND_RASTERS = ("auto", "gl", "cpu")
SOFTWARE_GL = ("llvmpipe", "softpipe", "swrast")
RESHADE_SHARE = 0.25  # moves that changed more of the vertices than this shade them all again
KEEP_TOPOLOGIES = 1  # sets of strands kept besides the current one (the studio's drag / release pair)


def is_software_gl(ctx: moderngl.Context) -> bool:
    """Whether ``ctx`` is Mesa's software rasterizer (GL_RENDERER names llvmpipe, softpipe or swrast)."""
    renderer = str(ctx.info.get("GL_RENDERER", "")).lower()
    return any(name in renderer for name in SOFTWARE_GL)


def default_strand_raster() -> str:
    """``HAIRTOOL_STRAND_RASTER`` (``auto``, ``gl`` or ``cpu``; unset: ``auto``)."""
    value = os.environ.get(RASTER_ENV, "auto").strip().lower() or "auto"
    if value not in STRAND_RASTERS:
        raise ParameterError(RASTER_ENV, value, " or ".join(STRAND_RASTERS))
    return value


def strip_indices_reference(topology: Topology) -> NDArray[np.uint32]:
    """Loop over strands: the plain definition :func:`strip_indices` is tested against."""
    parts = []
    for s in range(topology.strand_count):
        parts.append(np.arange(topology.offsets[s], topology.offsets[s + 1]))
        parts.append([RESTART_INDEX])
    return np.concatenate(parts).astype(np.uint32)


@dataclass
class _Kept:
    """What the renderer made for one topology, kept for when it comes back."""

    gpu: StrandGPU
    main: PointSet
    vaos: dict
    segment_starts: NDArray[np.int64]
    ramp: str  # the ramp ramp_colors were sampled from
    ramp_colors: NDArray[np.float32] | None
    taper_scale: tuple[float, NDArray[np.float64]] | None
    base_store: NDArray[np.float32] | None

    def release(self) -> None:
        for vao in self.vaos.values():
            vao.release()
        self.main.release()
        self.gpu.release()


class StrandRenderer:
    """Draws one groom (plus an optional head mesh and the brush circle) with a :class:`Camera`."""

    def __init__(self, ctx: moderngl.Context) -> None:
        self.ctx = ctx
        self.programs = {method: load_program(ctx, name) for method, name in _PROGRAMS.items()}
        self.line_width = 2.0
        self.fast_lines = False  # the artist's "fast lines": 1-px lines whatever the width
        self.wide_lines = "geometry"  # how widths above THIN_MAX_WIDTH are drawn: "geometry" or "quads"
        self.strand_raster = default_strand_raster()  # "auto", "gl" or "cpu" (see the module doc)
        self.software_gl = is_software_gl(ctx)
        self.raster: RasterLayer | None = None  # made on the first CPU draw
        self.background: tuple[float, float, float, float] = DEFAULT_BACKGROUND
        self.ramp = DEFAULT_RAMP
        self.ramp_texture = ctx.texture((RAMP_TEXELS, 1), 3, dtype="f4")
        self.ramp_texture.filter = (moderngl.LINEAR, moderngl.LINEAR)
        self.ramp_texture.repeat_x = False
        self.ramp_texture.write(ramp_texture(self.ramp, RAMP_TEXELS).tobytes())
        self.mesh = MeshLayer(ctx)
        self.character = CharacterLayer(ctx)  # a character's skinned meshes (app.ui.character_studio)
        self.overlay = CircleOverlay(ctx)
        self.outline = OutlineOverlay(ctx)
        self.topology: Topology | None = None
        self.bounds: tuple[NDArray[np.float32], NDArray[np.float32]] | None = None
        self._gpu: StrandGPU | None = None
        self._main: PointSet | None = None
        self._ghost: PointSet | None = None
        self._vaos: dict[tuple[str, bool], moderngl.VertexArray] = {}  # (method, ghost) → VAO
        self.use_vertex_colors = False
        self.ghost_rgba: tuple[float, float, float, float] = DEFAULT_GHOST_RGBA
        self._segment_starts: NDArray[np.int64] | None = None
        self._ramp_colors: NDArray[np.float32] | None = None  # the ramp at every vertex, for "cpu"
        # Hair shading (app.render.hair_shading): the base colours (vertex colours or the ramp)
        # lit from the strand direction per vertex, redone when points, colours or view change.
        self.hair_shading = False
        self.taper = 0.0  # width at the tip = (1 − taper) × at the root (per segment, at its middle t)
        self._taper_scale: tuple[float, NDArray[np.float64]] | None = None
        self.hair_look: HairLook = DEFAULT_LOOK
        self._base_colors: NDArray[np.float32] | None = None
        self._base_store: NDArray[np.float32] | None = None  # memory for _base_colors, per topology
        self._kept: list[_Kept] = []  # the last topologies drawn before this one (KEEP_TOPOLOGIES)
        self._version = 0  # bumped by every change of points or base colours
        self._shade_key: tuple | None = None
        # Strands moved since the last shade by update_points alone (None: shade them all).
        self._reshade: NDArray[np.int64] | None = None
        self.last_moved: NDArray[np.int64] | None = None  # the strands the last update_points changed
        # (point set, colours, the raster's draw count) after the last CPU draw told what changed
        self._cpu_drawn: tuple | None = None

    # -- what is drawn and how -------------------------------------------------------
    def line_method(self) -> str:
        """How the strands are drawn now: "cpu", "thin", "quads" or "geometry" (see the module doc)."""
        if self.strand_raster not in STRAND_RASTERS:
            raise ParameterError("strand_raster", self.strand_raster, " or ".join(STRAND_RASTERS))
        if self.strand_raster == "cpu" or (self.strand_raster == "auto" and self.software_gl):
            return "cpu"
        return self.gl_line_method()

    def gl_line_method(self) -> str:
        """The GL draw for the current width: "thin", "quads" or "geometry" (the ghost's too)."""
        if self.fast_lines or float(self.line_width) <= THIN_MAX_WIDTH:
            return "thin"
        if self.wide_lines not in WIDE_LINES:
            raise ParameterError("wide_lines", self.wide_lines, " or ".join(WIDE_LINES))
        return self.wide_lines

    @property
    def program(self) -> moderngl.Program:
        """The program of the current :meth:`gl_line_method`."""
        return self.programs[self.gl_line_method()]

    @property
    def position_buffer(self) -> moderngl.Buffer | None:
        """The groom's vertex buffer of positions (``"thin"`` and ``"geometry"`` draws), up to
        date (while the quads draw is in use it is uploaded only when asked for: here)."""
        return None if self._main is None else self._main.vertex_buffer(draw=False)

    @property
    def param_buffer(self) -> moderngl.Buffer | None:
        return None if self._gpu is None else self._gpu.param_buffer

    @property
    def color_buffer(self) -> moderngl.Buffer | None:
        return None if self._gpu is None else self._gpu.color_buffer

    @property
    def index_buffer(self) -> moderngl.Buffer | None:
        """The index buffer of the current :meth:`gl_line_method` (None without a groom)."""
        return None if self._gpu is None else self._gpu.index_buffer(_INDEX_KIND[self.gl_line_method()])

    @property
    def vao(self) -> moderngl.VertexArray | None:
        """The strands' vertex array for the current :meth:`gl_line_method` (None without a groom)."""
        return None if self._main is None else self._vao(self.gl_line_method(), ghost=False)

    @property
    def ghost_buffer(self) -> moderngl.Buffer | None:
        """The ghost's vertex buffer of positions, up to date (as :attr:`position_buffer`)."""
        return None if self._ghost is None else self._ghost.vertex_buffer(draw=False)

    @property
    def ghost_points(self) -> NDArray[np.float32] | None:
        """The ghost's positions (read-only view), or None without a ghost."""
        return None if self._ghost is None else self._ghost.points

    def _vao(self, method: str, ghost: bool) -> moderngl.VertexArray:
        # The quads draw reads no attributes (its points come from textures): one VAO serves both.
        key = (method, ghost and method != "quads")
        vao = self._vaos.get(key)
        if vao is None:
            gpu, prog = self._gpu, self.programs[method]
            index = gpu.index_buffer(_INDEX_KIND[method])
            if method == "quads":
                content = []
            else:
                points = (self._ghost if ghost else self._main).buffer
                content = [(points, "3f", "in_position"), (gpu.param_buffer, "1f", "in_t")]
                content.append((gpu.color_buffer, "3f", "in_color"))
            vao = self._vaos[key] = self.ctx.vertex_array(
                prog, content, index_buffer=index, index_element_size=4
            )
        return vao

    # -- content ---------------------------------------------------------------------
    def set_groom(self, groom: Groom) -> None:
        """Upload a groom: positions, t = i/(N_s−1) (and the groom's colours); index buffers
        follow when a line method first needs them. A ghost of the same topology is kept."""
        self.set_strands(groom.points, groom.topology, groom.colors)

    def set_strands(self, points: ArrayLike, topology: Topology, colors: ArrayLike | None = None) -> None:
        """:meth:`set_groom` from ``(V, 3)`` points and their topology (no groom made to pass
        them: the studio's render hair has millions of points). Strands of a topology drawn
        recently reuse what was made for it (buffers, t, colours' memory)."""
        p, bounds = self._checked_points(points, topology.vertex_count, "points")
        ghost = self._ghost_points_if_same(topology)
        kept = self._take_kept(topology)
        self._park_groom()
        self.topology = topology
        if kept is None:
            self._gpu = StrandGPU(self.ctx, topology)
            self._main = PointSet(self._gpu, p)
            self._segment_starts = np.ascontiguousarray(topology.segment_end - 1)
            self._segment_starts.flags.writeable = False  # fixed: the raster need not compare it
        else:
            self._gpu, self._main, self._segment_starts = kept.gpu, kept.main, kept.segment_starts
            self._vaos.update(kept.vaos)
            self._ramp_colors = kept.ramp_colors if kept.ramp == self.ramp else None
            self._taper_scale, self._base_store = kept.taper_scale, kept.base_store
            self._main.write(p)
        self._version += 1
        self._reshade = None
        self.bounds = bounds
        self.set_vertex_colors(colors)
        if ghost is not None:
            self.set_ghost_points(ghost, self.ghost_rgba)

    def show(self, drawn: Drawn) -> None:
        """Upload everything of a :class:`~app.render.drawn.Drawn`: strands, look and colours."""
        self.set_strands(drawn.points, drawn.topology)
        self.set_look(drawn)
        self.set_vertex_colors(drawn.colors)

    def set_look(self, drawn: Drawn) -> None:
        """The ramp, line width, taper and hair shading of ``drawn`` (no upload of points)."""
        self.set_ramp(drawn.ramp)
        self.line_width = float(drawn.line_width)
        self.set_hair_shading(drawn.shaded)
        self.taper = float(drawn.taper)

    @staticmethod
    def _checked_points(points: ArrayLike, v: int, what: str) -> tuple[NDArray[np.float32], tuple]:
        """The points as contiguous float32, and their box (which also finds a non-finite one:
        a NaN or an inf anywhere shows in it, at no extra pass over millions of points)."""
        p = np.ascontiguousarray(points, dtype=np.float32)
        if p.shape != (v, 3):
            raise GroomError(f"{what} must have shape ({v}, 3) like the groom, got {p.shape}")
        if v == 0:
            return p, (np.zeros(3, np.float32), np.zeros(3, np.float32))
        bounds = box(p)
        if not (np.all(np.isfinite(bounds[0])) and np.all(np.isfinite(bounds[1]))):
            raise GroomError(f"{what} have a non-finite coordinate")
        return p, bounds

    def _take_kept(self, topology: Topology) -> _Kept | None:
        for i, kept in enumerate(self._kept):
            if kept.gpu.topology is topology or kept.gpu.topology == topology:
                return self._kept.pop(i)
        return None

    def _park_groom(self) -> None:
        """Keep the current groom's GPU objects for when its topology comes back (the ghost
        goes); free the oldest kept beyond :data:`KEEP_TOPOLOGIES`."""
        if self._gpu is None or self._main is None:
            self._free_groom()
            return
        self._free_ghost()
        self._kept.insert(
            0,
            _Kept(
                self._gpu, self._main, dict(self._vaos), self._segment_starts, self.ramp,
                self._ramp_colors, self._taper_scale, self._base_store,
            ),
        )  # fmt: skip
        self._vaos.clear()
        self._main = self._gpu = None
        self._free_groom()
        while len(self._kept) > KEEP_TOPOLOGIES:
            self._kept.pop().release()

    def update_points(self, points: ArrayLike, changed: ArrayLike | None = None) -> None:
        """Rewrite only the positions (same strands), e.g. every mouse move of a brush stroke.

        Only the strands that changed are uploaded and shaded again: ``changed``, the sorted ids
        of the only strands that may differ from the last points (the engine knows them), or
        without it the strands whose points differ bit for bit (found by comparing)."""
        if self.topology is None or self._main is None:
            raise GroomError("update_points needs a groom: call set_groom first")
        p, self.bounds = self._checked_points(points, self.topology.vertex_count, "points")
        if changed is not None:
            changed = distinct(np.asarray(changed, np.int64))
            if changed.size and (changed[0] < 0 or changed[-1] >= self.topology.strand_count):
                raise ParameterError(
                    "changed", "a strand id out of range", f"ids in [0, {self.topology.strand_count})"
                )
        moved = self._main.write(p, changed, find=self.hair_shading)
        self.last_moved = moved
        if self._reshade is not None:
            self._reshade = None if moved is None else union(self._reshade, moved)
        self._version += 1

    def set_ghost_points(
        self, points: ArrayLike | None, rgba: tuple[float, float, float, float] = DEFAULT_GHOST_RGBA
    ) -> None:
        """A second copy of the groom's strands at ``points`` (``(V, 3)``, same topology), drawn
        before the strands in one flat translucent ``rgba`` (each in [0, 1]); None removes it.

        E.g. a keyframe reconstruction shown under the original. Same line width as the strands;
        it is depth-tested against the head mesh but writes no depth, so the strands always draw
        over it. Calling it again with the same topology only rewrites the positions;
        :meth:`set_groom` keeps the ghost while the topology stays the same and drops it otherwise.
        """
        if points is None:
            self._free_ghost()
            return
        if self.topology is None or self._gpu is None:
            raise GroomError("set_ghost_points needs a groom: call set_groom first")
        try:
            c = tuple(float(x) for x in rgba)
        except (TypeError, ValueError):
            raise ParameterError("rgba", rgba, "(r, g, b, a) in [0, 1]") from None
        if len(c) != 4 or not all(0.0 <= x <= 1.0 for x in c):
            raise ParameterError("rgba", rgba, "(r, g, b, a) in [0, 1]")
        p = np.ascontiguousarray(points, dtype=np.float32)
        v = self.topology.vertex_count
        if p.shape != (v, 3):
            raise GroomError(f"ghost points must have shape ({v}, 3) like the groom, got {p.shape}")
        if not np.all(np.isfinite(p)):
            raise GroomError("ghost points have a non-finite coordinate")
        self.ghost_rgba = c  # type: ignore[assignment]
        if self._ghost is None:
            self._ghost = PointSet(self._gpu, p)
        else:
            self._ghost.write(p)

    def _ghost_points_if_same(self, top: Topology) -> NDArray[np.float32] | None:
        old = self.topology
        if self._ghost is None or old is None:
            return None
        if old.vertex_count != top.vertex_count or not np.array_equal(old.offsets, top.offsets):
            return None
        return self._ghost.points.copy()

    def _free_ghost(self) -> None:
        for key in [k for k in self._vaos if k[1]]:
            self._vaos.pop(key).release()
        if self._ghost is not None:
            self._ghost.release()
            self._ghost = None

    def set_vertex_colors(self, colors: ArrayLike | None) -> None:
        """``(V, 3)`` RGB in [0, 1] per vertex, or None to colour by the ramp along t."""
        if colors is None:
            self.use_vertex_colors = False
            self._base_colors = None
            self._shade_key = None
            return
        if self.topology is None or self._gpu is None:
            raise GroomError("set_vertex_colors needs a groom: call set_groom first")
        c = np.ascontiguousarray(colors, dtype=np.float32)
        v = self.topology.vertex_count
        if c.shape != (v, 3):
            raise ParameterError("colors", c.shape, f"shape ({v}, 3) (one RGB per vertex)")
        if not np.all(np.isfinite(c)):
            raise ParameterError("colors", "non-finite", "finite RGB values in [0, 1]")
        if self.use_vertex_colors and self._base_colors is not None and self._base_colors.shape == c.shape:
            self._recolour(np.clip(c, 0.0, 1.0))
            return
        if self._base_store is None or self._base_store.shape != c.shape:
            self._base_store = np.empty_like(c)
        self._base_colors = np.clip(c, 0.0, 1.0, out=self._base_store)
        if not self.hair_shading:  # shaded, the colour buffer gets the shade of these instead
            self._gpu.write_colors(self._base_colors)
        self.use_vertex_colors = True
        self._version += 1
        self._shade_key = None
        self._reshade = None

    def _recolour(self, c: NDArray[np.float32]) -> None:
        """New vertex colours over vertex colours (a colour mode that follows the brush, such as
        displacement): only the strands whose colours changed are uploaded, or shaded again."""
        moved = changed_strands(self._base_colors, c, self.topology)
        if moved.size == 0:
            return
        runs = vertex_runs(self.topology.offsets, moved)
        for a, b in runs:
            self._base_colors[a:b] = c[a:b]
        if not self.hair_shading:
            for a, b in runs:
                self._gpu.colors[a:b] = c[a:b]
            self._gpu.colors_written(runs)
        elif self._reshade is not None:
            self._reshade = union(self._reshade, moved)
        self._version += 1

    def set_ramp(self, name: str) -> None:
        """Colour ramp used while no vertex colours are set (see :data:`app.render.ramps.RAMPS`)."""
        ramp_stops(name)  # validates the name
        if name != self.ramp:
            self.ramp_texture.write(ramp_texture(name, RAMP_TEXELS).tobytes())
            self.ramp = name
            self._ramp_colors = None
            self._shade_key = None

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

    def set_overlay_outline(self, corners_px, viewport_size: tuple[float, float] = (1, 1)) -> None:
        """A closed outline through ``(n, 2)`` widget pixels (the symmetry plane); None hides it."""
        self.outline.set(corners_px, viewport_size)

    def scene_bounds(self) -> tuple[NDArray[np.float32], NDArray[np.float32]] | None:
        """Box around the groom and the mesh, for :meth:`Camera.frame`."""
        boxes = [b for b in (self.bounds, self.mesh.bounds, self.character.bounds) if b is not None]
        if not boxes:
            return None
        return np.min([b[0] for b in boxes], axis=0), np.max([b[1] for b in boxes], axis=0)

    # -- drawing ---------------------------------------------------------------------
    def render(
        self,
        fbo: moderngl.Framebuffer,
        camera: Camera,
        size: tuple[int, int],
        samples: int | None = None,
        overlays: bool = True,
    ) -> None:
        """Clear ``fbo`` to the background and draw mesh, strands and overlay at ``size`` pixels
        (CPU strands over a bare background write every pixel instead of a clear, leaving the
        depth buffer as it was: nothing after them is depth-tested).

        ``samples``: the framebuffer's samples per pixel where ``fbo.samples`` does not know them
        (moderngl reports 0 for framebuffers it did not make, such as Qt's). ``overlays`` False
        leaves them out (a view keeps the image without them: :meth:`render_overlays`).
        """
        w, h = int(size[0]), int(size[1])
        if w <= 0 or h <= 0:
            return
        width = float(self.line_width)
        if not np.isfinite(width) or width <= 0:
            raise ParameterError("line_width", self.line_width, "a positive width in pixels")
        method = self.line_method()
        samples = fbo.samples if samples is None else samples
        # CPU strands blitted over nothing but the background write every pixel: no GL clear.
        cpu_only = method == "cpu" and samples == 0 and self._main is not None
        cpu_only = cpu_only and self.mesh.vao is None and not self.character.drawn and self._ghost is None
        ctx = self.ctx
        fbo.use()
        ctx.viewport = (0, 0, w, h)
        view = camera.view_matrix()
        mvp = (view @ camera.projection_matrix(w / h)).astype(np.float32)
        backdrop = self._backdrop_key(method, samples, cpu_only, mvp, view, (w, h))
        kept = backdrop is not None and self.cpu_raster_layer().holds_backdrop(backdrop)
        if not (cpu_only or kept):
            fbo.clear(*self.background, depth=1.0)
        ctx.enable(moderngl.DEPTH_TEST)
        ctx.disable(moderngl.BLEND | moderngl.CULL_FACE)
        if not kept:  # (kept: the raster layer has what these draw, and the strands cover it)
            self.mesh.render(mvp, view)
            self.character.render(mvp, view)
        self._shade(camera)
        if self._main is not None:
            gl_method = self.gl_line_method()
            if method != "cpu" or self._ghost is not None:
                self._set_uniforms(gl_method, mvp, (w, h), width)
            if self._ghost is not None:
                self._render_ghost(fbo, gl_method)
            if method == "cpu":
                width = 1.0 if gl_method == "thin" else width
                background = self.background if cpu_only else None
                self._render_cpu(fbo, samples, mvp, (w, h), width, background, backdrop)
            else:
                self.programs[method]["u_use_flat_color"].value = False
                self._draw(method, self._main, ghost=False)
        ctx.disable(moderngl.DEPTH_TEST)
        if overlays:
            self.render_overlays(fbo, (w, h))

    def render_overlays(self, fbo: moderngl.Framebuffer, size: tuple[int, int]) -> None:
        """The symmetry outline and the brush circle over what ``fbo`` holds (``size`` pixels)."""
        fbo.use()
        self.ctx.viewport = (0, 0, int(size[0]), int(size[1]))
        self.ctx.disable(moderngl.DEPTH_TEST)
        self.outline.render()
        self.overlay.render()

    def _set_uniforms(self, method: str, mvp: NDArray, size: tuple[int, int], width: float) -> None:
        prog = self.programs[method]
        prog["u_mvp"].write(mvp.tobytes())
        self.ramp_texture.use(location=0)
        for name, value in (
            ("u_viewport", (float(size[0]), float(size[1]))),
            ("u_width", width),
            ("u_use_vertex_color", self.vertex_coloured),
            ("u_taper", self._checked_taper()),
            ("u_ramp", 0),
            ("u_points", 1),
            ("u_colors", 2),
        ):
            if name in prog:
                prog[name].value = value
        if method == "quads" and self.vertex_coloured:
            self._gpu.color_texture().use(location=2)

    def cpu_raster_layer(self) -> RasterLayer:
        """The layer strands rasterized on the CPU go through (made now where none is yet): an
        export defers its raster to its worker there (:class:`~app.render.raster_layer.RasterJob`)."""
        if self.raster is None:
            self.raster = RasterLayer(self.ctx)
        return self.raster

    def _backdrop_key(self, method: str, samples: int, cpu_only: bool, mvp, view, size) -> tuple | None:
        """The key of what GL draws under CPU strands in a single-sampled frame, when only the
        head mesh is (no ghost, no character): the raster layer keeps it by this key
        (:meth:`RasterLayer.holds_backdrop`), so a frame where only the strands changed (a
        scrubbed animation) neither draws the mesh nor reads the frame back. None otherwise."""
        if method != "cpu" or samples != 0 or cpu_only or self._main is None:
            return None
        if self._ghost is not None or self.character.drawn or self.mesh.vao is None:
            return None
        mesh = (self.mesh.vao, tuple(float(c) for c in self.mesh.color))
        return (tuple(size), tuple(self.background), mesh, mvp.tobytes(), view.tobytes())

    def _render_cpu(
        self, fbo, samples: int, mvp, size: tuple[int, int], width: float, background, backdrop=None
    ) -> None:
        self.cpu_raster_layer()
        points, colors, starts = self._main.cpu_points(), self.cpu_colors(), self._segment_starts
        mesh = self.mesh.vao is not None or self.character.drawn
        scale = self.segment_width_scale() if width > 1.0 else None
        changed = self._cpu_changed(colors, samples == 0 and background is not None)
        self.raster.render(
            fbo, samples, points, starts, colors, mvp, size, width, background=background, read_depth=mesh,
            scale=scale, backdrop=backdrop, changed=changed,
        )  # fmt: skip

    def _cpu_changed(self, colors: NDArray[np.float32], told: bool) -> NDArray[np.int64] | None:
        """The vertex ranges whose points or colours were written since the raster's last draw,
        when that draw was the last CPU draw and was told them too (``told``: this one is, a
        single-sampled draw over the background) of these same points and colours; else None:
        unknown, the raster compares them all. The count starts afresh."""
        main, gpu, raster = self._main, self._gpu, self.raster.raster
        last = self._cpu_drawn
        known = last is not None and last[0] is main and last[1] is colors and last[2] == raster.draws
        known = (
            known
            and main.cpu_runs is not None
            and (colors is not gpu.colors or gpu.cpu_color_runs is not None)
        )
        runs = None
        if known:
            parts = list(main.cpu_runs) + (list(gpu.cpu_color_runs) if colors is gpu.colors else [])
            runs = np.concatenate(parts) if parts else np.zeros((0, 2), np.int64)
        main.cpu_runs, gpu.cpu_color_runs = [], []
        self._cpu_drawn = (main, colors, raster.draws + 1) if told else None
        return runs

    def _checked_taper(self) -> float:
        t = float(self.taper)
        if not 0.0 <= t < 1.0:
            raise ParameterError(
                "taper", self.taper, "a number in [0, 1): the share of the width lost at the tip"
            )
        return t

    def segment_width_scale(self) -> NDArray[np.float64] | None:
        """Per segment, its width factor 1 − taper·(t_a + t_b)/2 (as the shaders compute it from
        the vertex parameter t in float32), or None without a taper."""
        taper = self._checked_taper()
        if taper == 0.0 or self._gpu is None:
            return None
        if self._taper_scale is None or self._taper_scale[0] != taper:
            t, s = self._gpu.param, self._segment_starts
            mid = (np.float32(0.5) * (t[s] + t[s + 1])).astype(np.float32)
            scale = (np.float32(1.0) - np.float32(taper) * mid).astype(np.float64)
            scale = np.clip(scale, 0.0, 1.0)
            scale.flags.writeable = False  # fixed per taper: the raster need not compare it
            self._taper_scale = (taper, scale)
        return self._taper_scale[1]

    def cpu_colors(self) -> NDArray[np.float32]:
        """``(V, 3)`` the colour of every vertex as the GL draws give it: the vertex colours, or
        the ramp texture sampled at t (LINEAR, clamped), as the shaders do."""
        if self.vertex_coloured:
            return self._gpu.colors
        return self._ramp_vertex_colors()

    def _ramp_vertex_colors(self) -> NDArray[np.float32]:
        if self._ramp_colors is None:
            self._ramp_colors = sample_linear(ramp_texture(self.ramp, RAMP_TEXELS), self._gpu.param)
        return self._ramp_colors

    @property
    def vertex_coloured(self) -> bool:
        """Whether the strands take the per-vertex colour buffer (vertex colours, or the shade)."""
        return self.use_vertex_colors or (self.hair_shading and self._shade_key is not None)

    def set_hair_shading(self, on: bool, look: HairLook | None = None) -> None:
        """Shade the strands as hair (Kajiya-Kay from the strand tangent, the light tied to the
        camera) over their colours: the vertex colours, or the ramp from root to tip."""
        look = self.hair_look if look is None else look
        if bool(on) != self.hair_shading or look != self.hair_look:
            self.hair_shading, self.hair_look = bool(on), look
            self._shade_key = None
            if not on and self._gpu is not None and self._base_colors is not None:
                self._gpu.write_colors(self._base_colors)

    def _shade(self, camera: Camera) -> None:
        """Write the shaded colours into the colour buffer when points, colours or view changed:
        after moves alone (same view, colours and look), only the strands they moved."""
        if not self.hair_shading or self._main is None:
            return
        right, up, forward = camera.basis()
        key = (self._version, id(self._gpu), tuple(right), tuple(up), self.hair_look)
        if key == self._shade_key:
            return
        base = self._base_colors if self.use_vertex_colors else self._ramp_vertex_colors()
        light, eye = light_and_eye(right, up, forward)
        gpu = self._gpu
        offsets = self.topology.offsets
        some = self._reshade is not None and self._shade_key is not None and self._shade_key[1:] == key[1:]
        if some and self._reshade.size:  # a gather and scatter beat shading all only for a few
            share = (offsets[self._reshade + 1] - offsets[self._reshade]).sum() / max(offsets[-1], 1)
            some = share <= RESHADE_SHARE
        if some:
            moved = self._reshade
            if moved.size:
                rows, sub = strand_rows(offsets, moved)
                gpu.colors[rows] = shade(self._main.points[rows], sub, base[rows], light, eye, self.hair_look)
                gpu.colors_written(vertex_runs(offsets, moved))
        else:
            shade(self._main.points, offsets, base, light, eye, self.hair_look, out=gpu.colors)
            gpu.colors_written()  # shaded in place: no (V, 3) array made and copied per frame
        self._shade_key = key
        self._reshade = np.zeros(0, np.int64)

    def _draw(self, method: str, points: PointSet, ghost: bool) -> None:
        if method == "quads":
            points.texture().use(location=1)
            self._vao(method, ghost).render(moderngl.TRIANGLES)
        else:
            points.vertex_buffer()  # up to date
            self._gpu.sync_color_buffer()
            self._vao(method, ghost).render(moderngl.LINES if method == "thin" else moderngl.LINE_STRIP)

    def _render_ghost(self, fbo: moderngl.Framebuffer, method: str) -> None:
        """The ghost strands: flat colour, blended over what is drawn, depth-tested, no depth write."""
        ctx, prog = self.ctx, self.programs[method]
        prog["u_use_flat_color"].value = True
        prog["u_flat_color"].value = self.ghost_rgba
        ctx.enable(moderngl.BLEND)
        # Alpha accumulates as "over" too, so a transparent background stays premultiplied.
        ctx.blend_func = (
            moderngl.SRC_ALPHA,
            moderngl.ONE_MINUS_SRC_ALPHA,
            moderngl.ONE,
            moderngl.ONE_MINUS_SRC_ALPHA,
        )
        fbo.depth_mask = False
        try:
            self._draw(method, self._ghost, ghost=True)
        finally:
            fbo.depth_mask = True
            ctx.disable(moderngl.BLEND)

    def _free_groom(self) -> None:
        self._free_ghost()
        for vao in self._vaos.values():
            vao.release()
        self._vaos.clear()
        for part in (self._main, self._gpu):
            if part is not None:
                part.release()
        self._main = self._gpu = None
        self.topology = None
        self.bounds = None
        self.use_vertex_colors = False
        self._segment_starts = self._ramp_colors = self._base_colors = self._base_store = None
        self._taper_scale = None
        self._shade_key = None

    def release(self) -> None:
        """Free every GL object this renderer made (call with its context current)."""
        self._free_groom()
        while self._kept:
            self._kept.pop().release()
        self.mesh.release()
        self.character.release()
        self.overlay.release()
        self.outline.release()
        if self.raster is not None:
            self.raster.release()
            self.raster = None
        self.ramp_texture.release()
        for prog in self.programs.values():
            prog.release()
