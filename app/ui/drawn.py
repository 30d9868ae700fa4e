"""The scene's :class:`~app.render.drawn.Drawn`: the one value the viewport, stills, videos and
SVG read for "what is drawn" (the groom, or its drawn children then the guides), at the groom's
current shape or at an animation frame of its guides."""

from __future__ import annotations

import numpy as np

from app.render.drawn import Drawn
from app.render.hair_shading import HAIR_TAPER
from app.ui.colouring import vertex_colors
from app.ui.scene import Scene


def drawn(
    scene: Scene,
    frame: np.ndarray | None = None,
    frame_colors: np.ndarray | None = None,
    *,
    mask: bool = True,
) -> Drawn:
    """What the viewport draws of ``scene``: ``frame`` (``(V, 3)`` points of the groom's strands,
    an animation frame; None: the groom as edited) with render hair following it, coloured by the
    scene's colour mode (``frame_colors``: an animation's own per-vertex colours, used where no
    render hair is drawn over the frame); ``mask``: the mask brush's tint (a working overlay)."""
    s = scene
    if frame is not None and len(frame) != s.result.vertex_count:
        frame = None  # another groom's frame: the scene's own strands are drawn
    children = s.has_children
    if frame is None:
        points = s.drawn_points
    else:
        points = s.drawn_for(frame) if children else np.asarray(frame, np.float32)
    if frame is not None and frame_colors is not None and not children:
        own = frame_colors

        def make_colors():
            return own
    else:

        def make_colors():
            return vertex_colors(s, mask=mask)

    hair = s.colour_mode == "hair"
    return Drawn(
        points,
        s.drawn_topology,
        guides=s.drawn_guides if children else 0,
        ramp=s.ramp,
        line_width=s.line_width,
        taper=HAIR_TAPER if hair else 0.0,
        shaded=hair,
        make_colors=make_colors,
    )
