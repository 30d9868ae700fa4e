"""Stroke logs as files: an artist's strokes, replayed by a pipeline on a new version of a groom.

A stroke log is a JSON list of strokes, in groom units::

    [{"brush": "comb", "falloff": "smooth", "symmetry": "x", "mirror_x": 0.0,
      "params": {}, "samples": [{"cursor": [x, y, z], "direction": [dx, dy, dz],
                                 "radius": r, "strength": s, "view": [vx, vy, vz],
                                 "pressure": p}, ...]}, ...]

- ``brush``: ``align`` (the paper's UserAlign; ``params.mode`` "paper" or "preserve-length",
  ``strength`` its intensity, no direction needed), ``comb``, ``smooth``, ``length`` (a signed
  strength: > 0 grows, < 0 shrinks, as a fraction of the strand's length at the brush centre),
  ``puff``, ``mask`` (> 0 locks the strands touched, < 0 frees them) or ``clump`` (> 0 paints
  clumping on, < 0 off: each strand's clump strength moves toward 1 or 0), ``delete`` (removes
  the strands whose root lies within the radius; strength > 0, falloff ignored), ``pinch`` (> 0
  gathers toward the brush centre, < 0 spreads) or ``snake_hook`` (the strands whose tip lies
  within the radius at the stroke's first sample follow the cursor; ``direction`` is the
  cursor's motion since the sample before), ``slide`` (roots slide along the head; needs one)
  or ``add`` (plants ``params.count`` strands per sample, default 1, around the head's point
  nearest the cursor, drawn from ``params.seed``, default 0, and the cursor; needs a head) or
  ``density`` (removes and plants strands under the brush until the roots are
  ``params.spacing`` apart, in groom units; ``params.seed`` as add's; needs a head) or
  ``select`` (> 0 selects the strands touched, < 0 deselects them; hidden strands stay as
  they are).
- ``only_selected`` (per stroke, optional, default false): the stroke leaves the strands that
  are not selected as they are (the studio's "Affect selection only"). Hidden strands are left
  alone by every stroke.
- ``collision`` (per stroke, optional, default true): with a head surface (``--scalp``), no
  vertex the stroke moves ends inside it; false: strands may pass through the head.
- ``start`` (per sample, optional): true where a stroke begins (a snake hook hooks its strands
  there); missing: true for a stroke's first sample only. Written for snake hooks, whose
  mirrored first sample is a start too.
- ``pressure`` (per sample, optional, default 1.0): the pen's pressure in [0, 1] at that
  sample (a mouse presses 1.0). ``radius`` and ``strength`` are what the brush used there, the
  pressure already applied (the studio scales them by it where the brush's pressure toggles
  are on), so a replay reads them as they are and gives the same bytes; the pressure says how
  the stroke was drawn.
- ``view`` (per sample, optional): the camera's viewing direction, from the eye into the scene;
  only the strands facing that camera are touched. null or missing (older logs): every strand.
- ``falloff``: ``smooth``, ``linear``, ``constant``, or a curve ``[[t, w], ...]`` over t =
  distance / radius from 0 to 1 (align keeps the paper's own weighting and ignores it).
- ``symmetry``: ``"x"`` mirrors every sample across the plane x = ``mirror_x`` (default: the
  centre of the sphere fitted to the roots), into the same stroke; null for none.

Besides strokes, a log holds selection steps (:mod:`hairtool.frozen.selection`), each an
object with a ``selection`` field instead of ``brush``::

    {"selection": "all"}  {"selection": "none"}  {"selection": "invert"}
    {"selection": "hide_selected"}  {"selection": "hide_unselected"}  {"selection": "reveal"}
    {"selection": "box", "mode": "set", "matrix": [16 numbers], "rect": [x0, y0, x1, y1],
     "view": [vx, vy, vz]}

- ``box``: the strands with a point inside the rectangle ``rect`` (normalised device
  coordinates, −1 … 1, y up) of the camera whose world-to-clip matrix is ``matrix`` (4×4,
  row-major); ``mode`` ``set`` (default), ``add`` or ``subtract``; ``view`` as a sample's.

Fields a reader does not know are ignored and missing optional ones take their defaults, so
logs written by older and newer versions stay readable.
"""

