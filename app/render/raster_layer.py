"""Strands rasterized on the CPU (:mod:`app.render.soft_raster`) put into the GL frame.

Two ways, by the target framebuffer:

- single-sampled (the viewport): rasterize the strands on the CPU over the background colour
  (GL need not even clear), or, when GL drew something first (a head mesh, a ghost), over what
  it drew, read back with its depth; write the colour into a texture and blit it into ``fbo``.
  On llvmpipe a full-screen textured draw costs several milliseconds, about as much as the
  strands themselves; reading back and blitting are copies.
- multisampled (exports; GL can neither read nor blit into it pixel for pixel): strands into
  cleared images, uploaded as colour and depth textures and drawn by one full-screen triangle
  (``shaders/strands_raster.glsl``) that skips empty pixels and writes ``gl_FragDepth``.

Blitted, the strands leave the framebuffer's depth as GL left it: nothing after them (the brush
circle) is depth-tested. Textures and images are kept between frames and remade only on resize.

What GL drew under single-sampled strands (the head mesh) is kept as the *backdrop* of a key
the caller gives (the camera, the size, the mesh and its colour): a frame of the same key
copies it instead of reading the framebuffer back, and its caller need not draw it again
(:meth:`RasterLayer.holds_backdrop`). Scrubbing an animation changes only the strands, and
the two read-backs waited for GL to clear and draw the head each frame.

A multisampled draw can also be split across threads (an export's frames, whose raster is the
frame's CPU cost: :mod:`app.ui.animation_export`): with :attr:`RasterLayer.defer` it keeps what
it would raster as a :class:`RasterJob` and draws no strands; any thread rasters the job
(:meth:`RasterJob.draw`, into a :class:`~app.render.soft_raster.StrandRaster` of its own); a
second draw of the same strands with :attr:`RasterLayer.given` set to those images composites
them instead of rastering again. The images are those the layer's own raster would make.
"""

from __future__ import annotations

from dataclasses import dataclass

import moderngl
import numpy as np
from numpy.typing import ArrayLike

from app.render.shaders import load_program
from app.render.soft_raster import StrandRaster

COLOR_UNIT, DEPTH_UNIT = 3, 4  # texture units clear of the strand programs' 0–2


def _owned(a: ArrayLike) -> np.ndarray:
    """``a`` as it is now: itself where it is a read-only array of its own (the renderer's
    segment starts and widths, fixed per topology), else a copy."""
    a = np.asarray(a)
    return a if not a.flags.writeable and a.base is None else a.copy()


@dataclass(frozen=True, eq=False)
class RasterJob:
    """What one multisampled draw rasters on the CPU: its inputs, kept as they were."""

    points: np.ndarray
    starts: np.ndarray
    colors: np.ndarray
    mvp: np.ndarray
    size: tuple[int, int]
    width: float
    scale: np.ndarray | None

    @classmethod
    def of(cls, points, starts, colors, mvp, size, width, scale) -> RasterJob:
        """The job of a draw of these inputs (the points, colours and camera copied)."""
        points, colors, mvp = (np.array(a, copy=True) for a in (points, colors, mvp))
        scale = None if scale is None else _owned(scale)
        return cls(points, _owned(starts), colors, mvp, tuple(size), float(width), scale)

    def draw(self, raster: StrandRaster) -> tuple[np.ndarray, np.ndarray]:
        """The colour and depth images (copies) ``raster`` makes of these strands."""
        rgba, depth = raster.draw(
            self.points, self.starts, self.colors, self.mvp, self.size, self.width, scale=self.scale
        )
        return rgba.copy(), depth.copy()

    def same(self, points, starts, colors, mvp, size, width, scale) -> bool:
        """Whether a draw of these inputs is this job."""
        arrays = ((self.points, points), (self.starts, starts), (self.colors, colors), (self.mvp, mvp))
        same_scale = (scale is None) == (self.scale is None) and (
            scale is None or np.array_equal(self.scale, scale)
        )
        return (
            tuple(size) == self.size
            and float(width) == self.width
            and same_scale
            and all(a is b or (np.shape(a) == np.shape(b) and np.array_equal(a, b)) for a, b in arrays)
        )


