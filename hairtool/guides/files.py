"""Render hair and its guides as one groom of two kinds of curves prims, so one USD file holds
both: the render strands (with widths and colours) and the guides marked with USD's purpose
``guide``, which DCCs show as guides and do not render (Blender imports render and default
purposes as hair). The prims are the sources' own where they have them (a Blender groom's
``/root/Head/Hair/HairData`` as guides, its children beside it at ``…/HairDataRender``),
hairtool's ``/Groom/Hair`` and ``/Groom/Guides`` otherwise (:func:`render_prims`).
:func:`split_guides` takes such a groom apart again; :class:`AnimationWithGuides` is the same
for an animation, its frames made one at a time.
"""

from __future__ import annotations

import os
from collections.abc import Callable
from dataclasses import replace
from pathlib import Path

import numpy as np

from hairtool.errors import ParameterError
from hairtool.groom import Animation, Groom, StrandSizes, Topology, vertex_ids_of
from hairtool.guides.animate import RenderHairAnimation
from hairtool.metadata import HAIR_WIDTH_M, CurvesPrim, Metadata, join_attributes

HAIR_PRIM = "/Groom/Hair"
GUIDES_PRIM = "/Groom/Guides"
ROOT_WIDTH_M = HAIR_WIDTH_M  # render strand width at the root where the guides have none: 80 µm …
TIP_WIDTH_M = HAIR_WIDTH_M / 5  # … narrowing linearly to 16 µm at the tip
GUIDE_WIDTH_M = HAIR_WIDTH_M


def tapered_widths(
    groom: Groom | Topology,
    root: float | None = None,
    tip: float | None = None,
    meters_per_unit: float = 0.01,
) -> np.ndarray:
    """``(V,)`` float32 widths from ``root`` at the root to ``tip`` at the tip, linear in t
    (of a groom's strands or of a topology's), in scene units; by default 80 µm → 16 µm in a
    scene of ``meters_per_unit`` (a groom's own unit when a groom is given).

    Parameters
    ----------
    groom : Groom or Topology
        The strands.
    root, tip : float, optional
        Widths at the root and the tip in scene units (None: 80 µm and 16 µm).
    meters_per_unit : float, default 0.01
        The scene's unit, where a topology is given.

    Returns
    -------
    ndarray
        ``(V,)`` float32.
    """
    if isinstance(groom, Groom):
        meters_per_unit = groom.metadata.meters_per_unit
    root = ROOT_WIDTH_M / meters_per_unit if root is None else root
    tip = TIP_WIDTH_M / meters_per_unit if tip is None else tip
    for name, value in (("root width", root), ("tip width", tip)):
        if not np.isfinite(value) or value < 0:
            raise ParameterError(name, value, "a width ≥ 0 in scene units")
    t = groom.vertex_param.astype(np.float64)
    return (root + (tip - root) * t).astype(np.float32)


def _fitting(meta: Metadata, strands: int, guide: bool) -> tuple[CurvesPrim, ...]:
    prims = meta.for_strands(strands).curves
    return tuple(c for c in prims if (c.purpose == "guide") == guide) if prims else ()


def render_prims(hair: Metadata, hair_strands: int, guides: Metadata, guide_strands: int):
    """``(hair prims, guide prims)`` of render hair written beside its guides.

    Each side keeps the prims it came with (paths, basis, wrap; the guides' purpose set to
    ``guide``), so a groom's guide prim ``/root/Head/Hair/HairData`` stays there. A side
    without prims of its own is named after the other: children of the guides at P go to
    ``P + "Render"`` (``/Groom/Hair`` beside hairtool's own ``/Groom/Guides``) and are drawn
    with the guides' basis (their points are interpolated control points); guides picked from
    dense hair at H go to ``H + "Guides"``; with neither, ``/Groom/Hair`` and ``/Groom/Guides``.

    Parameters
    ----------
    hair : Metadata
        The render hair's record.
    hair_strands : int
        Its strands.
    guides : Metadata
        The guides' record.
    guide_strands : int
        Their strands.

    Returns
    -------
    tuple of (tuple, tuple)
        The hair's prims and the guides' prims.
    """
    own_hair = _fitting(hair, hair_strands, guide=False)
    own_guides = tuple(replace(c, purpose="guide") for c in guides.for_strands(guide_strands).curves)
    if not own_guides:
        path = own_hair[0].path + "Guides" if len(own_hair) == 1 else GUIDES_PRIM
        own_guides = (CurvesPrim(path, guide_strands, purpose="guide"),)
    if not own_hair:
        first = own_guides[0]
        path = HAIR_PRIM if first.path == GUIDES_PRIM else first.path + "Render"
        own_hair = (CurvesPrim(path, hair_strands, first.basis, first.wrap),)
    if {c.path for c in own_hair} & {c.path for c in own_guides}:  # never two prims on one path
        own_guides = tuple(replace(c, path=c.path + "Guides") for c in own_guides)
    return own_hair, own_guides


