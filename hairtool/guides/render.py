"""Render hair: the children of a binding rebuilt from the guides, then, if switched on,
ClumpWithGaps among the children themselves (the paper's adhesion at render density), the
children of each guide with each other (:mod:`hairtool.guides.child_clumps`).

The clump radius defaults to the children's own: 2× the median distance between neighbouring
child roots (:func:`~hairtool.frozen.strand_clumps.auto_clump_radius` of the rest children),
and lengths are kept after clumping by default, since render hair should not stretch.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from hairtool.frozen.clump import check_clump_params
from hairtool.frozen.noise import check_seed
from hairtool.frozen.strand_clumps import auto_clump_radius
from hairtool.groom import Groom
from hairtool.guides.binding import ChildBinding
from hairtool.guides.child_clumps import ChildClumps
from hairtool.guides.children import build_points, moved_guides
from hairtool.guides.root_motion import following


@dataclass(frozen=True)
class ChildClump:
    """ClumpWithGaps on the children: radius h (None: the children's automatic radius),
    iterations k, step Δt²/m (None: automatic), gap mode, seed, keep_lengths."""

    radius: float | None = None
    iterations: int = 3
    step: float | None = None
    gap_mode: str = "printed"
    seed: int = 0
    keep_lengths: bool = True

    @classmethod
    def following(cls, params) -> ChildClump:
        """The children's ClumpWithGaps with an engine's clump passes, gap mode and length rule
        (``params``: a :class:`~hairtool.frozen.pipeline.FrozenParams`), at the children's own
        automatic radius and step: what the studio's Clump children runs.

        Parameters
        ----------
        params : FrozenParams
            The engine's parameters.

        Returns
        -------
        ChildClump
            The children's clumping.
        """
        return cls(
            iterations=params.clump_iterations, gap_mode=params.gap_mode, keep_lengths=params.keep_lengths
        )

    def validate(self) -> ChildClump:
        check_clump_params(
            1.0 if self.radius is None else self.radius, self.iterations, self.step, self.gap_mode
        )
        check_seed(self.seed)
        return self


class RenderHair:
    """The children of ``binding`` for any pose of its guides; ``clump`` None: no adhesion.

    Clumping runs among the children of each guide (:mod:`hairtool.guides.child_clumps`). An
    update after another rebuilds only the children that follow a guide which moved since, and
    clumps again only the clumps holding them, with the bytes of a fresh run."""

    def __init__(
        self, binding: ChildBinding, clump: ChildClump | None = None, *, follow_roots: bool = False
    ) -> None:
        """The render strands of ``binding``, clumped by ``clump`` where given.

        Parameters
        ----------
        binding : ChildBinding
            The children bound to their guides.
        clump : ChildClump, optional
            The children's own clumping (None: none).
        follow_roots : bool, default False
            Carry the children's roots with their guides' roots (an animation's frames); a
            static pose keeps the roots the children were bound at.
        """
        self.binding = binding
        #: children's roots carried by their guides' roots (:mod:`hairtool.guides.root_motion`):
        #: an animation's frames; a static pose keeps the roots the children were bound at
        self.follow_roots = follow_roots
        self._roots_from: np.ndarray | None = None  # the guide roots the children were built on
        self.clump = None if clump is None else clump.validate()
        self._radius: float | None = None
        self._clumps: ChildClumps | None = None
        self._children: np.ndarray | None = None  # the children as built, before clumping …
        self._built_from: np.ndarray | None = None  # … from these guide points

    @property
    def clump_radius(self) -> float:
        """h of the children's ClumpWithGaps (the setting, or the rest children's automatic one)."""
        c = self.clump
        if c is not None and c.radius is not None:
            return float(c.radius)
        if self._radius is None:
            self._radius = auto_clump_radius(self.binding.build())
        return self._radius

    @property
    def clumps(self) -> ChildClumps | None:
        """The clumps' runs (None before the first clumped update); ``mean_neighbours`` and
        ``clumps_run`` say what the last one did."""
        return self._clumps

    def update_points(self, guides: Groom | None = None) -> np.ndarray:
        """float32 ``(V, 3)``: the render strands' points for the guides' current shapes (their
        rest shapes by default), in an array this object keeps and rewrites on the next update
        (copy it to keep it).

        Parameters
        ----------
        guides : Groom, optional
            The guides' current shapes (None: at rest).

        Returns
        -------
        ndarray
            ``(V, 3)`` float32, this object's buffer.
        """
        b = self.binding
        pose = b.rest_guides if guides is None else guides
        b.check_guides(pose)
        moved = None
        roots = np.array(pose.roots, np.float32)
        if self._children is not None:
            moved = moved_guides(pose, self._built_from)
            if self.follow_roots and not np.array_equal(roots, self._roots_from):
                moved = None  # the roots' rigid motion moves every child
        built = following(b, pose) if self.follow_roots else b
        self._children = build_points(built, pose, out=self._children, moved=moved)
        self._roots_from = roots
        self._built_from = np.array(pose.points, np.float32)
        c = self.clump
        if c is None or c.iterations == 0:
            return self._children
        if self._clumps is None:
            self._clumps = ChildClumps(
                b.guide_ids, b.rest_guides.strand_count, self.clump_radius, c.iterations, c.step,
                c.gap_mode, c.seed, c.keep_lengths,
            )  # fmt: skip
            moved = None
        redo = None if moved is None else self._clumps.redo_for(moved)
        return self._clumps.run(self._children, b.topology, redo)

    def update(self, guides: Groom | None = None) -> Groom:
        """The render strands for the guides' current shapes (their rest shapes by default).

        Parameters
        ----------
        guides : Groom, optional
            The guides' current shapes (None: at rest).

        Returns
        -------
        Groom
            The render strands.
        """
        b = self.binding
        points = self.update_points(guides).copy()
        return Groom(points, b.topology, **b.attributes, metadata=b.metadata)
