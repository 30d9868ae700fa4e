"""The span of one axis a plot shows (frames across the dope sheet, frames and values in the graph
editor): zoom about a point, pan, fit inside limits, and the mapping to pixels. One helper so
the dope sheet and the graph editor navigate alike (wheel zoom about the cursor, middle-drag pan).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

Span = tuple[float, float]


def zoom(span: Span, factor: float, about: float) -> Span:
    """``span`` scaled by 1 / ``factor`` (> 1 zooms in) keeping the value ``about`` put."""
    lo, hi = span
    return about - (about - lo) / factor, about + (hi - about) / factor


def pan(span: Span, delta: float) -> Span:
    lo, hi = span
    return lo + delta, hi + delta


def fit(span: Span, first: float, last: float, least: float) -> Span | None:
    """``span`` kept inside ``first .. last`` and at least ``least`` wide (or the whole when
    shorter); None when it covers it all (nothing zoomed)."""
    whole = last - first
    width = min(max(span[1] - span[0], min(least, whole)), whole)
    if width >= whole:
        return None
    lo = min(max(span[0], first), last - width)
    return lo, lo + width


@dataclass(frozen=True)
class Axis:
    """A span laid across ``length`` pixels from ``start`` (``flip``: values grow upward, as a
    plot's vertical axis)."""

    span: Span
    start: float
    length: float
    flip: bool = False

    @property
    def per_px(self) -> float:
        """Values per pixel."""
        return (self.span[1] - self.span[0]) / max(self.length, 1e-9)

    def to_px(self, value: np.ndarray | float) -> np.ndarray | float:
        share = (np.asarray(value, dtype=np.float64) - self.span[0]) / self.per_px
        return self.start + self.length - share if self.flip else self.start + share

    def from_px(self, px: float) -> float:
        share = (self.start + self.length - px) if self.flip else (px - self.start)
        return self.span[0] + share * self.per_px
