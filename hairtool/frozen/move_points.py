"""Copy-on-write points for brush-local moves.

A brush move on a groom of millions of vertices changes a few thousand of them, and grooms are
immutable: each move used to hand out copies of every point (the aligned groom and the result,
5 ms each at 3.2M vertices) while the move's own work took a millisecond or two. The pipeline
now writes a move's rows into the arrays of the last move's grooms when nothing but the
pipeline holds those grooms or their arrays (a script or a benchmark that drops each result),
and copies first where anything else does (the studio's scene, an undo snapshot, a caller's
variable, a view of the points): a groom never changes once it has been handed out.

Whether anything else holds them is read from their reference counts (CPython's), calibrated
once on an object held by one attribute and read the same way, so the call's own reference
counts alike in both (or, where an interpreter borrows it, in neither).
"""

from __future__ import annotations

import sys

import numpy as np


class _One:
    __slots__ = ("item",)


def _one_holder() -> int:
    """What ``sys.getrefcount(x.attr)`` reads for an object held by that attribute alone."""
    one = _One()
    one.item = np.empty(0)
    return sys.getrefcount(one.item)


_ONE_HOLDER = _one_holder()


def held_by_at_most(count: int, holders: int) -> bool:
    """Whether an object whose ``sys.getrefcount(x.attr)`` (read from an attribute, as the
    calibration is) gave ``count`` has no more than ``holders`` references.

    Parameters
    ----------
    count : int
        What ``sys.getrefcount`` gave.
    holders : int
        The references allowed.

    Returns
    -------
    bool
        True where no one else holds it.
    """
    return count - _ONE_HOLDER + 1 <= holders


def may_write(a: np.ndarray) -> bool:
    """Whether ``a`` (read-only, as grooms' points are) can be made writable again: it owns its
    memory (a view's flag cannot be set back).

    Parameters
    ----------
    a : ndarray
        A read-only array.

    Returns
    -------
    bool
        True where it owns its memory.
    """
    return a.flags.owndata and a.flags.c_contiguous


class MovePoints:
    """A brush-local move's points, written row by row as its samples run.

    ``in_place``: the last points are the pipeline's alone, so the writes go into them, each
    row's value before kept to answer :meth:`before` and :meth:`undo`. Otherwise they are read
    until a sample moves something, and copied then (a move whose brush moves no strand copies
    nothing)."""

    def __init__(self, last: np.ndarray, in_place: bool) -> None:
        """One move of the points ``last``: written in place (its old rows logged) or into a
        copy made at the first change.

        Parameters
        ----------
        last : ndarray
            ``(V, 3)`` the points before the move.
        in_place : bool
            Whether ``last`` may be written (no one else holds it).
        """
        self.points = last
        self._last = last
        self._in_place = in_place
        self._copied = False
        self._log: list[tuple[np.ndarray, np.ndarray]] = []  # in place: (rows, their values before)

    def write(self, rows: np.ndarray, values: np.ndarray) -> None:
        """Set ``rows`` to ``values``; a write that changes no bit copies nothing.

        Parameters
        ----------
        rows : ndarray
            Vertex ids.
        values : ndarray
            ``(len(rows), 3)`` float32.
        """
        if not self._copied:
            if np.array_equal(self.points[rows].view(np.uint32), values.view(np.uint32)):
                return  # (the brush reached strands but moved none of them)
            if self._in_place:
                self._log.append((rows, self.points[rows]))  # (a copy: fancy indexing)
                self.points.flags.writeable = True
            else:
                self.points = self.points.copy()
                self._copied = True
        self.points[rows] = values

    def before(self, rows: np.ndarray) -> np.ndarray:
        """The points of ``rows`` (vertex ids, increasing, unique) before this move.

        Parameters
        ----------
        rows : ndarray
            Vertex ids, increasing, unique.

        Returns
        -------
        ndarray
            ``(len(rows), 3)`` float32.
        """
        if not self._in_place:
            return self._last[rows]
        out = self.points[rows]
        for written, was in reversed(self._log):
            at = np.searchsorted(rows, written)
            hit = at < rows.size
            hit[hit] = rows[at[hit]] == written[hit]
            out[at[hit]] = was[hit]
        return out

    def undo(self) -> None:
        """Back to the points before this move (a refused sample: none of the samples happened)."""
        for written, was in reversed(self._log):
            self.points[written] = was
        self._log.clear()
        self.done()

    def done(self) -> None:
        """The points read-only again (a groom may hold them)."""
        if self._in_place:
            self.points.flags.writeable = False
