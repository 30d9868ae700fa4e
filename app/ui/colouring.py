"""Per-vertex colours for the "Colour by" modes other than the root-to-tip ramp."""

from __future__ import annotations

import numpy as np

from app.render.ramps import (
    categorical_colors,
    per_strand_random_colors,
    strand_to_vertex_colors,
)
from app.ui.legend import magnitude_colors
from app.ui.scene import Scene

STRAND_COLOUR_SEED = 7  # fixed, so a groom keeps its per-strand colours between runs


def vertex_colors(scene: Scene) -> np.ndarray | None:
    """``(V, 3)`` float32 colours, or None where the renderer's ramp over t does the colouring."""
    mode = scene.colour_mode
    top = scene.result.topology
    if mode == "root-to-tip":
        return None
    if mode == "strand":
        return strand_to_vertex_colors(per_strand_random_colors(top.strand_count, STRAND_COLOUR_SEED), top)
    if mode == "clump":
        if scene.pipeline is None:  # no clumps before the engine starts: all strands grey
            return strand_to_vertex_colors(categorical_colors(np.full(top.strand_count, -1)), top)
        ids = np.asarray(scene.pipeline.clump_ids())
        return strand_to_vertex_colors(categorical_colors(ids), top)
    if mode == "displacement":
        return magnitude_colors(scene.displacement() / displacement_scale(scene))
    raise ValueError(f"unknown colour mode {mode!r}")


def displacement_scale(scene: Scene) -> float:
    """The displacement that shows at the ramp's top: the median strand length of the rest groom,
    a fixed scale per groom, so colours do not flicker while dragging as a per-frame maximum would."""
    return max(float(np.median(scene.rest.strand_lengths)), 1e-9)
