"""Per-vertex colours for the "Colour by" modes, of the strands the viewport draws: the groom,
or its interpolated children followed by the guides (drawn in one colour of their own). Strands
the mask brush locked are drawn darkened toward a slate blue in every mode, so the artist sees
the mask (a child by its nearest guide); strands the clump brush loosened are drawn toward a
plum of their own, the more the less they clump, so the painted strength shows in every mode."""

from __future__ import annotations

import numpy as np

from app.render.ramps import (
    categorical_colors,
    per_strand_random_colors,
    ramp_texture,
    sample_linear,
    strand_to_vertex_colors,
)
from app.render.strands import RAMP_TEXELS
from app.ui.legend import magnitude_colors
from app.ui.scene import Scene

STRAND_COLOUR_SEED = 7  # fixed, so a groom keeps its per-strand colours between runs
GUIDE_RGB = (1.0, 0.62, 0.12)  # guides over render hair: one warm orange whatever the mode
MASK_RGB = np.array([0.24, 0.28, 0.5], np.float32)  # masked strands: toward this slate blue …
MASK_KEEP = 0.3  # … keeping this share of their own colour
CLUMP_RGB = np.array([0.72, 0.3, 0.62], np.float32)  # strands that clump less: toward this plum …
CLUMP_TINT = 0.6  # … by this share where they do not clump at all


def vertex_colors(scene: Scene, mask: bool = True) -> np.ndarray | None:
    """``(V, 3)`` float32 colours of the drawn strands, or None where the renderer's ramp over t
    does the colouring (shaded hair too: the renderer lights the ramp or these colours);
    ``mask`` False leaves out the mask's tint (a still or video without the working overlays)."""
    colors = _mode_colors(scene)
    locked, clump = scene.locked, scene.clump_strength
    n = scene.result.strand_count
    loose = clump.size == n and bool((clump < 1.0).any())
    if not mask or locked.size != n or not (locked.any() or loose):
        return colors
    top = scene.drawn_topology
    if colors is None:
        colors = sample_linear(ramp_texture(scene.ramp, RAMP_TEXELS), top.vertex_param)
    colors = np.array(colors, np.float32)
    if loose:
        share = np.repeat(_drawn(scene, CLUMP_TINT * (1.0 - clump), 0.0), top.counts)
        share = share[:, None].astype(np.float32)
        colors = (1.0 - share) * colors + share * CLUMP_RGB
    masked = np.repeat(_drawn(scene, locked, False), top.counts)
    colors[masked] = MASK_KEEP * colors[masked] + (1.0 - MASK_KEEP) * MASK_RGB
    return colors


def _drawn(scene: Scene, per_strand: np.ndarray, guide_fill) -> np.ndarray:
    """A per-strand value for the drawn strands: a child takes its nearest guide's, and the
    guides drawn over them their own (``guide_fill`` where none are drawn)."""
    if not scene.has_children:
        return per_strand
    guides = per_strand if scene.drawn_guides else np.full(0, guide_fill, per_strand.dtype)
    return np.concatenate([per_strand[scene.drawn_binding().guide_ids[:, 0]], guides])


def _mode_colors(scene: Scene) -> np.ndarray | None:
    mode = scene.colour_mode
    top = scene.drawn_topology
    guides = scene.drawn_guides if scene.has_children else 0
    if mode in ("root-to-tip", "hair"):
        if not guides:
            return None
        colors = scene.cached(("ramp", scene.ramp), lambda: _guides_over_ramp(scene, top, guides))
        return colors
    elif mode == "strand":
        colors = strand_to_vertex_colors(per_strand_random_colors(top.strand_count, STRAND_COLOUR_SEED), top)
    elif mode == "clump":
        if scene.pipeline is None:  # no clumps before the engine starts: all strands grey
            ids = np.full(top.strand_count, -1)
        else:
            ids = np.asarray(scene.pipeline.clump_ids())
            if scene.has_children:  # each child in its nearest guide's clump
                b = scene.drawn_binding()
                ids = np.concatenate([ids[b.guide_ids[:, 0]], ids[:guides]])
        colors = strand_to_vertex_colors(categorical_colors(ids), top)
    elif mode == "displacement":
        colors = magnitude_colors(scene.displacement() / displacement_scale(scene))
    else:
        raise ValueError(f"unknown colour mode {mode!r}")
    if guides:
        colors = np.array(colors, np.float32)
        colors[top.offsets[top.strand_count - guides] :] = GUIDE_RGB
    return colors


def displacement_scale(scene: Scene) -> float:
    """The displacement that shows at the ramp's top: the median strand length of the rest groom,
    a fixed scale per groom, so colours do not flicker while dragging as a per-frame maximum would."""
    return max(float(np.median(scene.rest.strand_lengths)), 1e-9)


def _guides_over_ramp(scene: Scene, top, guides: int) -> np.ndarray:
    """The ramp over t, sampled as the renderer samples it, with the guides in their colour."""
    colors = sample_linear(ramp_texture(scene.ramp, RAMP_TEXELS), top.vertex_param)
    colors[top.offsets[top.strand_count - guides] :] = GUIDE_RGB
    return colors