def _with_lacks(prims: tuple[CurvesPrim, ...], lacks: tuple[str, ...]) -> tuple[CurvesPrim, ...]:
    return tuple(replace(c, lacks=tuple(sorted(set(c.lacks) | set(lacks)))) for c in prims)


def joined_attributes(hair, hair_topology: Topology, guides, meta: Metadata, prims) -> tuple[dict, tuple]:
    """The per-vertex attributes of the hair then the guides, widths defaulted where a side has
    none (80 µm tapered to 16 µm for the hair, 80 µm for the guides, in ``meta``'s unit), a
    colour or transparency only one side has filled on the other (its prims then say they lack
    it, so it is not written there); and the prims with those marks.

    Parameters
    ----------
    hair : dict or Groom
        The render hair's per-vertex attributes, or the render hair.
    hair_topology : Topology
        Its strands.
    guides : Groom
        The guides.
    meta : Metadata
        The record written (its unit for the default widths).
    prims : tuple
        The hair's and the guides' prims (:func:`render_prims`).

    Returns
    -------
    tuple of (dict, tuple)
        The joined attributes and the prims with their marks.
    """
    mpu = meta.meters_per_unit
    h = dict(hair) if isinstance(hair, dict) else dict(hair.attributes)
    g = dict(guides.attributes)
    if h.get("thickness") is None:
        h["thickness"] = tapered_widths(hair_topology, meters_per_unit=mpu)
    if g.get("thickness") is None:
        g["thickness"] = np.full(guides.vertex_count, GUIDE_WIDTH_M / mpu, np.float32)
    attrs, lacks = join_attributes([h, g], [hair_topology.vertex_count, guides.vertex_count], mpu)
    hair_prims, guide_prims = prims
    return attrs, _with_lacks(hair_prims, lacks[0]) + _with_lacks(guide_prims, lacks[1])


def with_guides(hair: Groom, guides: Groom, metadata: Metadata | None = None) -> Groom:
    """One groom: the render strands then the guides (purpose ``guide``), each on its prims
    (:func:`render_prims`), with their widths, colours and transparency
    (:func:`joined_attributes`); ``metadata``'s space and time codes (default: the guides').

    Parameters
    ----------
    hair : Groom
        The render strands.
    guides : Groom
        Their guides.
    metadata : Metadata, optional
        Space and time codes (None: the guides').

    Returns
    -------
    Groom
        Both, on their own prims.
    """
    base = guides.metadata if metadata is None else metadata
    prims = render_prims(hair.metadata, hair.strand_count, guides.metadata, guides.strand_count)
    attrs, curves = joined_attributes(hair, hair.topology, guides, base, prims)
    return Groom(
        np.concatenate([hair.points, guides.points]),
        np.concatenate([hair.counts, guides.counts]),
        **attrs,
        metadata=base.with_(curves=curves),
    )


