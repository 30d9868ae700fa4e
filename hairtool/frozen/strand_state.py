"""What the pipeline keeps per strand of the stroked state, as one value.

Masked (``locked``), clump strength, the rest strand each comes from (``origin``, −1 for a
planted one), selected and hidden. A brush that removes strands keeps the rows of those that
stay (:meth:`StrandState.subset`), one that plants appends rows (:meth:`StrandState.append`);
a brush-local move works on the rows under the brush and writes them back
(:meth:`StrandState.scatter`). The arrays are never written in place: every change makes new
ones, so a state held by a snapshot or a refused batch stays as it was.
"""

from __future__ import annotations

from dataclasses import dataclass, fields, replace

import numpy as np


@dataclass(frozen=True, eq=False)
class StrandState:
    """Per-strand state, ``(S,)`` arrays of one length: see the module docstring."""

    locked: np.ndarray
    clump_strength: np.ndarray
    origin: np.ndarray
    selected: np.ndarray
    hidden: np.ndarray

    @classmethod
    def fresh(cls, n: int) -> StrandState:
        """``n`` rest strands: unmasked, clump strength 1, in order, selected, shown."""
        return cls(
            np.zeros(n, bool), np.ones(n), np.arange(n, dtype=np.int64), np.ones(n, bool), np.zeros(n, bool)
        )

    def arrays(self) -> tuple[np.ndarray, ...]:
        """The arrays in field order."""
        return tuple(getattr(self, f.name) for f in fields(self))

    def __len__(self) -> int:
        return len(self.locked)

    def with_(self, **changes: np.ndarray) -> StrandState:
        """This state with some arrays replaced."""
        return replace(self, **changes)

    def subset(self, rows: np.ndarray) -> StrandState:
        """The state of the strands ``rows`` (indices or a mask), in that order.

        Parameters
        ----------
        rows : numpy.ndarray
            Strand indices, or an ``(S,)`` bool mask.

        Returns
        -------
        StrandState
            New arrays.
        """
        return StrandState(*(a[rows] for a in self.arrays()))

    def append(self, m: int) -> StrandState:
        """``m`` planted strands after these: unmasked, clump strength 1, no rest strand, selected, shown.

        Parameters
        ----------
        m : int
            How many strands were appended.

        Returns
        -------
        StrandState
            New arrays, ``m`` rows longer.
        """
        fill = (np.zeros(m, bool), np.ones(m), np.full(m, -1, np.int64), np.ones(m, bool), np.zeros(m, bool))
        return StrandState(*(np.concatenate([a, b]) for a, b in zip(self.arrays(), fill, strict=True)))

    def copy(self) -> StrandState:
        """A state with copies of the arrays."""
        return StrandState(*(a.copy() for a in self.arrays()))

    def scatter(self, rows: np.ndarray, part: StrandState, was: StrandState) -> StrandState:
        """This state with ``part`` written at ``rows``, for each array ``part`` holds anew
        (``was``: the subset ``part`` started from; an array it still shares is left alone)."""
        changes = {}
        for f in fields(self):
            new = getattr(part, f.name)
            if new is not getattr(was, f.name):
                full = getattr(self, f.name).copy()
                full[rows] = new
                changes[f.name] = full
        return replace(self, **changes) if changes else self

    def lock(self, only_selected: bool, away: np.ndarray | None, mask: bool = True) -> np.ndarray:
        """``(S,)`` the strands a sample leaves as they are: masked (``mask``), hidden, facing away
        from its camera (``away``), and with ``only_selected`` the unselected ones."""
        locked = self.locked | self.hidden if mask else self.hidden
        if away is not None:
            locked = locked | away
        if only_selected:
            locked = locked | ~self.selected
        return locked