from __future__ import annotations

import json
import math
import os
import sys
from collections.abc import Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np

from hairtool.errors import FormatError, ParameterError
from hairtool.frozen.align import MODES
from hairtool.frozen.brushes import (
    BRUSHES,
    MAX_FALLOFF_POINTS,
    BrushSample,
    check_pressure,
    check_sample,
    check_view,
    falloff_lut,
    mirrored_view,
)
from hairtool.frozen.pipeline import AlignSample
from hairtool.frozen.selection import SelectionSample, check_selection
from hairtool.io import user_text
from hairtool.io.atomic import atomic_open

MAX_LOG_BYTES = 256 * 1024**2


@dataclass(frozen=True)
class StrokeSample:
    cursor: tuple[float, float, float]
    radius: float
    strength: float
    direction: tuple[float, float, float] = (0.0, 0.0, 0.0)
    view: tuple[float, float, float] | None = None
    start: bool | None = None  # None: the stroke's first sample starts it
    pressure: float = 1.0  # the pen's, already applied to radius and strength (1: a mouse's)


@dataclass(frozen=True)
class Stroke:
    """One press-drag-release of one brush."""

    brush: str
    samples: tuple[StrokeSample, ...]
    falloff: str | tuple[tuple[float, float], ...] = "smooth"
    symmetry: str | None = None
    mirror_x: float | None = None
    params: dict = field(default_factory=dict)
    collision: bool = True  # with a head surface, no vertex the stroke moves ends inside it
    only_selected: bool = False  # the unselected strands are left as they are

    def validate(self) -> Stroke:
        if self.brush not in BRUSHES:
            raise ParameterError("brush", self.brush, " ".join(BRUSHES))
        if self.symmetry not in (None, "x"):
            raise ParameterError("symmetry", self.symmetry, '"x" or null')
        if self.mirror_x is not None and not math.isfinite(self.mirror_x):
            raise ParameterError("mirror_x", self.mirror_x, "a finite x")
        falloff_lut(self.falloff)
        if self.brush == "align" and self.params.get("mode", "paper") not in MODES:
            raise ParameterError("mode", self.params.get("mode"), " or ".join(MODES))
        return self

    def pipeline_samples(self, default_mirror_x: float) -> list[AlignSample | BrushSample]:
        """The samples a pipeline applies, mirrored ones right after their originals."""
        self.validate()
        out: list[AlignSample | BrushSample] = []
        mirror = self.mirror_x if self.mirror_x is not None else default_mirror_x
        lut = tuple(falloff_lut(self.falloff).tolist())
        for i, s in enumerate(self.samples):
            if self.brush == "align":
                mode = self.params.get("mode", "paper")
                v = check_view(s.view)
                only = self.only_selected
                first = AlignSample(s.cursor, s.radius, s.strength, mode, v, self.collision, only,
                                    check_pressure(s.pressure))  # fmt: skip
                out.append(first)
                if self.symmetry == "x":
                    cursor = (2.0 * mirror - s.cursor[0], s.cursor[1], s.cursor[2])
                    out.append(first._replace(cursor=cursor, view=mirrored_view(s.view)))
                continue
            start = (i == 0) if s.start is None else s.start
            start = start and self.brush == "snake_hook"  # (the only brush a start changes)
            count, seed, spacing = 1, 0, 0.0
            if self.brush in ("add", "density"):  # (checked with the sample)
                count, seed = self.params.get("count", 1), self.params.get("seed", 0)
            if self.brush == "density":
                spacing = self.params.get("spacing")
                spacing = _number("params.spacing", spacing) if spacing is not None else 0.0
            sample = BrushSample(
                self.brush, s.cursor, s.direction, s.radius, s.strength, lut, s.view, start, self.collision,
                count, seed, spacing, self.only_selected, s.pressure,
            )
            sample = check_sample(sample)
            out.append(sample)
            if self.symmetry == "x":
                out.append(sample.mirrored(mirror))
        return out

    def to_dict(self) -> dict:
        falloff = self.falloff if isinstance(self.falloff, str) else [list(p) for p in self.falloff]
        return {
            "brush": self.brush,
            "falloff": falloff,
            "symmetry": self.symmetry,
            "mirror_x": self.mirror_x,
            "params": dict(self.params),
            **({} if self.collision else {"collision": False}),
            **({"only_selected": True} if self.only_selected else {}),
            "samples": [
                {
                    "cursor": list(s.cursor),
                    "direction": list(s.direction),
                    "radius": s.radius,
                    "strength": s.strength,
                    "view": None if s.view is None else list(s.view),
                    "pressure": s.pressure,
                }
                | ({} if s.start is None else {"start": s.start})
                for s in self.samples
            ],
        }


