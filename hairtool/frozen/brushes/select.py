"""Select: strength > 0 selects the strands a sample touches, < 0 deselects them
(:mod:`hairtool.frozen.selection`). A sample with ``new_selection`` first deselects every shown
strand (Blender's Selection Paint, where a plain stroke starts a new selection at its first
sample, Shift adds and Ctrl deselects); one without it adds, as every log written before the
choice meant. Hidden strands are left as they are, selected or not (no sculpt brush touches a
hidden curve in Blender). No vertex moves."""

from __future__ import annotations

import numpy as np

from hairtool.frozen.brushes.mask import paint_mask
from hairtool.frozen.brushes.spec import Brush, BrushSpec, StrokeContext, Studio
from hairtool.groom import Groom

SPEC = BrushSpec(
    name="select",
    order=13,
    signed=True,
    moves_points=False,
    local=True,
    takes_strength=False,
    follows_selection=False,
    starts_anew=True,
    studio=Studio(
        "Select",
        "W",
        "Paints the selection: a stroke selects the strands it touches and only them, Shift+drag "
        "adds them to the selection, Ctrl+drag deselects them; with Affect selection only, the "
        "other brushes keep to the selected strands",
        1.0,
        ("Select", "Deselect"),
        "Select or deselect",
        place=13,
    ),
)


class Select(Brush):
    spec = SPEC

    def apply(self, ctx: StrokeContext, g: Groom, sample) -> Groom:
        hidden = ctx.state.hidden
        selected = ctx.state.selected
        if sample.new_selection:
            selected = np.logical_and(selected, hidden)  # every shown strand deselected first
        skip = hidden if ctx.away is None else hidden | ctx.away
        ctx.state = ctx.state.with_(selected=paint_mask(g, sample, selected, skip))
        return g

    def reaches_every_strand(self, sample) -> bool:
        return bool(sample.new_selection)


BRUSH = Select()
