"""Headless rendering to RGBA images (EGL, no display and no Qt) and PNG export.

One standalone context (and one renderer in it) is made per process on first use; each image
is drawn into a multisampled framebuffer (4× where the context allows), resolved into a plain
one and read back.
"""

from __future__ import annotations

import os
import threading
import weakref
from dataclasses import dataclass
from typing import Any

import moderngl
import numpy as np
from numpy.typing import ArrayLike, NDArray

from app.render.camera import Camera
from app.render.drawn import Drawn
from app.render.gl_objects import alive
from app.render.strands import DEFAULT_BACKGROUND, STRAND_RASTERS, StrandRenderer, default_strand_raster
from hairtool.errors import FormatError, HairtoolError, ParameterError
from hairtool.groom import Groom
from hairtool.io.atomic import atomic_path

MSAA_SAMPLES = 4
MAX_SIZE = 16384

_lock = threading.Lock()
_shared: dict[str, Any] = {}
_parking: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()
_kept_mesh: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()  # a kept renderer's mesh


class RenderError(HairtoolError):
    """No OpenGL context could be made (no EGL / Mesa on this machine)."""


def shared_context() -> moderngl.Context:
    """The process's standalone EGL context, made on first use."""
    with _lock:
        ctx = _shared.get("ctx")
        if ctx is None:
            try:
                ctx = moderngl.create_standalone_context(backend="egl")
            except Exception as e:  # moderngl raises plain Exception when EGL is missing
                raise RenderError(f"cannot create a headless OpenGL context (EGL): {e}") from None
            _shared["ctx"] = ctx
        return ctx


def _shared_renderer(ctx: moderngl.Context) -> StrandRenderer:
    renderer = _shared.get("renderer")
    if renderer is None or renderer.ctx is not ctx:
        renderer = StrandRenderer(ctx)
        _shared["renderer"] = renderer
    return renderer


def _check_size(size: tuple[int, int]) -> tuple[int, int]:
    try:
        w, h = (int(v) for v in size)
    except (TypeError, ValueError):
        raise ParameterError("size", size, "(width, height) in pixels") from None
    if not (1 <= w <= MAX_SIZE and 1 <= h <= MAX_SIZE) or (w, h) != tuple(size):
        raise ParameterError("size", size, f"whole (width, height) in [1, {MAX_SIZE}] pixels")
    return w, h


def _parking_framebuffer(ctx: moderngl.Context) -> moderngl.Framebuffer:
    """A 1×1 framebuffer kept bound between offscreen draws.

    moderngl re-binds the last used framebuffer whenever it makes a new one; if that one was
    released, GL reports GL_INVALID_OPERATION. Parking on a live framebuffer before releasing
    the temporary ones keeps the context free of errors.
    """
    fbo = _parking.get(ctx)
    if fbo is None:
        fbo = ctx.framebuffer([ctx.renderbuffer((1, 1), 4)])
        _parking[ctx] = fbo
    return fbo


def read_rgba(
    ctx: moderngl.Context, renderer: StrandRenderer, camera: Camera, size: tuple[int, int]
) -> NDArray:
    """Draw with ``renderer`` into a fresh (multisampled) framebuffer; ``(H, W, 4)`` uint8, top row first."""
    w, h = size
    previous = ctx.fbo
    samples = min(MSAA_SAMPLES, ctx.max_samples)
    color = ctx.renderbuffer((w, h), 4, samples=samples)
    depth = ctx.depth_renderbuffer((w, h), samples=samples)
    target = ctx.framebuffer([color], depth)
    objects: list = [target, depth, color]
    try:
        renderer.render(target, camera, (w, h))
        if samples > 0:
            plain = ctx.renderbuffer((w, h), 4)
            resolved = ctx.framebuffer([plain])
            objects += [resolved, plain]
            ctx.copy_framebuffer(resolved, target)
            target = resolved
        data = target.read(viewport=(0, 0, w, h), components=4, dtype="f1")
    finally:
        if alive(previous) and all(previous is not obj for obj in objects):
            previous.use()  # e.g. the Qt widget's framebuffer
        else:
            _parking_framebuffer(ctx).use()
        for obj in objects:
            obj.release()
    return np.frombuffer(data, dtype=np.uint8).reshape(h, w, 4)[::-1].copy()


def unpremultiply(image: NDArray[np.uint8]) -> NDArray[np.uint8]:
    """Straight alpha from an image resolved over a (0, 0, 0, 0) clear (MSAA averages premultiplied)."""
    a = image[..., 3:4].astype(np.float64)
    rgb = image[..., :3].astype(np.float64)
    with np.errstate(invalid="ignore", divide="ignore"):
        straight = np.where(a > 0, np.clip(np.round(rgb * 255.0 / a), 0, 255), 0)
    return np.concatenate([straight, a], axis=-1).astype(np.uint8)


def render_image(
    groom: Groom,
    *,
    size: tuple[int, int] = (800, 800),
    camera: Camera | None = None,
    ramp: str = "root-tip",
    colors: ArrayLike | None = None,
    line_width: float = 2.0,
    background: tuple[float, float, float, float] = DEFAULT_BACKGROUND,
    transparent: bool = False,
    mesh: Any | None = None,
    ctx: moderngl.Context | None = None,
    strand_raster: str | None = None,
) -> NDArray[np.uint8]:
    """Draw a groom headless; ``(H, W, 4)`` uint8 RGBA, top row first.

    ``camera`` None frames groom and mesh (orthographic for planar grooms). ``colors``: ``(V, 3)``
    per-vertex RGB, else the groom's own colours, else ``ramp`` along t. The other arguments
    are :func:`render_drawn`'s.
    """
    if not np.isfinite(line_width) or not 0 < line_width <= 256:
        raise ParameterError("line_width", line_width, "a width in (0, 256] pixels")
    own = None if colors is None else np.asarray(colors)
    drawn = Drawn.of_groom(groom, own, ramp=ramp, line_width=line_width)
    if camera is None:
        camera = _framing(drawn, mesh, size, bool(groom.is_planar))
    return render_drawn(
        drawn,
        size=size,
        camera=camera,
        background=background,
        transparent=transparent,
        mesh=mesh,
        ctx=ctx,
        strand_raster=strand_raster,
    )