@dataclass(frozen=True)
class SelectionStep:
    """One selection step of a log (:class:`~hairtool.frozen.selection.SelectionSample`)."""

    sample: SelectionSample

    def validate(self) -> SelectionStep:
        check_selection(self.sample)
        return self

    def pipeline_samples(self, default_mirror_x: float = 0.0) -> list[SelectionSample]:
        return [self.validate().sample]

    def to_dict(self) -> dict:
        s = self.sample
        if s.op != "box":
            return {"selection": s.op}
        view = None if s.view is None else list(s.view)
        box = {"mode": s.mode, "matrix": list(s.matrix), "rect": list(s.rect), "view": view}
        return {"selection": "box", **box}


def strokes_from_log(
    log: Sequence[AlignSample | BrushSample | SelectionSample],
) -> list[Stroke | SelectionStep]:
    """A pipeline's log as strokes that replay to the same bytes: runs of samples of one brush
    and falloff become one stroke, mirrored samples stay explicit (no symmetry flag); each
    selection step stays one."""
    runs: list[tuple[tuple, Stroke | SelectionStep]] = []
    for s in log:
        split = False
        if isinstance(s, SelectionSample):
            runs.append((("selection", len(runs)), SelectionStep(s)))
            continue
        if isinstance(s, AlignSample):
            key: tuple = ("align", s.mode, s.collide, s.only_selected)
            sample = StrokeSample(
                tuple(s.cursor), s.radius, s.intensity, view=_view_of(s.view), pressure=s.pressure
            )
            start = Stroke("align", (sample,), params={"mode": s.mode}, collision=s.collide,
                           only_selected=s.only_selected)  # fmt: skip
        else:
            key = (s.brush, s.lut, s.collide, s.count, s.seed, s.spacing, s.only_selected)
            hook = s.brush == "snake_hook"
            sample = StrokeSample(
                tuple(s.cursor), s.radius, s.strength, tuple(s.direction), _view_of(s.view),
                bool(s.start) if hook else None, s.pressure,
            )  # fmt: skip
            params = {"count": s.count, "seed": s.seed} if s.brush == "add" else {}
            if s.brush == "density":
                params = {"spacing": s.spacing, "seed": s.seed}
            start = Stroke(s.brush, (sample,), falloff=_falloff_of(s.lut), params=params, collision=s.collide,
                           only_selected=s.only_selected)  # fmt: skip
            # a snake hook's start (not its mirror's) begins a new stroke, with its own strands
            last = runs[-1][1] if runs else None
            split = hook and s.start and isinstance(last, Stroke) and not last.samples[-1].start
        if runs and runs[-1][0] == key and not split:
            last = runs[-1][1]
            more = Stroke(last.brush, (*last.samples, sample), last.falloff, params=last.params)
            runs[-1] = (key, replace(more, collision=last.collision, only_selected=last.only_selected))
        else:
            runs.append((key, start))
    return [stroke for _, stroke in runs]


