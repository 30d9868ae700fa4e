"""The brush an artist grooms with, as settings: which brush, its size and strength (each brush
remembers its own), grow or shrink, paint or erase, the falloff curve, X symmetry and "front faces
only"; and the pipeline samples that one mouse move of it gives.

Plain Python (no Qt): the scene holds one and the tool dock edits it through the scene.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from hairtool.errors import ParameterError
from hairtool.frozen.brushes import (
    BrushSample,
    any_within,
    falloff_lut,
    mirrored_eye,
    mirrored_view,
    registry,
)
from hairtool.frozen.pipeline import AlignSample
from hairtool.frozen.sample_schema import ALIGN, BRUSH

#: The brushes as the studio shows them, read from their specs (each brush module's
#: :class:`~hairtool.frozen.brushes.spec.Studio` row): in the toolbar's order, their artist's
#: names and Blender-like keys (Blender's sculpt mode: S smooth, M mask, I inflate ≈ puff, P
#: pinch ≈ clump, K snake hook; X deletes as in Blender's editors; pinch, with P taken by clump,
#: is Shift+P; slide G as Blender's grab; add Shift+A as Blender's Add menu; select W, Blender's
#: key for its select tools; align Shift+C, since A selects all as in Blender; the others by
#: their initial), tooltips and default strengths.
_SPECS = sorted(registry.specs(), key=lambda spec: (spec.studio.place, spec.order))
LABELS = {spec.name: spec.studio.label for spec in _SPECS}
SHORTCUTS = {spec.name: spec.studio.shortcut for spec in _SPECS}
TIPS = {spec.name: spec.studio.tip for spec in _SPECS}
#: Brushes with a signed strength: (label of > 0, label of < 0), and the toggle's label.
SIGNED = {spec.name: spec.studio.signs for spec in _SPECS if spec.signed and spec.studio.signs}
SIGN_LABELS = {spec.name: spec.studio.sign_label for spec in _SPECS if spec.signed and spec.studio.sign_label}
DEFAULT_STRENGTH = {spec.name: spec.studio.strength for spec in _SPECS}
#: The direction each signed brush starts in (True: its second, shrink or erase).
DEFAULT_SUBTRACT = {name: registry.spec_of(name).studio.starts_second for name in SIGNED}
#: Brushes whose strength is only a direction (paint or erase, on or off): a pen's pressure
#: never scales it (a light touch would otherwise erase, or do nothing).
STRENGTHLESS = tuple(spec.name for spec in _SPECS if not spec.takes_strength)
#: The smallest share of its radius a brush keeps under the lightest touch (a radius is never 0).
MIN_PRESSURE_RADIUS = 0.05
FALLOFF_LABELS = {"smooth": "Smooth", "linear": "Linear", "constant": "Constant"}

Falloff = str | tuple[tuple[float, float], ...]


def brushes() -> tuple[str, ...]:
    """The brushes the engine has, in the toolbar's order."""
    return tuple(LABELS)


def check_falloff(falloff: str | Sequence[Sequence[float]]) -> Falloff:
    """A preset name, or curve points as a tuple of (t, w) pairs; ParameterError otherwise."""
    falloff_lut(falloff)  # the engine's own check
    if isinstance(falloff, str):
        return falloff
    return tuple((float(t), float(w)) for t, w in falloff)


