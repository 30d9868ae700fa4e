"""One mouse move of one brush (:class:`BrushSample`) and the checks every sample passes.

What a sample may hold is the same for every brush; what its strength may be (signed or not)
and which fields it must fill come from the brush's spec (:mod:`.registry`).
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from hairtool.errors import ParameterError
from hairtool.frozen.brushes import registry
from hairtool.frozen.brushes.falloff import LUT_SIZE

MAX_COUNT = 1000  # strands one add sample may plant


@dataclass(frozen=True)
class BrushSample:
    """One mouse move of one brush (groom units); ``lut`` from
    :func:`~hairtool.frozen.brushes.falloff.falloff_lut`; ``view`` the camera's viewing
    direction (from the eye into the scene): with it only the strands facing the camera are
    touched; None: every strand. ``start``: the first sample of a stroke (a snake hook hooks its
    strands there). ``collide``: with a head surface, no vertex the sample moves ends inside it
    (:mod:`hairtool.frozen.collide`). ``count`` and ``seed``: the strands an add sample plants,
    and the seed of where (density's too); ``spacing``: the distance a density sample leaves
    between roots. ``only_selected``: the strands not selected are left as if locked
    (:mod:`hairtool.frozen.selection`). ``pressure``: the pen's pressure in [0, 1] at this move
    (1 for a mouse), already applied to ``radius`` and ``strength`` where the brush's pressure
    toggles said so: kept so a stroke log records it. ``any_segment``: a delete sample removes
    the strands with any segment under it (Blender's rule), else those whose root is (the rule
    of every log written before the choice, so its default). ``new_selection``: a select sample
    that starts a new selection: the shown strands are deselected before it selects (a plain
    stroke's first sample, as Blender's Selection Paint; not its mirror, which adds to what the
    first selected); False adds to the selection (what every log written before it meant).
    ``visible``: with a ``view``, the strands kept are those the head does not hide from the
    camera under the brush (:mod:`~hairtool.frozen.brushes.sight`: the studio's rule, needing a
    head mesh), else those whose root normal faces the camera (the rule of every log written
    before it, so its default; the rule without a head mesh too). ``eye``: a perspective
    camera's eye (the studio records it in its 3-D view; None for an orthographic camera, and
    in every log written before it): by sight, each vertex's ray goes to it rather than against
    ``view``, and add and density plant where the line from it through ``cursor`` meets the
    head."""

    brush: str
    cursor: tuple[float, float, float]
    direction: tuple[float, float, float]
    radius: float
    strength: float
    lut: tuple[float, ...]
    view: tuple[float, float, float] | None = None
    start: bool = False
    collide: bool = True
    count: int = 1
    seed: int = 0
    spacing: float = 0.0
    only_selected: bool = False
    pressure: float = 1.0
    any_segment: bool = False
    new_selection: bool = False
    visible: bool = False
    eye: tuple[float, float, float] | None = None

    def mirrored(self, plane_x: float) -> BrushSample:
        """The sample across the plane x = ``plane_x``, the second sample of the same move (so
        it never starts a new selection: that would clear what the first one selected)."""
        c, d = self.cursor, self.direction
        cursor, direction = (2.0 * plane_x - c[0], c[1], c[2]), (-d[0], d[1], d[2])
        view = mirrored_view(self.view)
        eye = mirrored_eye(self.eye, plane_x)
        return replace(self, cursor=cursor, direction=direction, view=view, new_selection=False, eye=eye)


def mirrored_view(view: tuple[float, float, float] | None) -> tuple[float, float, float] | None:
    """A viewing direction mirrored across a plane x = const (None stays None)."""
    return None if view is None else (-view[0], view[1], view[2])


def mirrored_eye(eye: tuple[float, float, float] | None, plane_x: float) -> tuple[float, float, float] | None:
    """An eye mirrored across the plane x = ``plane_x`` (None stays None)."""
    return None if eye is None else (2.0 * plane_x - eye[0], eye[1], eye[2])


def _check_vector(name: str, value: object, nonzero: bool) -> tuple[float, float, float] | None:
    """None, or three finite numbers (not all zero where ``nonzero``); else a ParameterError
    naming ``name``."""
    if value is None:
        return None
    try:
        v = np.asarray(value, dtype=np.float64) if not isinstance(value, str | bytes) else np.zeros(0)
    except (TypeError, ValueError):
        v = np.zeros(0)
    if v.shape != (3,) or not np.all(np.isfinite(v)) or (nonzero and not np.any(v != 0)):
        what = "null or three finite numbers" + (", not all zero" if nonzero else "")
        raise ParameterError(name, value, what)
    return (float(v[0]), float(v[1]), float(v[2]))


def check_view(view: object) -> tuple[float, float, float] | None:
    """None, or three finite numbers not all zero (ParameterError naming ``view``)."""
    return _check_vector("view", view, nonzero=True)


def check_eye(eye: object) -> tuple[float, float, float] | None:
    """None, or three finite numbers: a perspective camera's eye (ParameterError naming ``eye``)."""
    return _check_vector("eye", eye, nonzero=False)


