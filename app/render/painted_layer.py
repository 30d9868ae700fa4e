"""An image painted on the CPU drawn over the frame: what widgets paint with QPainter over the
view (a capture's joint handles). The viewport is a native GL window, which covers any widget
placed over it, so their painting comes to the frame as an image (program
``shaders/painted_over.glsl``)."""

from __future__ import annotations

import moderngl
import numpy as np

from app.render.shaders import load_program
from hairtool.errors import ParameterError

IMAGE_UNIT = 5  # clear of the strand programs' 0–2 and the raster layer's 3–4


class PaintedLayer:
    """Draws ``(H, W, 4)`` uint8 images, premultiplied RGBA with row 0 at the top, over a
    framebuffer of their size; the texture is kept and remade only when the size changes."""

    def __init__(self, ctx: moderngl.Context) -> None:
        self.ctx = ctx
        self.program = load_program(ctx, "painted_over")
        self.program["u_image"].value = IMAGE_UNIT
        self.vao = ctx.vertex_array(self.program, [])
        self._texture: moderngl.Texture | None = None

    def draw(self, fbo: moderngl.Framebuffer, rgba: np.ndarray) -> None:
        rgba = np.ascontiguousarray(rgba)
        if rgba.dtype != np.uint8 or rgba.ndim != 3 or rgba.shape[2] != 4:
            raise ParameterError("rgba", rgba.shape, "an (H, W, 4) uint8 image")
        size = (rgba.shape[1], rgba.shape[0])
        if self._texture is None or self._texture.size != size:
            if self._texture is not None:
                self._texture.release()
            self._texture = self.ctx.texture(size, 4)
        self._texture.write(rgba)
        fbo.use()
        self.ctx.viewport = (0, 0, *size)
        self._texture.use(IMAGE_UNIT)
        self.ctx.disable(moderngl.DEPTH_TEST)
        self.ctx.enable(moderngl.BLEND)
        self.ctx.blend_func = moderngl.ONE, moderngl.ONE_MINUS_SRC_ALPHA
        self.vao.render(moderngl.TRIANGLES, vertices=3)
        self.ctx.disable(moderngl.BLEND)

    def release(self) -> None:
        if self._texture is not None:
            self._texture.release()
            self._texture = None
        self.vao.release()
        self.program.release()