def _framing(drawn: Drawn, mesh: Any | None, size: tuple[int, int], planar: bool) -> Camera:
    w, h = _check_size(size)
    lo, hi = drawn.groom().bounds
    if mesh is not None and len(mesh.vertices):
        v = np.asarray(mesh.vertices, np.float32)
        lo, hi = np.minimum(lo, v.min(axis=0)), np.maximum(hi, v.max(axis=0))
    return Camera.for_bounds(lo, hi, ortho=planar, aspect=w / h)


@dataclass(frozen=True)
class Overlays:
    """The working overlays a still or video may include: the brush circle (centre and radius in
    pixels of the image) and the symmetry plane's outline (``(4, 2)`` pixels); None: not drawn."""

    circle: tuple[tuple[float, float], float] | None = None
    outline: NDArray | None = None


def render_drawn(
    drawn: Drawn,
    *,
    size: tuple[int, int],
    camera: Camera,
    background: tuple[float, float, float, float] = DEFAULT_BACKGROUND,
    transparent: bool = False,
    mesh: Any | None = None,
    ctx: moderngl.Context | None = None,
    strand_raster: str | None = None,
    overlays: Overlays | None = None,
    renderer: StrandRenderer | None = None,
) -> NDArray[np.uint8]:
    """Draw what the studio draws (:class:`~app.render.drawn.Drawn`) headless; ``(H, W, 4)``
    uint8 RGBA, top row first, no overlay unless ``overlays`` gives some.

    ``transparent`` gives alpha 0 wherever nothing is drawn (straight, not premultiplied,
    alpha). ``ctx``: a current context to draw in (None: the process's headless one);
    ``renderer``: a :class:`StrandRenderer` of ``ctx`` kept by the caller across images (a
    video's frames: its buffers and programs are made once, and only the points change), else
    one is made and released for this image.
    ``strand_raster``: ``"gl"``, ``"cpu"`` or ``"auto"`` (see :mod:`app.render.strands`; None:
    the environment's default); strands rasterized on the CPU are not multisampled.
    """
    w, h = _check_size(size)
    if not np.isfinite(drawn.line_width) or not 0 < drawn.line_width <= 256:
        raise ParameterError("line_width", drawn.line_width, "a width in (0, 256] pixels")
    bg = tuple(float(c) for c in background)
    if len(bg) == 3:
        bg = (*bg, 1.0)
    if len(bg) != 4 or not all(0.0 <= c <= 1.0 for c in bg):
        raise ParameterError("background", background, "(r, g, b[, a]) in [0, 1]")
    if strand_raster is None:
        strand_raster = default_strand_raster()
    if strand_raster not in STRAND_RASTERS:
        raise ParameterError("strand_raster", strand_raster, " or ".join(STRAND_RASTERS))
    drawn.colors  # noqa: B018 - made (and checked) before any GL object is
    args = (drawn, camera, (w, h), bg, transparent, mesh, strand_raster, overlays or Overlays())
    if ctx is not None:
        if renderer is not None:
            if renderer.ctx is not ctx:
                raise ParameterError("renderer", "a renderer of another context", "one of ctx")
            return _render_in(ctx, renderer, "kept", *args)
        return _render_in(ctx, StrandRenderer(ctx), "own", *args)
    ctx = shared_context()
    with ctx:  # current for this draw only: Qt may own the current context in the studio
        return _render_in(ctx, _shared_renderer(ctx), "shared", *args)


def _render_in(ctx, renderer, whose, drawn, camera, size, bg, transparent, mesh, raster, overlays):
    """``whose``: "own" (made for this image: released after it), "kept" (the caller's, left as
    it is for its next image) or "shared" (the process's: left without mesh and overlays)."""
    try:
        renderer.strand_raster = raster
        renderer.show(drawn)
        if whose != "kept" or _kept_mesh.get(renderer, _kept_mesh) is not mesh:
            renderer.set_mesh(mesh)  # (a kept renderer's mesh stays uploaded from image to image)
            if whose == "kept":
                _kept_mesh[renderer] = mesh
        centre, radius = overlays.circle or (None, 0.0)
        renderer.set_overlay_circle(centre, radius, size)
        renderer.set_overlay_outline(overlays.outline, size)
        renderer.background = (0.0, 0.0, 0.0, 0.0) if transparent else bg
        image = read_rgba(ctx, renderer, camera, size)
        if whose == "shared":
            renderer.set_mesh(None)
            renderer.set_overlay_circle(None)
            renderer.set_overlay_outline(None)
    finally:
        if whose == "own":
            renderer.release()
    return unpremultiply(image) if transparent else image


def save_png(path: str | os.PathLike[str], image: ArrayLike) -> None:
    """Write an ``(H, W, 3|4)`` uint8 image as PNG, atomically."""
    import imageio.v3 as iio

    img = np.asarray(image)
    if img.dtype != np.uint8 or img.ndim != 3 or img.shape[2] not in (3, 4):
        raise ParameterError("image", f"{img.dtype} {img.shape}", "(H, W, 3 or 4) uint8")
    try:
        with atomic_path(path) as tmp:
            iio.imwrite(tmp, img, extension=".png")
    except OSError as e:
        raise FormatError(path, f"cannot write: {e}") from None
