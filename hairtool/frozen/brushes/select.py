"""Select: strength > 0 selects the strands a sample touches, < 0 deselects them
(:mod:`hairtool.frozen.selection`); hidden strands are left as they are. No vertex moves."""

from __future__ import annotations

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
    studio=Studio(
        "Select",
        "W",
        "Paints the selection: the strands it touches are selected (Ctrl deselects); "
        "with Affect selection only, the other brushes keep to them",
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
        skip = hidden if ctx.away is None else hidden | ctx.away
        ctx.state = ctx.state.with_(selected=paint_mask(g, sample, ctx.state.selected, skip))
        return g


BRUSH = Select()
