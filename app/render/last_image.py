"""The last scene image a view drew, kept without its overlays, so that a frame in which only
the brush circle, the sizing ring or the selection box moved costs a copy and the overlays
instead of drawing every strand again (input at its own rate, whatever the groom costs)."""

from __future__ import annotations

import moderngl


class LastImage:
    """A colour copy of a framebuffer, valid for the ``key`` (camera and size) it was kept with.

    Only single-sample framebuffers are kept: GL cannot copy into a multisampled one, where the
    view simply draws its scene again."""

    def __init__(self, ctx: moderngl.Context) -> None:
        self.ctx = ctx
        self._fbo: moderngl.Framebuffer | None = None
        self._texture: moderngl.Texture | None = None
        self.key: tuple | None = None

    def holds(self, key: tuple) -> bool:
        """Whether the kept image is the one ``key`` would draw."""
        return self._fbo is not None and self.key == key

    def keep(self, fbo: moderngl.Framebuffer, size: tuple[int, int], samples: int, key: tuple) -> None:
        """Copy ``fbo``'s colour (``size`` pixels) as the image of ``key``; a multisampled
        ``fbo`` (``samples`` > 0) forgets the last image instead."""
        if samples > 0:
            self.forget()
            return
        size = (int(size[0]), int(size[1]))
        if self._texture is None or self._texture.size != size:
            self.release()
            self._texture = self.ctx.texture(size, 4)
            self._fbo = self.ctx.framebuffer(color_attachments=[self._texture])
        self.ctx.copy_framebuffer(self._fbo, fbo)
        self.key = key

    def put(self, fbo: moderngl.Framebuffer) -> None:
        """The kept image into ``fbo`` (of the kept size)."""
        self.ctx.copy_framebuffer(fbo, self._fbo)

    def forget(self) -> None:
        self.key = None

    def release(self) -> None:
        if self._fbo is not None:
            self._fbo.release()
            self._texture.release()
        self._fbo = self._texture = None
        self.key = None
