"""What each frame of a video of render hair draws, made in the export's worker thread.

A frame's children (interpolated from its guides and, with Clump children on, clumped: about
2 s for Sintel's 30,000 on a loaded 2-core host) are the export's real cost, and the GUI thread
must not pay it. Everything that belongs to the scene (the drawn share of the children, Clump
children, the guides shown, the selection's shown strands, the colours and the look) is read
once, on the GUI thread, when the export starts (:func:`render_hair_frames`); the function it
returns reads nothing of the scene, so the worker may call it while the artist goes on working.
"""

from __future__ import annotations

import copy
import dataclasses
from collections.abc import Callable

from app.render.drawn import Drawn
from app.ui.drawn import drawn
from app.ui.frame_children import FrameAsk, frame_points
from app.ui.scene import Scene
from app.ui.selection_look import shown_part
from hairtool.groom import Animation
from hairtool.guides.render import RenderHair


def render_hair_frames(scene: Scene, animation: Animation, *, mask: bool = False) -> Callable[[int], Drawn]:
    """``frame(f)`` → the :class:`Drawn` of ``animation``'s frame f (of the scene's guides) as
    the view draws an exported frame: the children drawn now, clumped as the groom's are (even
    while the animation plays), the guides after them when shown; ``mask``: the selection's
    look and the mask's tint. Call this on the GUI thread; the result in any one thread."""
    s = scene
    look = drawn(s, mask=mask)  # the topology, guides, colours and look of the drawn strands
    binding = s.drawn_binding()
    clump = s.children_clump() if s.children_clump_ready and not s.dragging else None
    with_guides = bool(s.drawn_guides)
    shown = shown_part(s) if mask else None
    ids = None if shown is None else shown[0]
    # the view's colours hang on the strands, not the pose; the distances from rest are the
    # edit's, not the frame's
    colors = None if s.colour_mode == "displacement" else look.colors
    clumper = None
    if clump is not None:
        # a copy of the view's own (its neighbours and last clumps already made, so the first
        # frame costs what the view's next one would), which the GUI thread goes on using
        clumper = copy.deepcopy(
            s.cached(("frames clumped", clump), lambda: RenderHair(binding, clump, follow_roots=True))
        )
    topology = s.result.topology

    def frame(f: int) -> Drawn:
        ask = FrameAsk(f, animation.frames[f], topology, binding, clump, with_guides)
        points = frame_points(ask, clumper)
        if ids is not None:
            points = points[ids]
        return dataclasses.replace(look, points=points, make_colors=lambda: colors)

    return frame
