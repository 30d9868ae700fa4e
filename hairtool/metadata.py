"""What a groom's source said about its space, time and curves, kept so that writing it back says the same.

A DCC's USD stage declares its up axis and unit (Blender: Z-up, metres), its time codes (an
animation sampled at time codes 1…48 at 24 per second) and how its curves are drawn (a cubic
Catmull-Rom basis, several prims under a head). hairtool's engines work on bare points; this
record rides along on :class:`~hairtool.groom.Groom` and :class:`~hairtool.groom.Animation` so
that ``hairtool convert`` and every writer put the groom back where it came from.

Defaults (a groom made by hairtool or read from a format that says nothing): Y-up, as the
samples, TressFX and the HAIR files are; ``meters_per_unit`` 0.01 (centimetres), which is
USD's own fallback when a stage leaves ``metersPerUnit`` out and the scale of TressFX and HAIR
models (a head is about 20 units across); one linear prim.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass, replace

from hairtool.errors import ParameterError, finite_number

UP_AXES = ("Y", "Z")
DEFAULT_UP_AXIS = "Y"
DEFAULT_METERS_PER_UNIT = 0.01
#: ``"linear"`` or the cubic basis of USD's BasisCurves.
BASES = ("linear", "bezier", "bspline", "catmullRom")
WRAPS = ("nonperiodic", "periodic", "pinned")
PURPOSES = ("default", "render", "proxy", "guide")  # UsdGeom's purpose tokens


def _positive(name: str, value: float | None) -> float | None:
    if value is None:
        return None
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise ParameterError(name, value, "a positive number") from None
    if not (math.isfinite(v) and v > 0):
        raise ParameterError(name, value, "a positive number")
    return v


def _finite(name: str, value: float | None) -> float | None:
    return None if value is None else finite_number(name, value)


@dataclass(frozen=True)
class CurvesPrim:
    """One source curves prim: its path, how many strands (in order) it holds and its basis.

    ``basis`` is ``"linear"`` or a cubic basis (``BASES``); the strands' points are the
    curve's control points either way.
    """

    path: str
    strands: int
    basis: str = "linear"
    wrap: str = "nonperiodic"
    purpose: str = "default"  # USD's purpose: "guide" marks guide curves beside the render hair

    def __post_init__(self) -> None:
        if not isinstance(self.path, str) or not self.path.startswith("/") or len(self.path) < 2:
            raise ParameterError("prim path", self.path, "an absolute prim path such as /Groom/Strands")
        if isinstance(self.strands, bool) or not isinstance(self.strands, int) or self.strands < 1:
            raise ParameterError("prim strands", self.strands, "a whole number ≥ 1")
        if self.basis not in BASES:
            raise ParameterError("basis", self.basis, f"one of {', '.join(BASES)}")
        if self.wrap not in WRAPS:
            raise ParameterError("wrap", self.wrap, f"one of {', '.join(WRAPS)}")
        if self.purpose not in PURPOSES:
            raise ParameterError("purpose", self.purpose, f"one of {', '.join(PURPOSES)}")

    @property
    def description(self) -> str:
        """``"linear"``, or e.g. ``"cubic catmullRom, pinned"`` as ``hairtool info`` prints it."""
        kind = "linear" if self.basis == "linear" else f"cubic {self.basis}"
        return kind if self.wrap == "nonperiodic" else f"{kind}, {self.wrap}"


@dataclass(frozen=True)
class Metadata:
    """Up axis, unit, time codes and curve prims of a groom's source (defaults when it had none).

    ``time_codes``: for an animation, the source's time code of each frame (None: 0…F−1);
    ``time_codes_per_second``, ``start_time_code``, ``end_time_code``: the stage's, when it
    authored them. ``curves``: the source prims in order, empty for one default prim.
    ``color_primvar``: the primvar the colours came from (``displayColor`` or Blender's ``color``).
    """

    up_axis: str = DEFAULT_UP_AXIS
    meters_per_unit: float = DEFAULT_METERS_PER_UNIT
    time_codes_per_second: float | None = None
    start_time_code: float | None = None
    end_time_code: float | None = None
    time_codes: tuple[float, ...] | None = None
    curves: tuple[CurvesPrim, ...] = ()
    color_primvar: str = "displayColor"

    def __post_init__(self) -> None:
        up = str(self.up_axis).upper()
        if up not in UP_AXES:
            raise ParameterError("up axis", self.up_axis, "Y or Z")
        object.__setattr__(self, "up_axis", up)
        object.__setattr__(self, "meters_per_unit", _positive("meters per unit", self.meters_per_unit))
        tcps = _positive("time codes per second", self.time_codes_per_second)
        object.__setattr__(self, "time_codes_per_second", tcps)
        start = _finite("start time code", self.start_time_code)
        end = _finite("end time code", self.end_time_code)
        if start is not None and end is not None and end < start:
            raise ParameterError("end time code", end, f"≥ the start time code {start}")
        object.__setattr__(self, "start_time_code", start)
        object.__setattr__(self, "end_time_code", end)
        if self.time_codes is not None:
            codes = tuple(float(t) for t in self.time_codes)
            if not codes or not all(math.isfinite(t) for t in codes):
                raise ParameterError(
                    "time codes", "non-finite or empty", "finite, strictly increasing numbers"
                )
            if any(b <= a for a, b in itertools.pairwise(codes)):
                raise ParameterError("time codes", codes[:8], "finite, strictly increasing numbers")
            object.__setattr__(self, "time_codes", codes)
        object.__setattr__(self, "curves", tuple(self.curves))
        paths = [c.path for c in self.curves]
        if len(set(paths)) != len(paths):
            raise ParameterError("prim paths", paths[:8], "one prim per path")
        if self.color_primvar not in ("displayColor", "color"):
            raise ParameterError("colour primvar", self.color_primvar, "displayColor or color")

    def with_(self, **changes) -> Metadata:
        """A copy with some fields changed (checked again)."""
        return replace(self, **changes)

    def for_strands(self, strand_count: int) -> Metadata:
        """The prims only while they still add up to the groom's strands (else one default prim)."""
        if self.curves and sum(c.strands for c in self.curves) != strand_count:
            return replace(self, curves=())
        return self
