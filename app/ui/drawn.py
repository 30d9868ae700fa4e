"""The scene's :class:`~app.render.drawn.Drawn`: the one value the viewport, stills, videos and
SVG read for "what is drawn" (the groom, or its drawn children then the guides), at the groom's
current shape or at an animation frame of its guides."""

from __future__ import annotations

import numpy as np

from app.render.drawn import Drawn
from app.render.hair_shading import HAIR_TAPER
from app.ui.colouring import vertex_colors
from app.ui.scene import Scene
from app.ui.selection_look import dimmed, shown_part


def drawn(
    scene: Scene,
    frame: np.ndarray | None = None,
    frame_colors: np.ndarray | None = None,
    *,
    mask: bool = True,
    kept: bool = False,
    children: np.ndarray | None = None,
) -> Drawn:
    """What the viewport draws of ``scene``: ``frame`` (``(V, 3)`` points of the groom's strands,
    an animation frame; None: the groom as edited) with render hair following it, coloured by the
    scene's colour mode (``frame_colors``: an animation's own per-vertex colours, used where no
    render hair is drawn over the frame); ``mask``: the working overlays, the mask brush's tint
    and the selection (unselected strands dimmed, hidden ones left out:
    :mod:`app.ui.selection_look`); ``kept``: a frame written out (an export), whose children
    are clumped (with Clump children on) even while the animation plays; ``children``: the drawn
    points already built for ``frame`` (:mod:`app.ui.frame_children`), used while they fit the
    drawn strands (else they are built here)."""
    s = scene
    if frame is not None and len(frame) != s.result.vertex_count:
        frame = None  # another groom's frame: the scene's own strands are drawn
    has_children = s.has_children
    if frame is None:
        points = s.drawn_points
    elif not has_children:
        points = np.asarray(frame, np.float32)
    elif children is not None and not kept and len(children) == s.drawn_topology.vertex_count:
        points = children
    else:
        points = s.drawn_for(frame, kept=kept)
    if frame is not None and frame_colors is not None and not has_children:
        own = frame_colors

        def make_colors():
            return own
    else:

        def make_colors():
            return vertex_colors(s, mask=mask)

    topology = s.drawn_topology
    if mask:
        shown = shown_part(s)
        all_colors = make_colors

        def make_colors():
            return dimmed(s, all_colors())

        if shown is not None:
            ids, topology = shown
            points = points[ids]
            dim = make_colors

            def make_colors():
                c = dim()
                return None if c is None else c[ids]

    hair = s.colour_mode == "hair"
    return Drawn(
        points,
        topology,
        guides=_shown_guides(s, topology) if has_children else 0,
        ramp=s.ramp,
        line_width=s.line_width,
        taper=HAIR_TAPER if hair else 0.0,
        shaded=hair,
        make_colors=make_colors,
    )


def _shown_guides(scene: Scene, topology) -> int:
    """The guides among the drawn strands (the last ones), hidden guides left out."""
    if not scene.drawn_guides or topology is scene.drawn_topology:
        return scene.drawn_guides
    return int((~scene.hidden).sum())