def check_sample(sample: BrushSample) -> BrushSample:
    """The sample itself, or ParameterError naming its first bad field.

    Parameters
    ----------
    sample : BrushSample
        A sample of any registered brush but align (whose samples are AlignSamples).

    Returns
    -------
    BrushSample
        ``sample``, unchanged.
    """
    names = registry.names()
    if sample.brush not in names or sample.brush == "align":
        raise ParameterError("brush", sample.brush, "one of " + ", ".join(n for n in names if n != "align"))
    spec = registry.spec_of(sample.brush)
    for name in ("cursor", "direction"):
        v = np.asarray(getattr(sample, name), dtype=np.float64)
        if v.shape != (3,) or not np.all(np.isfinite(v)):
            raise ParameterError(name, getattr(sample, name), "three finite numbers")
    if not np.isfinite(sample.radius) or sample.radius <= 0:
        raise ParameterError("radius", sample.radius, "a positive finite distance")
    check_view(sample.view)
    low = -1.0 if spec.signed else 0.0
    if not np.isfinite(sample.strength) or not low <= sample.strength <= 1.0:
        raise ParameterError("strength", sample.strength, f"a number in [{low:g}, 1]")
    c = sample.count
    if isinstance(c, bool) or not isinstance(c, int | np.integer) or not 1 <= c <= MAX_COUNT:
        raise ParameterError("count", c, f"a whole number of strands in [1, {MAX_COUNT}]")
    s = sample.seed
    if isinstance(s, bool) or not isinstance(s, int | np.integer) or not 0 <= s < 2**32:
        raise ParameterError("seed", s, "a whole number in [0, 2^32)")
    for param in spec.params:  # the brush's own fields, as its spec bounds them
        param.check(getattr(sample, param.field))
    if len(sample.lut) != LUT_SIZE:
        raise ParameterError("falloff", f"{len(sample.lut)} samples", f"{LUT_SIZE}")
    check_pressure(sample.pressure)
    check_flag("visible", sample.visible)
    check_eye(sample.eye)
    return sample


def check_flag(name: str, value: object) -> bool:
    """True or False (ParameterError naming ``name`` for anything else)."""
    if not isinstance(value, bool | np.bool_):
        raise ParameterError(name, value, "true or false")
    return bool(value)


def check_pressure(pressure: object) -> float:
    """A pen's pressure: a number in [0, 1] (ParameterError naming ``pressure``)."""
    number = isinstance(pressure, int | float | np.integer | np.floating) and not isinstance(pressure, bool)
    if not number or not 0.0 <= float(pressure) <= 1.0:  # (NaN fails the comparison)
        raise ParameterError("pressure", pressure, "a number in [0, 1]")
    return float(pressure)
