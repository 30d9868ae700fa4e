"""Children bound prim by prim, for the commands that animate the guides (``simulate``,
``anime``) of a scene with several hair prims.

Hair and eyebrows are two prims: a child of the hair must never follow a brow guide, and the
brows' children go to the brows' own render prim (:mod:`hairtool.prims`). ``interpolate``
grows each prim's children on its own; so does :func:`bind_per_prim`, ``--count`` shared
between the prims in proportion to their guides (:func:`~hairtool.prims.shares`). The command
then animates every guide at once (a simulation, a cycle: neither mixes strands), and
:func:`prim_frames` cuts that animation back into the prims, each prim's children following
its own guides, laid end to end in the source's order as one frame stream
(:class:`~hairtool.guides.animated_prims.JoinedFrames`).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

from hairtool.errors import ParameterError
from hairtool.groom import Animation, Groom
from hairtool.guides.animate import RenderHairAnimation
from hairtool.guides.animated_prims import JoinedFrames, split_animation
from hairtool.guides.binding import ChildBinding
from hairtool.guides.files import AnimationWithGuides, render_prims
from hairtool.guides.render import ChildClump
from hairtool.prims import shares, split


@dataclass(frozen=True)
class PrimBindings:
    """One :class:`~hairtool.guides.binding.ChildBinding` per hair prim, in the source's order;
    each binding's rest guides are that prim's strands."""

    bindings: tuple[ChildBinding, ...]

    @property
    def child_count(self) -> int:
        return sum(b.child_count for b in self.bindings)

    @property
    def vertex_count(self) -> int:
        return sum(b.vertex_count for b in self.bindings)


def bind_per_prim(guides: Groom, count: int, bind: Callable[[Groom, int], ChildBinding]) -> PrimBindings:
    """Each prim of ``guides`` bound on its own (``bind(prim's guides, its share of count)``).

    Parameters
    ----------
    guides : Groom
        The guides, on several prims.
    count : int
        Children in all, shared in proportion to the prims' guides.
    bind : callable
        ``(guides of one prim, children) -> ChildBinding``.

    Returns
    -------
    PrimBindings
        One binding per prim.
    """
    parts = split(guides)
    each = shares(count, [p.strand_count for p in parts])
    return PrimBindings(tuple(bind(p, n) for p, n in zip(parts, each, strict=True)))


def prim_frames(
    bindings: PrimBindings,
    guides: Animation,
    clump: Callable[[ChildBinding], ChildClump | None],
    *,
    with_guides: bool,
) -> tuple[JoinedFrames, Sequence[Animation]]:
    """The render hair of every prim following its own guides in ``guides`` (an animation of
    all the prims' guides, end to end), as one frame stream: each prim's children then, where
    ``with_guides`` (a USD file marks them), its guides (purpose ``guide``). Also the prims'
    guide animations.

    Parameters
    ----------
    bindings : PrimBindings
        The prims' children.
    guides : Animation
        Every guide, the prims end to end as the bindings' rest guides are.
    clump : callable
        ``binding -> ChildClump or None``: the children's own clumping.
    with_guides : bool
        Each prim's guides after its children.

    Returns
    -------
    tuple of (JoinedFrames, list of Animation)
        The frames, and each prim's guides animation.
    """
    parts = split_animation(guides)
    if len(parts) != len(bindings.bindings):
        raise ParameterError("guides", f"{len(parts)} prims", f"the {len(bindings.bindings)} prims bound")
    out = []
    for part, b in zip(parts, bindings.bindings, strict=True):
        hair = RenderHairAnimation(b, part, clump(b))
        out.append(AnimationWithGuides(hair) if with_guides else OnRenderPrim(hair))
    return JoinedFrames(out), parts


class OnRenderPrim:
    """Render hair following one prim's guides, alone on that prim's render prim (``P`` →
    ``PRender``, :func:`~hairtool.guides.files.render_prims`): a prim's part of the frames
    written to a format that cannot hold the guides beside it (``.npz``). Everything else is
    the render hair's own."""

    def __init__(self, hair: RenderHairAnimation) -> None:
        """``hair`` on its render prim.

        Parameters
        ----------
        hair : RenderHairAnimation
            One prim's children following its guides.
        """
        self.hair = hair
        guides = hair.guides
        prims = render_prims(hair.metadata, hair.strand_count, guides.metadata, guides.strand_count)[0]
        self.metadata = hair.metadata.with_(curves=prims)

    def __getattr__(self, name: str):
        return getattr(self.hair, name)