def _view_of(view: Sequence[float] | None) -> tuple[float, float, float] | None:
    return None if view is None else (float(view[0]), float(view[1]), float(view[2]))


def _flag(where: str, value: Any) -> bool | None:
    if value is None or isinstance(value, bool):
        return value
    raise ParameterError(where, value, "true, false or null")


def _falloff_of(lut: Sequence[float]) -> str | tuple[tuple[float, float], ...]:
    """A preset's name when the table is one, else the table as curve points."""
    for name in ("smooth", "linear", "constant"):
        if tuple(falloff_lut(name).tolist()) == tuple(lut):
            return name
    t = np.linspace(0.0, 1.0, len(lut))
    return tuple((float(a), float(b)) for a, b in zip(t, lut, strict=True))


def _vector(where: str, value: Any, default: tuple | None = None) -> tuple[float, float, float]:
    if value is None and default is not None:
        return default
    if not isinstance(value, list) or len(value) != 3:
        raise ParameterError(where, _short(value), "three numbers [x, y, z]")
    v = tuple(_number(where, c) for c in value)
    return v  # type: ignore[return-value]


def _pressure(where: str, value: Any) -> float:
    try:
        return check_pressure(value)
    except ParameterError:
        raise ParameterError(where, _short(value), "a pen's pressure in [0, 1]") from None


def _number(where: str, value: Any) -> float:
    """A finite float; an integer beyond float64's range is refused before ``float()`` (the
    comparison of an int with a float is exact, so it cannot overflow)."""
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise ParameterError(where, _short(value), "a finite number")
    if isinstance(value, int) and not -sys.float_info.max <= value <= sys.float_info.max:
        digits = int(abs(value).bit_length() * math.log10(2)) + 1  # str() refuses over 4,300 digits
        raise ParameterError(where, f"an integer of about {digits} digits", "a finite number")
    if not math.isfinite(value):
        raise ParameterError(where, value, "a finite number")
    return float(value)


def _short(value: Any) -> Any:
    """``value`` for a message: a long list or text by its kind and length."""
    if isinstance(value, list | dict | str) and len(repr(value)) > 80:
        unit = "characters" if isinstance(value, str) else "items"
        return f"a {type(value).__name__} of {len(value)} {unit}"
    return value


def selection_from_dict(d: dict, where: str = "stroke") -> SelectionStep:
    """A :class:`SelectionStep` from its JSON form; ParameterError naming the field."""
    op = d.get("selection")
    if op not in ("box",):
        step = SelectionStep(SelectionSample(op))
    else:
        matrix, rect = d.get("matrix"), d.get("rect")
        if not isinstance(matrix, list) or len(matrix) != 16:
            raise ParameterError(f"{where}.matrix", _short(matrix), "16 numbers (a 4×4 matrix, row-major)")
        if not isinstance(rect, list) or len(rect) != 4:
            raise ParameterError(f"{where}.rect", _short(rect), "four numbers [x0, y0, x1, y1]")
        view = d.get("view")
        step = SelectionStep(SelectionSample(
            "box", tuple(_number(f"{where}.matrix", v) for v in matrix),
            tuple(_number(f"{where}.rect", v) for v in rect),  # type: ignore[arg-type]
            d.get("mode", "set"), None if view is None else _vector(f"{where}.view", view),
        ))  # fmt: skip
    try:
        return step.validate()
    except ParameterError as e:
        raise ParameterError(f"{where}.{e.name}", _short(e.value), str(e).split("expected ", 1)[-1]) from None