def split_guides(groom: Groom | Animation) -> tuple[Groom | Animation, Groom | Animation | None]:
    """``(hair, guides)``: the strands of prims with purpose ``guide`` apart from the rest
    (``guides`` None when no prim is marked so); an animation splits into two animations. Each
    part keeps the scene and its own prims (paths, basis, wrap).

    Parameters
    ----------
    groom : Groom or Animation
        Strands read from a file.

    Returns
    -------
    tuple of (Groom or Animation, Groom or Animation or None)
        The render hair and the guides.
    """
    prims = groom.metadata.for_strands(groom.strand_count).curves
    marks = [np.full(c.strands, c.purpose == "guide") for c in prims]
    if not marks or not any(c.purpose == "guide" for c in prims):
        return groom, None
    is_guide = np.concatenate(marks)

    def meta(guide: bool) -> Metadata:
        return groom.metadata.with_(curves=tuple(c for c in prims if (c.purpose == "guide") == guide))

    if isinstance(groom, Animation):
        top = groom.topology

        def part(ids: np.ndarray, guide: bool) -> Animation:
            vids = vertex_ids_of(top, ids)
            pick = {k: (None if v is None else v[vids]) for k, v in groom.attributes.items()}
            return Animation(groom.frames[:, vids], top.counts[ids], groom.fps, **pick, metadata=meta(guide))

        return part(np.flatnonzero(~is_guide), False), part(np.flatnonzero(is_guide), True)
    hair = groom.subset(np.flatnonzero(~is_guide)).with_metadata(meta(False))
    guides = groom.subset(np.flatnonzero(is_guide)).with_metadata(meta(True))
    return hair, guides


class AnimationWithGuides(StrandSizes):
    """Render hair following an animation of its guides, and those guides, as one animation of
    their prims (:func:`render_prims`: the guides' own, purpose ``guide``) whose frames are made
    one at a time: what :func:`hairtool.io.usd.write` takes as a frame stream. Widths, colours
    and transparency as in :func:`with_guides`; the time codes, up axis and unit of ``metadata``
    (default: the guides animation's)."""

    def __init__(self, hair: RenderHairAnimation, metadata: Metadata | None = None) -> None:
        """The frames of ``hair`` with its guides after them, made one at a time.

        Parameters
        ----------
        hair : RenderHairAnimation
            Render hair following its guides.
        metadata : Metadata, optional
            Space and time codes (None: the guides').
        """
        self.hair, guides = hair, hair.guides
        self.guides = guides
        self.topology = Topology(np.concatenate([hair.counts, guides.counts]))
        base = guides.metadata if metadata is None else metadata
        prims = render_prims(hair.metadata, hair.strand_count, guides.metadata, guides.strand_count)
        attrs, curves = joined_attributes(hair.binding.attributes, hair.topology, guides, base, prims)
        self.thickness, self.transparency, self.colors = (
            attrs["thickness"],
            attrs["transparency"],
            attrs["colors"],
        )
        self.metadata = base.with_(time_codes=guides.metadata.time_codes, curves=curves)
        self.fps = guides.fps

    @property
    def n_frames(self) -> int:
        return self.guides.n_frames

    @property
    def time_codes(self) -> np.ndarray:
        return self.guides.time_codes

    def frame_points(self, f: int) -> np.ndarray:
        """``(V, 3)`` float32: the children at frame ``f``, then the guides.

        Parameters
        ----------
        f : int
            The frame.

        Returns
        -------
        ndarray
            ``(V, 3)`` float32.
        """
        out = np.empty((self.vertex_count, 3), np.float32)
        n = self.hair.vertex_count
        self.hair.frame_points(f, out[:n])  # the children straight into their rows
        out[n:] = self.guides.frames[f]
        return out


def guides_path_for(path: str | os.PathLike[str]) -> Path:
    """Where the guides go beside render hair in a format that cannot mark them:
    ``shot.npz`` → ``shot.guides.npz``.

    Parameters
    ----------
    path : str or os.PathLike
        The render hair's file.

    Returns
    -------
    Path
        The guides' file beside it.
    """
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
    left. Returns the paths written (``output``, ``guides_output``).

    Parameters
    ----------
    path : str or os.PathLike
        The render hair's file.
    hair : RenderHairAnimation
        Render hair following its guides.
    guides_path : str or os.PathLike, optional
        Where the guides go too (a USD file) or instead.
    progress : callable, optional
        ``progress(done, total)`` after each frame.

    Returns
    -------
    dict of str to str
        ``output`` and ``guides_output``.
    """
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
