"""Add: plants new strands on the head under the brush, shaped like their neighbours (the
surface's ``plant``); they come unmasked, with clump strength 1, selected and shown. Front faces
only: a sample that says ``visible`` plants only the roots the head does not hide from the
camera; one that does not (every log before it) plants nothing where the head under the cursor
faces away."""

from __future__ import annotations

import numpy as np

from hairtool.errors import ParameterError
from hairtool.frozen.brushes.sample import MAX_COUNT
from hairtool.frozen.brushes.spec import Brush, BrushSpec, Param, StrokeContext, Studio
from hairtool.frozen.root_grid import nearest_root
from hairtool.groom import Groom

SEED = Param("seed", int, 0, 2**32 - 1, 0, "seed", "a whole number in [0, 2^32)")

SPEC = BrushSpec(
    name="add",
    order=11,
    moves_points=False,
    changes_strands=True,
    needs_surface=True,
    takes_strength=False,
    follows_selection=False,
    params=(
        Param("count", int, 1, MAX_COUNT, 1, "count", f"a whole number of strands in [1, {MAX_COUNT}]"),
        SEED,
    ),
    studio=Studio(
        "Add",
        "Shift+A",
        "Plants new strands on the head under the brush, shaped like their neighbours (needs the head mesh)",
        1.0,
        place=11,
    ),
)


def append_strands(g: Groom, new: Groom) -> Groom:
    """``g`` with ``new``'s strands after its own; each per-vertex attribute of ``g`` taken for a
    new strand from the strand whose root is nearest (found through a grid of the roots), by
    the vertex parameter; a new strand joins that strand's prim where it can
    (:meth:`~hairtool.metadata.Metadata.extended`)."""
    attrs = {}
    near = nearest_root(g.roots, new.roots)
    if any(a is not None for a in g.attributes.values()):
        for name, a in g.attributes.items():
            if a is None:
                attrs[name] = None
                continue
            rows = []
            for s, t in zip(near, new.topology.offsets[:-1], strict=True):
                o, e = g.offsets[s], g.offsets[s + 1]
                tn = new.vertex_param[t : t + new.counts[len(rows)]]
                src, ts = a[o:e], g.vertex_param[o:e]
                if a.ndim == 1:
                    rows.append(np.interp(tn, ts, src))
                else:
                    rows.append(np.column_stack([np.interp(tn, ts, src[:, c]) for c in range(a.shape[1])]))
            attrs[name] = np.concatenate([a, *rows]).astype(np.float32)
    points, counts = np.concatenate([g.points, new.points]), np.concatenate([g.counts, new.counts])
    return Groom(points, counts, **attrs, metadata=g.metadata.extended(g.metadata.prim_of(near)))


class Add(Brush):
    spec = SPEC

    def apply(self, ctx: StrokeContext, g: Groom, sample) -> Groom:
        surface = ctx.surface
        if surface is None or not hasattr(surface, "plant"):
            raise ParameterError("scalp", None, "a head mesh for the add brush (--scalp MESH.obj)")
        s = sample
        new = surface.plant(g, s.cursor, s.radius, s.count, s.seed, s.view, s.visible, s.eye)
        if new is None:
            return g
        out = append_strands(g, new)
        ctx.planted(new.strand_count)
        return out


BRUSH = Add()