def stroke_from_dict(d: Any, where: str = "stroke") -> Stroke | SelectionStep:
    """A :class:`Stroke` (or :class:`SelectionStep`) from its JSON form; ParameterError naming
    the field on anything wrong."""
    if not isinstance(d, dict):
        raise ParameterError(where, type(d).__name__, "an object with brush and samples")
    if "selection" in d and "brush" not in d:
        return selection_from_dict(d, where)
    raw_samples = d.get("samples")
    if not isinstance(raw_samples, list):
        raise ParameterError(f"{where}.samples", _short(raw_samples), "a list of samples")
    samples = []
    for i, s in enumerate(raw_samples):
        at = f"{where}.samples[{i}]"
        if not isinstance(s, dict):
            raise ParameterError(at, type(s).__name__, "an object with cursor, radius and strength")
        samples.append(
            StrokeSample(
                _vector(f"{at}.cursor", s.get("cursor")),
                _number(f"{at}.radius", s.get("radius")),
                _number(f"{at}.strength", s.get("strength")),
                _vector(f"{at}.direction", s.get("direction"), (0.0, 0.0, 0.0)),
                None if s.get("view") is None else _vector(f"{at}.view", s.get("view")),
                _flag(f"{at}.start", s.get("start")),
                _pressure(f"{at}.pressure", s.get("pressure", 1.0)),
            )
        )
    falloff = d.get("falloff", "smooth")
    if isinstance(falloff, list):
        if len(falloff) > MAX_FALLOFF_POINTS:
            many = f"{len(falloff)} points"
            raise ParameterError(f"{where}.falloff", many, f"at most {MAX_FALLOFF_POINTS}")
        for k, p in enumerate(falloff):
            if not isinstance(p, list) or len(p) != 2:
                raise ParameterError(f"{where}.falloff[{k}]", _short(p), "a point [t, w]")
        falloff = tuple((_number(f"{where}.falloff", t), _number(f"{where}.falloff", w)) for t, w in falloff)
    params = d.get("params") or {}
    if not isinstance(params, dict):
        raise ParameterError(f"{where}.params", _short(params), "an object")
    mirror = d.get("mirror_x")
    stroke = Stroke(
        brush=d.get("brush"),
        samples=tuple(samples),
        falloff=falloff,
        symmetry=d.get("symmetry"),
        mirror_x=None if mirror is None else _number(f"{where}.mirror_x", mirror),
        params=params,
        collision=_flag(f"{where}.collision", d.get("collision")) is not False,
        only_selected=_flag(f"{where}.only_selected", d.get("only_selected")) is True,
    )
    try:
        stroke.pipeline_samples(0.0)  # every sample checked (radius, strength range) as it will run
        return stroke
    except ParameterError as e:
        raise ParameterError(f"{where}.{e.name}", _short(e.value), str(e).split("expected ", 1)[-1]) from None


def read_strokes(path: str | os.PathLike[str]) -> list[Stroke | SelectionStep]:
    """A stroke log file; :class:`FormatError` naming the file and the bad entry."""
    p = Path(path)
    data = user_text.read(p, "a stroke log", "json", MAX_LOG_BYTES)  # every user text limit
    if isinstance(data, dict) and isinstance(data.get("strokes"), list):
        data = data["strokes"]
    if not isinstance(data, list):
        raise FormatError(p, "a stroke log is a JSON list of strokes")
    try:
        return [stroke_from_dict(s, f"strokes[{i}]") for i, s in enumerate(data)]
    except ParameterError as e:
        raise FormatError(p, str(e)) from None


def write_strokes(path: str | os.PathLike[str], strokes: Sequence[Stroke | SelectionStep]) -> None:
    """Write a stroke log (atomically)."""
    try:
        with atomic_open(path, "w", encoding="utf-8") as f:
            json.dump([s.to_dict() for s in strokes], f, indent=1, allow_nan=False)
            f.write("\n")
    except (OSError, ValueError) as e:
        raise FormatError(path, f"cannot write the strokes: {e}") from None