class RasterLayer:
    """The CPU strands of one renderer: images, textures and the copy program."""

    def __init__(self, ctx: moderngl.Context) -> None:
        self.ctx = ctx
        self.raster = StrandRaster()
        self.program = load_program(ctx, "strands_raster")
        self.program["u_color"].value = COLOR_UNIT
        self.program["u_depth"].value = DEPTH_UNIT
        self.vao = ctx.vertex_array(self.program, [])
        self.size: tuple[int, int] | None = None
        self.color_texture: moderngl.Texture | None = None
        self.depth_texture: moderngl.Texture | None = None
        self._source: moderngl.Framebuffer | None = None  # the colour texture, to blit from
        self._texture_is_image = False  # the colour texture holds the raster's colour image
        self.defer = False  # multisampled: keep the strands as :attr:`job`, draw none
        self.job: RasterJob | None = None  # the last deferred draw's
        self.given: tuple[RasterJob, np.ndarray, np.ndarray] | None = None  # a job's images
        self._backdrop: tuple[tuple, np.ndarray, np.ndarray] | None = None  # (key, colour, depth)

    def holds_backdrop(self, key: tuple) -> bool:
        """Whether the images GL drew under the strands for ``key`` are kept (see the module doc):
        a single-sampled :meth:`render` with that ``backdrop`` then needs none drawn in ``fbo``."""
        return self._backdrop is not None and self._backdrop[0] == key

    def _resize(self, size: tuple[int, int]) -> None:
        if size == self.size:
            return
        self._free_textures()
        self.color_texture = self.ctx.texture(size, 4, dtype="f1")
        self.depth_texture = self.ctx.texture(size, 1, dtype="f4")
        for tex in (self.color_texture, self.depth_texture):
            tex.filter = (moderngl.NEAREST, moderngl.NEAREST)
            tex.repeat_x = tex.repeat_y = False
        self._source = self.ctx.framebuffer([self.color_texture])
        self.size = size
        self._texture_is_image = False

    def render(
        self,
        fbo: moderngl.Framebuffer,
        samples: int,
        points: ArrayLike,
        starts: ArrayLike,
        colors: ArrayLike,
        mvp: ArrayLike,
        size: tuple[int, int],
        width: float,
        *,
        background: tuple[float, float, float, float] | None = None,
        read_depth: bool = False,
        scale: ArrayLike | None = None,
        backdrop: tuple | None = None,
        changed: ArrayLike | None = None,
    ) -> None:
        """Draw the strands into ``fbo`` (bound, viewport ``size``, with ``samples`` per pixel).

        Single-sampled, ``background`` (RGBA in [0, 1]) fills every pixel no strand covers, for
        a frame GL drew nothing into; without it what GL drew is read back, its depth too with
        ``read_depth`` (the head mesh). Multisampled, strands go over what is there.
        ``scale``: per segment, its width factor (a tapering width; None: none).
        ``backdrop``: single-sampled without ``background``, the key of what GL drew under the
        strands (None: no key); the images of a key read back once are kept, and a later frame
        of that key starts from them instead of reading ``fbo`` (which it then need not draw).
        ``changed``: the only vertex ranges whose points or colours may differ from the last
        call's (:meth:`StrandRaster.draw`; None: any).
        """
        self._resize(size)
        if samples > 0:
            self._composite(points, starts, colors, mvp, size, width, scale)
            return
        if background is not None:
            clear = tuple(int(np.floor(c * 255.0 + 0.5)) for c in background)  # as GL stores it
            rgba, _ = self.raster.draw(
                points, starts, colors, mvp, size, width, clear=clear, scale=scale, changed=changed
            )
            self._upload(rgba, self.raster.changed)
        else:
            rgba, depth = self.raster.images(size)
            if backdrop is not None and self.holds_backdrop(backdrop):
                np.copyto(rgba, self._backdrop[1])
                np.copyto(depth, self._backdrop[2])
            else:
                viewport = (0, 0, *size)
                if read_depth:  # first: moderngl leaves the read buffer at GL_NONE after a depth read
                    fbo.read_into(depth, viewport=viewport, attachment=-1, dtype="f4")
                else:
                    depth.fill(1.0)
                fbo.read_into(rgba, viewport=viewport, components=4)
                self._backdrop = None if backdrop is None else (backdrop, rgba.copy(), depth.copy())
            self.raster.draw(points, starts, colors, mvp, size, width, clear=None, scale=scale)
            self._upload(rgba, self.raster.changed)
        self.ctx.copy_framebuffer(fbo, self._source)
        fbo.use()

    def _upload(self, rgba: np.ndarray, changed: tuple[int, int, int, int] | None) -> None:
        """The colour image into the texture: only the rows and columns ``changed`` since the
        last upload (None: nothing) when the texture holds the last image, else all of it."""
        if not self._texture_is_image:
            self.color_texture.write(rgba)
        elif changed is not None:
            r0, r1, c0, c1 = changed
            self.color_texture.write(
                np.ascontiguousarray(rgba[r0:r1, c0:c1]), viewport=(c0, r0, c1 - c0, r1 - r0)
            )
        self._texture_is_image = True

    def _composite(self, points, starts, colors, mvp, size, width, scale) -> None:
        self._texture_is_image = False
        if self.defer:
            self.job = RasterJob.of(points, starts, colors, mvp, size, width, scale)
            return
        given = self.given
        if given is not None and given[0].same(points, starts, colors, mvp, size, width, scale):
            rgba, depth = given[1], given[2]
        else:
            rgba, depth = self.raster.draw(points, starts, colors, mvp, size, width, scale=scale)
        self.color_texture.write(rgba)
        self.depth_texture.write(depth)
        self.color_texture.use(location=COLOR_UNIT)
        self.depth_texture.use(location=DEPTH_UNIT)
        self.vao.render(moderngl.TRIANGLES, vertices=3)

    def _free_textures(self) -> None:
        for obj in (self._source, self.color_texture, self.depth_texture):
            if obj is not None:
                obj.release()
        self._source = self.color_texture = self.depth_texture = None
        self.size = None

    def release(self) -> None:
        self._free_textures()
        self.vao.release()
        self.program.release()
