"""The prims of an animated groom, each on its own, and their frame streams laid end to end.

Children of an animated groom grow once from the guides of its first frame (the rest pose) and
follow each frame's guides with the same weights, as Blender's interpolated children follow
their guides (:class:`~hairtool.guides.animate.RenderHairAnimation`). With several hair prims
(hair and eyebrows) each prim grows its own children (:mod:`hairtool.prims`):
:func:`split_animation` cuts the animation into one per prim, and :class:`JoinedFrames` lays the
results back in the source's order as one frame stream, which a writer takes frame by frame
(:func:`hairtool.io.usd.write`): the prims not picked pass through with their own motion.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import replace

import numpy as np

from hairtool.errors import ParameterError
from hairtool.groom import Animation, StrandSizes, Topology, vertex_ids_of
from hairtool.metadata import ATTRIBUTES, join_attributes


def split_animation(anim: Animation) -> list[Animation]:
    """The animation of each source prim, in order (the animation itself where it has one)."""
    prims = anim.metadata.for_strands(anim.strand_count).curves
    if len(prims) <= 1:
        return [anim]
    out, first = [], 0
    for c in prims:
        ids = np.arange(first, first + c.strands)
        first += c.strands
        vids = vertex_ids_of(anim.topology, ids)
        pick = {k: (None if v is None else v[vids]) for k, v in anim.attributes.items()}
        meta = anim.metadata.with_(curves=(c,))
        out.append(Animation(anim.frames[:, vids], anim.counts[ids], anim.fps, **pick, metadata=meta))
    return out


def _frame(part, f: int) -> np.ndarray:
    return part.frames[f] if isinstance(part, Animation) else part.frame_points(f)


class JoinedFrames(StrandSizes):
    """Animations and frame streams on prims of their own (one per source prim: its render hair
    and guides, or the prim as it was), end to end as one frame stream of the same frames. An
    attribute some parts lack is filled with defaults there and their prims say they lack it
    (the writer leaves it out of them), as :func:`hairtool.prims.concat` does for grooms. The
    scene and time codes are the first part's."""

    def __init__(self, parts: Sequence) -> None:
        if not parts:
            raise ParameterError("parts", 0, "at least one animation")
        first = parts[0]
        for p in parts[1:]:
            if p.n_frames != first.n_frames or not np.array_equal(p.time_codes, first.time_codes):
                raise ParameterError("parts", repr(p), f"the {first.n_frames} frames of the first part")
        self.parts = list(parts)
        self.fps = first.fps
        self.topology = Topology(np.concatenate([p.counts for p in parts]))
        meta = first.metadata
        attrs, lacks = join_attributes(
            [{n: getattr(p, n) for n in ATTRIBUTES} for p in parts],
            [p.vertex_count for p in parts],
            meta.meters_per_unit,
        )
        curves = []
        for part, lack in zip(parts, lacks, strict=True):
            prims = part.metadata.for_strands(part.strand_count).curves
            if not prims:
                raise ParameterError("prims", repr(part), "a part on prims of its own")
            curves += [replace(c, lacks=tuple(sorted(set(c.lacks) | set(lack)))) for c in prims]
        self.thickness, self.transparency, self.colors = (attrs[n] for n in ATTRIBUTES)
        self.metadata = meta.with_(curves=tuple(curves))

    @property
    def n_frames(self) -> int:
        return self.parts[0].n_frames

    @property
    def time_codes(self) -> np.ndarray:
        return np.asarray(self.parts[0].time_codes, np.float64)

    @property
    def attributes(self) -> dict:
        return {n: getattr(self, n) for n in ATTRIBUTES}

    def frame_points(self, f: int) -> np.ndarray:
        """``(V, 3)`` float32: every part's points at frame ``f``, end to end."""
        return np.concatenate([np.asarray(_frame(p, f), np.float32) for p in self.parts])

    def animation(self) -> Animation:
        """Every frame in one Animation (for the formats that take the whole array)."""
        frames = np.stack([self.frame_points(f) for f in range(self.n_frames)])
        return Animation(frames, self.topology, self.fps, **self.attributes, metadata=self.metadata)
