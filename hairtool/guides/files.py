"""Render hair and its guides as one groom of two curves prims, so one USD file holds both:
``/Groom/Hair`` (the render strands, with widths) and ``/Groom/Guides`` marked with USD's
purpose ``guide``, which DCCs show as guides and do not render (Blender imports render and
default purposes as hair). :func:`split_guides` takes such a groom apart again.
"""

from __future__ import annotations

import numpy as np

from hairtool.errors import ParameterError
from hairtool.groom import Groom
from hairtool.metadata import CurvesPrim, Metadata

HAIR_PRIM = "/Groom/Hair"
GUIDES_PRIM = "/Groom/Guides"
ROOT_WIDTH = 0.01  # render strand width at the root, in scene units (centimetres: 0.1 mm)
TIP_WIDTH = 0.002  # … narrowing linearly to the tip
GUIDE_WIDTH = 0.01


def tapered_widths(groom: Groom, root: float = ROOT_WIDTH, tip: float = TIP_WIDTH) -> np.ndarray:
    """``(V,)`` float32 widths from ``root`` at the root to ``tip`` at the tip, linear in t."""
    for name, value in (("root width", root), ("tip width", tip)):
        if not np.isfinite(value) or value < 0:
            raise ParameterError(name, value, "a width ≥ 0 in scene units")
    t = groom.vertex_param.astype(np.float64)
    return (root + (tip - root) * t).astype(np.float32)


def with_guides(hair: Groom, guides: Groom, metadata: Metadata | None = None) -> Groom:
    """One groom: the render strands (widths their own or tapered) then the guides (purpose
    ``guide``), as two prims; ``metadata``'s space and time codes (default: the guides')."""
    widths = hair.thickness if hair.thickness is not None else tapered_widths(hair)
    guide_widths = (
        guides.thickness if guides.thickness is not None else np.full(guides.vertex_count, GUIDE_WIDTH)
    )
    colors = None
    if hair.colors is not None and guides.colors is not None:
        colors = np.concatenate([hair.colors, guides.colors])
    base = guides.metadata if metadata is None else metadata
    meta = base.with_(
        curves=(
            CurvesPrim(HAIR_PRIM, hair.strand_count),
            CurvesPrim(GUIDES_PRIM, guides.strand_count, purpose="guide"),
        )
    )
    return Groom(
        np.concatenate([hair.points, guides.points]),
        np.concatenate([hair.counts, guides.counts]),
        thickness=np.concatenate([widths, guide_widths.astype(np.float32)]),
        colors=colors,
        metadata=meta,
    )


def split_guides(groom: Groom) -> tuple[Groom, Groom | None]:
    """``(hair, guides)``: the strands of prims with purpose ``guide`` apart from the rest
    (``guides`` None when no prim is marked so)."""
    prims = groom.metadata.for_strands(groom.strand_count).curves
    marks = [np.full(c.strands, c.purpose == "guide") for c in prims]
    if not marks or not any(c.purpose == "guide" for c in prims):
        return groom, None
    is_guide = np.concatenate(marks)
    keep_meta = groom.metadata.with_(curves=())
    hair = groom.subset(np.flatnonzero(~is_guide)).with_metadata(keep_meta)
    guides = groom.subset(np.flatnonzero(is_guide)).with_metadata(keep_meta)
    return hair, guides
