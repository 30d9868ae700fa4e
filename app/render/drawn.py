"""What is drawn: one value for the strands on screen, read alike by the viewport, stills and videos.

The studio draws either the groom itself or its render hair (interpolated children, then the
guides as the last strands when they are shown), at the groom's current shape or at an
animation frame. Points, topology, colours and the look (ramp, width, taper, hair shading) are
made together (:func:`app.ui.drawn.drawn`) and checked against each other here, so a consumer
can never pair the guides' points with the colours of every child.

Colours are made on first use (:attr:`Drawn.colors`): a brush drag re-uploads the points of a
``Drawn`` every move while its colours, cached in the scene, are not even asked for.
"""

from __future__ import annotations

import functools
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from app.render.ramps import DEFAULT_RAMP
from hairtool.errors import GroomError, ParameterError
from hairtool.groom import Groom, Topology


def _no_colors() -> None:
    return None


@dataclass(frozen=True, eq=False)
class Drawn:
    """The drawn strands: ``points`` ``(V, 3)`` float32 of ``topology``; ``guides`` the number
    of guide strands drawn last over render hair (0: none, or no render hair); the look:
    ``ramp`` (root-to-tip colours where ``colors`` is None), ``line_width`` in pixels, ``taper``
    (share of the width lost at the tip) and ``shaded`` (lit as hair)."""

    points: NDArray[np.float32]
    topology: Topology
    guides: int = 0
    ramp: str = DEFAULT_RAMP
    line_width: float = 2.0
    taper: float = 0.0
    shaded: bool = False
    make_colors: Callable[[], NDArray | None] = field(default=_no_colors, repr=False)

    def __post_init__(self) -> None:
        v = self.topology.vertex_count
        if np.shape(self.points) != (v, 3):
            raise GroomError(f"drawn points have shape {np.shape(self.points)}, expected ({v}, 3)")
        if not 0 <= self.guides <= self.topology.strand_count:
            raise GroomError(f"{self.guides} drawn guides of {self.topology.strand_count} strands")

    @functools.cached_property
    def colors(self) -> NDArray[np.float32] | None:
        """``(V, 3)`` RGB per vertex, or None for the ramp along t (checked against the points)."""
        c = self.make_colors()
        if c is not None and np.shape(c) != (self.topology.vertex_count, 3):
            v = self.topology.vertex_count
            raise ParameterError("colors", np.shape(c), f"shape ({v}, 3): one RGB per drawn vertex")
        return c

    @property
    def vertex_count(self) -> int:
        return self.topology.vertex_count

    @property
    def strand_count(self) -> int:
        return self.topology.strand_count

    def groom(self) -> Groom:
        """The drawn strands as a groom (for the SVG writer and tests)."""
        return Groom(self.points, self.topology)

    @classmethod
    def of_groom(
        cls, groom: Groom, colors: NDArray | None = None, *, ramp: str = DEFAULT_RAMP, line_width: float = 2.0
    ) -> Drawn:
        """A groom drawn as it is: ``colors``, else its own colours, else the ramp."""
        own = colors if colors is not None else groom.colors
        return cls(groom.points, groom.topology, ramp=ramp, line_width=line_width, make_colors=lambda: own)
