"""Strokes against the head: what the pipeline asks of the head's surface, in one place.

A sample that moves points with ``collide`` leaves no vertex it moved inside the head
(:func:`~hairtool.frozen.collide.collide`), and clumping after such strokes pushes back out the
strands it pulled inside (:class:`~hairtool.frozen.collide.KeepOut`, which remembers the head's
distances). Both need a surface that tells signed distances, and leave a margin of
:data:`~hairtool.frozen.collide.MARGIN` of the rest groom's box diagonal.
"""

from __future__ import annotations

import functools
from collections.abc import Sequence

import numpy as np

from hairtool.frozen.brushes import registry
from hairtool.frozen.collide import MARGIN, CollisionSurface, KeepOut, collide
from hairtool.groom import Groom


def head_of(surface: object | None) -> CollisionSurface | None:
    """The surface strokes collide with (one that tells signed distances), or None.

    Parameters
    ----------
    surface : object or None
        The head a pipeline was given.

    Returns
    -------
    CollisionSurface or None
        It, where it tells signed distances.
    """
    return surface if surface is not None and hasattr(surface, "signed_distance") else None  # type: ignore[return-value]


class HeadCollision:
    """Collision with the head for one rest groom (its margin, and the keep-out memory)."""

    def __init__(self, rest: Groom) -> None:
        """Collision of a pipeline's strokes with the head, over the rest groom ``rest``.

        Parameters
        ----------
        rest : Groom
            The groom at rest.
        """
        self._rest = rest
        self._scanned: tuple[Sequence | None, int, bool] = (None, 0, False)  # (log, read, any collides)

    @functools.cached_property
    def margin(self) -> float:
        """How far outside the head a collision leaves a vertex: MARGIN of the rest box's diagonal."""
        lo, hi = self._rest.bounds
        return MARGIN * max(float(np.linalg.norm(hi.astype(np.float64) - lo)), 1e-9)

    @functools.cached_property
    def keep_out(self) -> KeepOut:
        """:func:`~hairtool.frozen.collide.keep_out` with its memory of the head's distances."""
        return KeepOut()

    def collide(self, surface: object | None, before: Groom, after: Groom) -> Groom:
        """``after`` with the vertices a sample moved from ``before`` kept out of the head
        (``after`` itself without a head).

        Parameters
        ----------
        surface : object or None
            The pipeline's surface (a head only where it tells signed distances).
        before, after : Groom
            The groom before and after one sample, of one topology.

        Returns
        -------
        Groom
            The groom after the sample, outside the head.
        """
        head = head_of(surface)
        return after if head is None else collide(before, after, head, self.margin)

    def kept_out(self, surface: object | None, log: Sequence, aligned: Groom, clumped: Groom) -> Groom:
        """Clumping respects the head: where the strokes of ``log`` collide with it (a sample
        that moves points with ``collide``), the strands clumping pulled back inside are pushed
        out again, so no brushed vertex ends inside.

        Parameters
        ----------
        surface : object or None
            The pipeline's surface.
        log : sequence of samples
            The stroke log.
        aligned, clumped : Groom
            The stroked state and its clumped result.

        Returns
        -------
        Groom
            The clumped result, outside the head where strokes collide.
        """
        head = head_of(surface)
        if head is None:
            return clumped
        if not self.strokes_collide(log):
            return clumped
        return self.keep_out(aligned, clumped, head, self.margin)

    def strokes_collide(self, log: Sequence) -> bool:
        """Whether a sample of ``log`` moves points with ``collide``. The log asked about last
        time, grown since (a pipeline's log grows in place, or is replaced by another), is read on
        from where that look stopped: a move reads its own samples, not the whole session's.

        Parameters
        ----------
        log : sequence of samples
            The stroke log.

        Returns
        -------
        bool
            True where one collides.
        """
        seen, read, hit = self._scanned
        if seen is not log or read > len(log):
            read, hit = 0, False
        if not hit:
            hit = any(_collides(log[k]) for k in range(read, len(log)))
        self._scanned = (log, len(log), hit)
        return hit

    def remember(self, surface: object | None, aligned: Groom, result: Groom) -> None:
        """The head's distances a first collision asks for, now.

        Parameters
        ----------
        surface : object or None
            The head.
        aligned : Groom
            The strands before clumping.
        result : Groom
            The strands after.
        """
        head = head_of(surface)
        if head is not None:
            self.keep_out.remember(aligned, result, head)


def _collides(sample: object) -> bool:
    """Whether ``sample`` moves points and collides with the head."""
    return bool(getattr(sample, "collide", False)) and registry.spec_of(registry.name_of(sample)).moves_points