@dataclass
class BrushTool:
    """See the module docstring. ``mirror_x`` None: the plane through the scalp's centre."""

    brush: str = "align"
    radius: dict[str, float] = field(default_factory=dict)
    strength: dict[str, float] = field(default_factory=lambda: dict(DEFAULT_STRENGTH))
    subtract: dict[str, bool] = field(default_factory=lambda: dict(DEFAULT_SUBTRACT))
    falloff: Falloff = "smooth"
    symmetry: bool = False
    mirror_x: float | None = None
    front_only: bool = True
    #: per brush: with a head mesh, no vertex the brush moves ends inside it (on by default)
    collide: dict[str, bool] = field(default_factory=lambda: dict.fromkeys(brushes(), True))
    add_count: int = 2  # strands the add brush plants per mouse move
    spacing: float = 0.05  # between roots, the density brush's (groom units)
    #: delete takes the strands with any segment under the brush (Blender's rule), else only
    #: those whose root is
    delete_any_segment: bool = True
    align_mode: str = "paper"
    only_selected: bool = True  # brushes keep to the selected strands (Blender's selection toggle)
    #: per brush: a pen's pressure scales the radius / the strength (Blender's pressure buttons;
    #: strength on by default as in Blender's sculpt brushes, radius off)
    pressure_radius: dict[str, bool] = field(default_factory=lambda: dict.fromkeys(brushes(), False))
    pressure_strength: dict[str, bool] = field(
        default_factory=lambda: {b: b not in STRENGTHLESS for b in brushes()}
    )
    _lut: tuple[Falloff, tuple[float, ...]] | None = field(default=None, repr=False)

    def reset_radius(self, radius: float) -> None:
        """Every brush at one size (a new groom)."""
        self.radius = dict.fromkeys(brushes(), float(radius))
        self.spacing = 0.2 * float(radius)

    def set_brush(self, name: str) -> None:
        if name not in brushes():
            raise ParameterError("brush", name, "one of " + ", ".join(brushes()))
        self.brush = name

    def lut(self) -> tuple[float, ...]:
        """The falloff as the engine's table (cached: a table per mouse move would cost)."""
        if self._lut is None or self._lut[0] != self.falloff:
            self._lut = (self.falloff, tuple(falloff_lut(self.falloff).tolist()))
        return self._lut[1]

    def shift_adds(self) -> bool:
        """Shift+drag adds with the current brush (select: a plain drag starts a new selection,
        Shift+drag adds to it, as in Blender) instead of panning the view."""
        return bool(registry.spec_of(self.brush).starts_anew)

    def radius_at(self, pressure: float = 1.0) -> float:
        """The current brush's radius under a pen's ``pressure`` (the radius itself with the
        brush's radius toggle off, or at full pressure)."""
        r = self.radius[self.brush]
        if not self.pressure_radius.get(self.brush, False):
            return r
        return r * max(float(pressure), MIN_PRESSURE_RADIUS)

    def strength_at(self, pressure: float = 1.0) -> float:
        """The current brush's strength (unsigned) under a pen's ``pressure``."""
        s = self.strength[self.brush]
        if self.brush in STRENGTHLESS or not self.pressure_strength.get(self.brush, False):
            return s
        return s * float(pressure)

    def signed_strength(self, invert: bool = False, pressure: float = 1.0) -> float:
        """The current brush's strength, negative for shrink / erase (``invert``: Ctrl held)."""
        s = self.strength_at(pressure)
        if self.brush in SIGNED and self.subtract.get(self.brush, False) != bool(invert):
            return -s
        return s

    def samples(
        self,
        cursor: Sequence[float],
        direction: Sequence[float],
        view: Sequence[float] | None,
        plane_x: float,
        invert: bool = False,
        start: bool = False,
        pressure: float = 1.0,
        add: bool = False,
        eye: Sequence[float] | None = None,
    ) -> list[AlignSample | BrushSample]:
        """The samples of one mouse move at ``cursor`` (groom units), mirrored one right after it
        with symmetry on. ``direction``: the mouse's motion in the world (comb needs one: none
        while it stands still). ``view``: the camera's direction, given to the engine with
        "front faces only". ``start``: the stroke's first move (a snake hook hooks there).
        ``pressure``: a pen's, in [0, 1] (1 for a mouse), scaling the radius and the strength as
        the brush's toggles say; the samples carry it for the stroke log. ``add``: Shift held,
        so a brush that starts anew (select: a plain stroke is a new selection) adds instead.
        ``eye``: a perspective camera's eye (None: orthographic), which every sample records:
        by sight its rays go there, and add and density plant on the line from it through the
        cursor (:class:`~hairtool.frozen.brushes.BrushSample`)."""
        p = min(max(float(pressure), 0.0), 1.0)
        c = tuple(float(x) for x in cursor)
        d = tuple(float(x) for x in direction)
        v = None if view is None or not self.front_only else tuple(float(x) for x in view)
        r, name = self.radius_at(p), self.brush
        hit = self.collide.get(name, True)
        only = self.only_selected and name != "select"
        # the sample's fields by name (hairtool.frozen.sample_schema): those a brush does not
        # use (add's count, density's spacing, delete's rule, a snake hook's start) keep their
        # defaults there
        # front faces only by sight (the head hides what lies behind it; hairtool.frozen.brushes.sight)
        e = None if eye is None else tuple(float(x) for x in eye)
        common = {
            "cursor": c, "radius": r, "view": v, "collide": hit, "only_selected": only, "pressure": p,
            "visible": v is not None, "eye": e,
        }  # fmt: skip
        if name == "align":
            first = ALIGN.make(intensity=self.strength_at(p), mode=self.align_mode, **common)
            if not self.symmetry:
                return [first]
            mirror = (2.0 * plane_x - c[0], c[1], c[2])
            return [first, first._replace(cursor=mirror, view=mirrored_view(v), eye=mirrored_eye(e, plane_x))]
        spec = registry.spec_of(name)
        if spec.needs_direction and math.hypot(*d) == 0.0:
            return []
        strength = self.signed_strength(invert, p)
        anew = start and spec.starts_anew and strength > 0 and not add
        first = BRUSH.make(
            brush=name, direction=d, strength=strength, lut=self.lut(), start=start,
            count=self.add_count, spacing=self.spacing, any_segment=self.delete_any_segment,
            new_selection=anew, **common,
        )  # fmt: skip
        return [first, first.mirrored(plane_x)] if self.symmetry else [first]

    def touches(
        self, points: np.ndarray, cursor: Sequence[float], plane_x: float, pressure: float = 1.0
    ) -> bool:
        """Whether a move at ``cursor`` (and its mirror) reaches any of ``points`` ``(V, 3)``
        (at the radius a pen's ``pressure`` gives)."""
        r = self.radius_at(pressure)
        centres = [np.asarray(cursor, np.float64)]
        if self.symmetry:
            centres.append(np.array([2.0 * plane_x - centres[0][0], centres[0][1], centres[0][2]]))
        return any(any_within(points, c, r) for c in centres)
