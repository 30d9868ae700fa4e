"""Stills of the current view: PNG from an offscreen render, SVG for 2-D grooms."""

from __future__ import annotations

import os
from pathlib import Path

import moderngl
import numpy as np

from app.render.camera import Camera
from app.render.offscreen import render_image, save_png
from app.render.strands import DEFAULT_BACKGROUND
from app.render.svg import save_svg
from app.ui.colouring import vertex_colors
from app.ui.scene import Scene
from hairtool.errors import FormatError

STILL_FORMATS = (".png", ".svg")


def export_still(
    path: str | os.PathLike[str],
    scene: Scene,
    camera: Camera,
    size: tuple[int, int],
    transparent: bool = False,
    ctx: moderngl.Context | None = None,
    points: np.ndarray | None = None,
    point_colors: np.ndarray | None = None,
) -> None:
    """Write what the viewport shows (without the brush circle) at ``size`` pixels.

    ``ctx``: the (current) context to draw in; None uses the headless one. ``points`` (and
    ``point_colors``): an animation frame shown instead of the scene's groom, same strands.
    """
    suffix = Path(path).suffix.lower()
    colors = point_colors if point_colors is not None else vertex_colors(scene)
    groom = scene.result if points is None else scene.result.with_points(points)
    if suffix == ".png":
        image = render_image(
            groom,
            size=size,
            camera=camera,
            ramp=scene.ramp,
            colors=colors,
            line_width=scene.line_width,
            transparent=transparent,
            mesh=scene.mesh,
            ctx=ctx,
            strand_raster="gl",  # a still is made once: GL's multisampled, antialiased strands
        )
        save_png(path, image)
    elif suffix == ".svg":
        if not scene.is_planar:
            raise FormatError(path, "SVG export is for 2-D (planar) grooms; export a PNG instead")
        save_svg(
            path,
            groom,
            camera,
            size,
            ramp=scene.ramp,
            colors=colors,
            line_width=scene.line_width,
            background=None if transparent else DEFAULT_BACKGROUND,
        )
    else:
        raise FormatError(
            path, f"stills are written as {' or '.join(STILL_FORMATS)}, not '{suffix or 'none'}'"
        )
