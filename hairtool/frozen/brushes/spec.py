"""What a brush declares (:class:`BrushSpec`) and the one interface every brush implements
(:class:`Brush`), over the stroke context the pipeline hands it (:class:`StrokeContext`).

A brush module holds one spec, its kernels and their numpy twins, and a ``BRUSH`` object: the
registry (:mod:`.registry`) finds it there, the pipeline dispatches to it, the stroke log and
the studio read its spec. Nothing else names the brush.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from hairtool.errors import ParameterError
from hairtool.frozen.brushes.sample import check_sample
from hairtool.frozen.strand_state import StrandState
from hairtool.groom import Groom


@dataclass(frozen=True)
class Param:
    """One field of :class:`~hairtool.frozen.brushes.sample.BrushSample` a brush reads beyond
    cursor, radius and strength: its type, range (``low`` exclusive where ``open_low``), default,
    the stroke log's name for it, and the words a refusal names."""

    field: str
    kind: type
    low: float
    high: float
    default: float
    log_name: str
    expects: str
    open_low: bool = False

    def check(self, value: object) -> None:
        """ParameterError naming the field where ``value`` is not of the type or out of range
        (a ``bool`` field: True or False, nothing else)."""
        if self.kind is bool:
            if not isinstance(value, bool | np.bool_):
                raise ParameterError(self.field, value, self.expects)
            return
        number = isinstance(value, int | float | np.integer | np.floating) and not isinstance(value, bool)
        if self.kind is int and not isinstance(value, int | np.integer):
            number = False
        v = float(value) if number else math.nan  # type: ignore[arg-type]
        above = v > self.low if self.open_low else v >= self.low
        if not (number and math.isfinite(v) and above and v <= self.high):
            raise ParameterError(self.field, value, self.expects)


@dataclass(frozen=True)
class Studio:
    """How the studio shows a brush: its artist's name, key, tooltip and default strength;
    for a signed brush the labels of its two directions and of the toggle between them, and
    ``starts_second``: it starts in the second direction (where the first shows nothing on a new
    groom: every strand already clumps fully); ``place``: its place in the toolbar (last: after
    the brushes that say where they go)."""

    label: str
    shortcut: str
    tip: str
    strength: float
    signs: tuple[str, str] | None = None
    sign_label: str | None = None
    place: int = 1000
    starts_second: bool = False


@dataclass(frozen=True)
class BrushSpec:
    """What a brush is, for everything that is not its operation.

    ``order``: its place in the toolbar and in the stroke logs' brush tables (existing files
    keep their numbers). ``signed``: strength in [-1, 1] (else [0, 1]). ``moves_points``: it
    moves vertices (so they may collide with the head). ``changes_strands``: it adds or removes
    strands or vertices. ``needs_surface``: it needs the head mesh. ``local``: a move may run on
    the strands under it only (:mod:`hairtool.frozen.local`). ``takes_strength``: its strength
    is an amount (not only a direction, on or off). ``uses_pressure``: a pen's pressure scales
    its strength by default. ``needs_direction``: a move without motion does nothing.
    ``keeps_stroke``: it remembers state over a stroke's samples (:class:`StrokeMemory`).
    ``follows_selection``: "affect selection only" keeps it to the selected strands (the
    selection brush makes the selection, and planting brushes make new strands).
    ``starts_anew``: a plain stroke replaces what the brush paints (Blender's Selection Paint:
    the selection is cleared at the stroke's first sample, then what it touches is selected), so
    its effect reaches every shown strand, not only those under it. ``straightens``: it takes
    out bends (smooth): on straight strands it has nothing to do, as in Blender. ``params``: its
    own sample fields."""

    name: str
    order: int
    studio: Studio
    signed: bool = False
    moves_points: bool = True
    changes_strands: bool = False
    needs_surface: bool = False
    local: bool = False
    takes_strength: bool = True
    uses_pressure: bool = True
    needs_direction: bool = False
    keeps_stroke: bool = False
    follows_selection: bool = True
    starts_anew: bool = False
    straightens: bool = False
    params: tuple[Param, ...] = ()


@dataclass
class StrokeMemory:
    """What a brush keeps over one stroke (a snake hook's hooked strands): one entry per start
    sample (the stroke's and its mirror's), used in turn by the later samples."""

    entries: list = field(default_factory=list)
    next: int = 0
    starting: bool = False  # the last sample was a start

    def frozen(self) -> tuple[tuple, int, bool]:
        return (tuple(self.entries), self.next, self.starting)

    @classmethod
    def of(cls, state: tuple[tuple, int, bool]) -> StrokeMemory:
        return cls(list(state[0]), state[1], state[2])


@dataclass
class StrokeContext:
    """What one sample works with besides the groom: the per-strand state (replaced, never
    written in place), the strands facing away from its camera, the head's surface, the
    scalp's centre (computed when first asked), the stroke's memory, and whether the groom
    counts as 2-D (None: ask the groom)."""

    state: StrandState
    away: np.ndarray | None = None
    surface: object | None = None
    centre_of: Callable[[], np.ndarray] | None = None
    memory: StrokeMemory = field(default_factory=StrokeMemory)
    planar: bool | None = None

    @property
    def scalp_centre(self) -> np.ndarray:
        assert self.centre_of is not None
        return self.centre_of()

    def lock(self, sample, mask: bool = True) -> np.ndarray:
        """``(S,)`` the strands ``sample`` leaves as they are (:meth:`StrandState.lock`)."""
        return self.state.lock(bool(getattr(sample, "only_selected", False)), self.away, mask)

    def keep(self, g: Groom, kept: np.ndarray) -> Groom:
        """Only the strands ``kept`` (indices) remain, their state with them."""
        self.state = self.state.subset(kept)
        return g.subset(kept)

    def planted(self, m: int) -> None:
        """``m`` strands were appended (planted: unmasked, clump strength 1, selected, shown)."""
        self.state = self.state.append(m)


class Brush:
    """One brush: its spec and its operation. ``apply`` runs one sample on the groom ``g``
    (the stroked state so far) and returns the groom after it, changing ``ctx.state`` where it
    paints, removes or plants; ``reference`` is its numpy twin (None where the brush has no
    kernel of its own), compared with it byte for byte by the brush contract test."""

    spec: BrushSpec

    def check(self, sample) -> None:
        """ParameterError naming the first bad field of ``sample``."""
        check_sample(sample)

    def apply(self, ctx: StrokeContext, g: Groom, sample) -> Groom:
        raise TypeError(f"{type(self).__name__} has no operation")

    def reference(self, ctx: StrokeContext, g: Groom, sample) -> Groom | None:
        return None

    def reaches_every_strand(self, sample) -> bool:
        """Whether ``sample`` changes strands beyond those under it (a new selection clears the
        others): a brush-local move then runs it on the whole groom."""
        return False


class StrandMove(Brush):
    """A brush that moves the vertices of the unlocked strands under it and nothing else:
    ``move(groom, sample, locked, centre)`` (numba) and ``move_reference`` (numpy)."""

    move: Callable
    move_reference: Callable

    def apply(self, ctx: StrokeContext, g: Groom, sample) -> Groom:
        return self.move(g, sample, ctx.lock(sample), ctx.scalp_centre)

    def reference(self, ctx: StrokeContext, g: Groom, sample) -> Groom | None:
        return self.move_reference(g, sample, ctx.lock(sample), ctx.scalp_centre)
