"""Render hair: the children of a binding rebuilt from the guides, then, if switched on,
ClumpWithGaps among the children themselves (the paper's adhesion at render density, with the
engine's spatial hashing, :func:`hairtool.frozen.clump.clump_points`).

The clump radius defaults to the children's own: 2× the median distance between neighbouring
child roots (:func:`~hairtool.frozen.strand_clumps.auto_clump_radius` of the rest children),
and lengths are kept after clumping by default, since render hair should not stretch.
"""

from __future__ import annotations

from dataclasses import dataclass

from hairtool.frozen.clump import ClumpWorkspace, check_clump_params, clump_points
from hairtool.frozen.noise import check_seed
from hairtool.frozen.strand_clumps import auto_clump_radius
from hairtool.groom import Groom
from hairtool.guides.binding import ChildBinding


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

    def validate(self) -> ChildClump:
        check_clump_params(
            1.0 if self.radius is None else self.radius, self.iterations, self.step, self.gap_mode
        )
        check_seed(self.seed)
        return self


class RenderHair:
    """The children of ``binding`` for any pose of its guides; ``clump`` None: no adhesion."""

    def __init__(self, binding: ChildBinding, clump: ChildClump | None = None) -> None:
        self.binding = binding
        self.clump = None if clump is None else clump.validate()
        self.workspace = ClumpWorkspace()
        self._radius: float | None = None

    @property
    def clump_radius(self) -> float:
        """h of the children's ClumpWithGaps (the setting, or the rest children's automatic one)."""
        c = self.clump
        if c is not None and c.radius is not None:
            return float(c.radius)
        if self._radius is None:
            self._radius = auto_clump_radius(self.binding.build())
        return self._radius

    def update(self, guides: Groom | None = None) -> Groom:
        """The render strands for the guides' current shapes (their rest shapes by default)."""
        children = self.binding.build(guides)
        c = self.clump
        if c is None or c.iterations == 0:
            return children
        pts = clump_points(
            children,
            self.clump_radius,
            c.iterations,
            c.step,
            c.gap_mode,
            c.seed,
            self.workspace,
            c.keep_lengths,
        )
        return children.with_points(pts)
