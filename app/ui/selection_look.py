"""How the selection shows in the viewport: unselected strands dimmed toward a dark grey while
some strand is selected and some not (as Blender draws unselected curves darker), hidden strands
left out of what is drawn. A child of render hair follows its nearest guide, as the mask's tint
does. Both are working overlays: a still or video without the overlays shows every strand as it is.
"""

from __future__ import annotations

import numpy as np

from app.render.ramps import ramp_texture, sample_linear
from app.render.strands import RAMP_TEXELS
from app.ui.scene import Scene
from hairtool.groom import Topology

DIM_RGB = np.array([0.16, 0.16, 0.18], np.float32)  # unselected strands: toward this grey …
DIM_KEEP = 0.35  # … keeping this share of their own colour


def drawn_flags(scene: Scene, flags: np.ndarray) -> np.ndarray:
    """``(drawn strands,)`` a per-strand flag of the groom for each drawn strand (a child takes
    its nearest guide's; the guides drawn after the children, their own)."""
    if not scene.has_children:
        return flags
    guides = flags if scene.drawn_guides else np.zeros(0, bool)
    return np.concatenate([flags[scene.drawn_binding().guide_ids[:, 0]], guides])


def dimmed(scene: Scene, colors: np.ndarray | None) -> np.ndarray | None:
    """``colors`` (None: the ramp) with the unselected shown strands dimmed; unchanged while the
    selection is everything shown, or nothing."""
    sel, hid = scene.selected, scene.hidden
    if sel.size != scene.result.strand_count:
        return colors
    shown = ~hid
    if not (sel & shown).any() or not (~sel & shown).any():
        return colors
    top = scene.drawn_topology
    if colors is None:
        colors = sample_linear(ramp_texture(scene.ramp, RAMP_TEXELS), top.vertex_param)
    off = np.repeat(~drawn_flags(scene, sel), top.counts)
    colors = np.array(colors, np.float32)
    colors[off] = DIM_KEEP * colors[off] + (1.0 - DIM_KEEP) * DIM_RGB
    return colors


def shown_part(scene: Scene) -> tuple[np.ndarray, Topology] | None:
    """The drawn vertices of the strands not hidden, and their topology (None: nothing hidden,
    or everything, which only a replayed log can do: the studio refuses it, and a view of no
    strand cannot be drawn). Made once per hiding and drawn density, so a drag only gathers."""
    hid = scene.hidden
    if hid.size != scene.result.strand_count or not hid.any() or hid.all():
        return None
    top = scene.drawn_topology
    cached = scene.shown_cache  # (hiding, the drawn topology it was made for, the part)
    if cached is not None and cached[0] == scene.hidden_version and cached[1] is top:
        return cached[2]
    keep = ~drawn_flags(scene, hid)
    ids = np.flatnonzero(np.repeat(keep, top.counts))
    part = (ids, Topology(top.counts[keep]))
    scene.shown_cache = (scene.hidden_version, top, part)
    return part
