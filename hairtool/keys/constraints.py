"""Frames the animator steers: pinned frames must be keys, excluded frames must not be.

Both are constraints on which segments a key set may use, so the DP stays exact under them by
running on a masked copy of the segment table: a segment (i, j) that skips a pinned frame
(i < p < j) or ends on an excluded one costs +inf. Every key set the DP can then return meets
the constraints, every key set that meets them keeps its cost, so the optimum over the masked
table is the constrained optimum, for every mode (count, tau, budget, worst-frame bound) and
both objectives. Moving a key is pinning the new frame and excluding the old one.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from hairtool.errors import ParameterError

F64 = NDArray[np.float64]
I64 = NDArray[np.int64]


def _frames(name: str, frames: ArrayLike) -> tuple[int, ...]:
    f = np.asarray(frames if frames is not None else [], dtype=np.float64).reshape(-1)
    if not np.all(np.isfinite(f)) or np.any(f != np.round(f)) or np.any(f < 0):
        raise ParameterError(name, f.tolist()[:8], "whole frame numbers >= 0")
    return tuple(sorted({int(v) for v in f}))


@dataclass(frozen=True)
class KeyConstraints:
    """Pinned and excluded frame numbers (0-based), each sorted and unique."""

    pins: tuple[int, ...] = ()
    excludes: tuple[int, ...] = ()

    def __post_init__(self) -> None:
        object.__setattr__(self, "pins", _frames("pin", self.pins))
        object.__setattr__(self, "excludes", _frames("exclude", self.excludes))
        both = sorted(set(self.pins) & set(self.excludes))
        if both:
            raise ParameterError("pin", both, "frames that are not also excluded")

    def __bool__(self) -> bool:
        return bool(self.pins or self.excludes)

    @classmethod
    def parse(cls, pins: str | None = None, excludes: str | None = None) -> KeyConstraints:
        """From command-line lists such as ``"10,55"`` and ``"30-34,40"`` (ranges inclusive).

        Parameters
        ----------
        pins : str, optional
            Frames that must be keys.
        excludes : str, optional
            Frames that must not be keys.

        Returns
        -------
        KeyConstraints
            The constraints (not yet checked against an animation: :meth:`check`).
        """
        return cls(parse_frames("pin", pins), parse_frames("exclude", excludes))

    def check(self, n_frames: int) -> KeyConstraints:
        """Frames inside the animation; the first and last frame are always keys, so they cannot
        be excluded; pins on every frame leave nothing to solve. Exclusions of every other frame
        are fine: the ends alone (and the pins) are then the one answer, in every mode.

        Parameters
        ----------
        n_frames : int
            The animation's frame count.

        Returns
        -------
        KeyConstraints
            These constraints (ParameterError naming the first bad frame otherwise).
        """
        for name, frames in (("pin", self.pins), ("exclude", self.excludes)):
            if frames and frames[-1] >= n_frames:
                raise ParameterError(name, list(frames), f"frames in [0, {n_frames - 1}]")
        ends = sorted({0, n_frames - 1} & set(self.excludes))
        if ends:
            raise ParameterError(
                "exclude", ends, f"frames other than the first (0) and the last ({n_frames - 1}), always keys"
            )
        if n_frames > 2 and set(range(1, n_frames - 1)) <= set(self.pins):
            pins = f"{len(self.pins)} pins"
            raise ParameterError("pin", pins, "at least one frame left for the solve to choose")
        return self

    def key_range(self, n_frames: int) -> tuple[int, int]:
        """The fewest and the most keys a key set under these constraints can have.

        Parameters
        ----------
        n_frames : int
            The animation's frame count.

        Returns
        -------
        tuple of (int, int)
            The fewest and the most keys.
        """
        required = len({0, n_frames - 1} | set(self.pins))
        return required, n_frames - len(self.excludes)

    def apply(self, table: F64) -> F64:
        """A copy of the ``(n, n)`` segment table with the forbidden segments at +inf (or the
        table itself when there is nothing to constrain).

        Parameters
        ----------
        table : ndarray
            ``(n, n)`` segment costs.

        Returns
        -------
        ndarray
            ``(n, n)`` float64.
        """
        if not self:
            return table
        n = table.shape[0]
        self.check(n)
        c = np.array(table, dtype=np.float64)
        if self.excludes:
            x = np.asarray(self.excludes)
            c[:, x] = np.inf
            c[x, :] = np.inf
        if self.pins:
            # the next pin after each frame i: a segment (i, j) skips a pin when j is past it
            nxt = np.full(n, n, dtype=np.int64)
            p = np.asarray(self.pins)
            idx = np.searchsorted(p, np.arange(n), side="right")
            has = idx < p.size
            nxt[has] = p[idx[has]]
            cols = np.arange(n)
            c[cols[None, :] > nxt[:, None]] = np.inf
        return c

    def allows(self, keys: ArrayLike) -> bool:
        """Whether a key set meets the constraints.

        Parameters
        ----------
        keys : array_like
            Key frames.

        Returns
        -------
        bool
            True where every pin is a key and no excluded frame is.
        """
        k = set(np.asarray(keys, dtype=np.int64).tolist())
        return set(self.pins) <= k and not (set(self.excludes) & k)

    def to_dict(self) -> dict:
        return {"pins": list(self.pins), "excludes": list(self.excludes)}


def parse_frames(name: str, text: str | None) -> tuple[int, ...]:
    """``"3,10-12"`` → (3, 10, 11, 12); empty or None → ().

    Parameters
    ----------
    name : str
        The option, named in a refusal.
    text : str or None
        The list.

    Returns
    -------
    tuple of int
        The frames, ascending, each once.
    """
    if text is None or not text.strip():
        return ()
    out: set[int] = set()
    for part in text.split(","):
        part = part.strip()
        lo, sep, hi = part.partition("-")
        try:
            a = int(lo)
            b = int(hi) if sep else a
        except ValueError:
            raise ParameterError(name, text, "frame numbers and ranges such as 10,30-34") from None
        if a < 0 or b < a or b - a > 10_000_000:
            raise ParameterError(name, part, "frames >= 0, ranges from low to high")
        out.update(range(a, b + 1))
    return tuple(sorted(out))
