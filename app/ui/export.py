"""Stills of the current view: PNG from an offscreen render, SVG for 2-D grooms.

Both draw the view's :class:`~app.render.drawn.Drawn` (the groom or its render hair at full
density, with the colours that go with those very points), never the brush circle, the
symmetry plane or the mask's tint unless ``overlays`` asks for them.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

import moderngl

from app.render.camera import Camera
from app.render.drawn import Drawn
from app.render.offscreen import Overlays, render_drawn, save_png
from app.render.strands import DEFAULT_BACKGROUND
from app.render.svg import save_svg
from hairtool.errors import FormatError

STILL_FORMATS = (".png", ".svg")


def export_still(
    path: str | os.PathLike[str],
    drawn: Drawn,
    camera: Camera,
    size: tuple[int, int],
    *,
    transparent: bool = False,
    mesh: Any | None = None,
    planar: bool = False,
    ctx: moderngl.Context | None = None,
    overlays: Overlays | None = None,
) -> None:
    """Write ``drawn`` as ``camera`` sees it at ``size`` pixels (PNG; SVG for ``planar`` grooms).

    ``ctx``: the (current) context to draw in; None uses the headless one. ``overlays``: the
    brush circle and symmetry plane to draw over it (PNG only; None: none).
    """
    suffix = Path(path).suffix.lower()
    if suffix == ".png":
        image = render_drawn(
            drawn,
            size=size,
            camera=camera,
            transparent=transparent,
            mesh=mesh,
            ctx=ctx,
            strand_raster="gl",  # a still is made once: GL's multisampled, antialiased strands
            overlays=overlays,
        )
        save_png(path, image)
    elif suffix == ".svg":
        if not planar:
            raise FormatError(path, "SVG export is for 2-D (planar) grooms; export a PNG instead")
        save_svg(
            path,
            drawn.groom(),
            camera,
            size,
            ramp=drawn.ramp,
            colors=drawn.colors,
            line_width=drawn.line_width,
            background=None if transparent else DEFAULT_BACKGROUND,
        )
    else:
        raise FormatError(
            path, f"stills are written as {' or '.join(STILL_FORMATS)}, not '{suffix or 'none'}'"
        )
