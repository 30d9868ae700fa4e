"""Render hair and its guides as one groom of two curves prims, so one USD file holds both:
``/Groom/Hair`` (the render strands, with widths) and ``/Groom/Guides`` marked with USD's
purpose ``guide``, which DCCs show as guides and do not render (Blender imports render and
default purposes as hair). :func:`split_guides` takes such a groom apart again;
:class:`AnimationWithGuides` is the same for an animation, its frames made one at a time.
"""

from __future__ import annotations

import os
from collections.abc import Callable
from pathlib import Path

import numpy as np

from hairtool.errors import ParameterError
from hairtool.groom import Animation, Groom, StrandSizes, Topology, vertex_ids_of
from hairtool.guides.animate import RenderHairAnimation
from hairtool.metadata import CurvesPrim, Metadata

HAIR_PRIM = "/Groom/Hair"
GUIDES_PRIM = "/Groom/Guides"
ROOT_WIDTH = 0.01  # render strand width at the root, in scene units (centimetres: 0.1 mm)
TIP_WIDTH = 0.002  # … narrowing linearly to the tip
GUIDE_WIDTH = 0.01


def tapered_widths(groom: Groom | Topology, root: float = ROOT_WIDTH, tip: float = TIP_WIDTH) -> np.ndarray:
    """``(V,)`` float32 widths from ``root`` at the root to ``tip`` at the tip, linear in t
    (of a groom's strands or of a topology's)."""
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


def split_guides(groom: Groom | Animation) -> tuple[Groom | Animation, Groom | Animation | None]:
    """``(hair, guides)``: the strands of prims with purpose ``guide`` apart from the rest
    (``guides`` None when no prim is marked so); an animation splits into two animations."""
    prims = groom.metadata.for_strands(groom.strand_count).curves
    marks = [np.full(c.strands, c.purpose == "guide") for c in prims]
    if not marks or not any(c.purpose == "guide" for c in prims):
        return groom, None
    is_guide = np.concatenate(marks)
    keep_meta = groom.metadata.with_(curves=())
    if isinstance(groom, Animation):
        top = groom.topology

        def part(ids: np.ndarray) -> Animation:
            vids = vertex_ids_of(top, ids)
            pick = {k: (None if v is None else v[vids]) for k, v in groom.attributes.items()}
            return Animation(groom.frames[:, vids], top.counts[ids], groom.fps, **pick, metadata=keep_meta)

        return part(np.flatnonzero(~is_guide)), part(np.flatnonzero(is_guide))
    hair = groom.subset(np.flatnonzero(~is_guide)).with_metadata(keep_meta)
    guides = groom.subset(np.flatnonzero(is_guide)).with_metadata(keep_meta)
    return hair, guides


class AnimationWithGuides(StrandSizes):
    """Render hair following an animation of its guides, and those guides, as one animation of
    two prims (``/Groom/Hair`` then ``/Groom/Guides``, purpose ``guide``) whose frames are made
    one at a time: what :func:`hairtool.io.usd.write` takes as a frame stream. Widths as in
    :func:`with_guides`; the time codes, up axis and unit of ``metadata`` (default: the guides
    animation's)."""

    transparency = None
    colors = None

    def __init__(self, hair: RenderHairAnimation, metadata: Metadata | None = None) -> None:
        self.hair, guides = hair, hair.guides
        self.guides = guides
        self.topology = Topology(np.concatenate([hair.counts, guides.counts]))
        guide_widths = (
            guides.thickness if guides.thickness is not None else np.full(guides.vertex_count, GUIDE_WIDTH)
        )
        self.thickness = np.concatenate([tapered_widths(hair.topology), guide_widths.astype(np.float32)])
        base = guides.metadata if metadata is None else metadata
        self.metadata = base.with_(
            time_codes=guides.metadata.time_codes,
            curves=(
                CurvesPrim(HAIR_PRIM, hair.strand_count),
                CurvesPrim(GUIDES_PRIM, guides.strand_count, purpose="guide"),
            ),
        )
        self.fps = guides.fps

    @property
    def n_frames(self) -> int:
        return self.guides.n_frames

    @property
    def time_codes(self) -> np.ndarray:
        return self.guides.time_codes

    def frame_points(self, f: int) -> np.ndarray:
        """``(V, 3)`` float32: the children at frame ``f``, then the guides."""
        out = np.empty((self.vertex_count, 3), np.float32)
        n = self.hair.vertex_count
        self.hair.frame_points(f, out[:n])  # the children straight into their rows
        out[n:] = self.guides.frames[f]
        return out


def guides_path_for(path: str | os.PathLike[str]) -> Path:
    """Where the guides go beside render hair in a format that cannot mark them:
    ``shot.npz`` → ``shot.guides.npz``."""
    p = Path(path)
    return p.with_name(f"{p.stem}.guides{p.suffix}")


def write_animation(
    path: str | os.PathLike[str],
    hair: RenderHairAnimation,
    *,
    guides_path: str | os.PathLike[str] | None = None,
    progress: Callable[[int, int], object] | None = None,
) -> dict[str, str]:
    """Write render hair following an animation of its guides, and the guides.

    USD: one file, the children and the guides (purpose ``guide``) time-sampled frame by frame,
    never the whole shot in memory (a ``.usdc`` is saved as it grows); the guides also go to
    ``guides_path`` if given. Other formats cannot mark guides: ``path`` gets the render hair
    (``.npz`` every frame, built whole in memory; ``.hair`` and ``.obj`` frame 0) and the guides
    animation goes to ``guides_path`` (default :func:`guides_path_for`). ``progress(done,
    total)`` after each frame; an exception it raises (Cancelled) stops the write, no file
    left. Returns the paths written (``output``, ``guides_output``)."""
    from hairtool import io
    from hairtool.io import usd

    usd_out = io.format_for(path, writing=True).module == "usd"
    if not usd_out and guides_path is None:
        guides_path = guides_path_for(path)
    if guides_path is not None:
        io.format_for(guides_path, writing=True)  # refused before the long part
    if usd_out:
        usd.write(Path(path), AnimationWithGuides(hair), progress=progress)
    else:
        io.write(path, hair.animation(progress))
    report = {"output": str(path)}
    if guides_path is not None:
        io.write(guides_path, hair.guides)
        report["guides_output"] = str(guides_path)
    return report
