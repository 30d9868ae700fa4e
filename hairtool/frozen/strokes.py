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
  the strands with any segment within the radius where ``params.any_segment`` is true, as
  Blender does, else those whose root lies within it, as a log without it meant; strength > 0,
  falloff ignored), ``pinch`` (> 0
  gathers toward the brush centre, < 0 spreads) or ``snake_hook`` (the strands whose tip lies
  within the radius at the stroke's first sample follow the cursor; ``direction`` is the
  cursor's motion since the sample before), ``slide`` (roots slide along the head; needs one)
  or ``add`` (plants ``params.count`` strands per sample, default 1, around the head's point
  nearest the cursor, drawn from ``params.seed``, default 0, and the cursor; needs a head) or
  ``density`` (removes and plants strands under the brush until the roots are
  ``params.spacing`` apart, in groom units; ``params.seed`` as add's; needs a head) or
  ``select`` (> 0 selects the strands touched, < 0 deselects them; a sample with
  ``"new_selection": true``, a plain stroke's first, deselects every shown strand first, as
  Blender's Selection Paint starts a new selection; without it the stroke adds, as every log
  before it meant; hidden strands stay as they are).
- ``only_selected`` (per stroke, optional, default false): the stroke leaves the strands that
  are not selected as they are (the studio's "Affect selection only"). Hidden strands are left
  alone by every stroke.
- ``collision`` (per stroke, optional, default true): with a head surface (``--scalp``), no
  vertex the stroke moves ends inside it; false: strands may pass through the head.
- ``start`` (per sample, optional): true where a stroke begins (a snake hook hooks its strands
  there); missing: true for a stroke's first sample only. Written for snake hooks, whose
  mirrored first sample is a start too.
- ``new_selection`` (per sample, optional, default false; select only): true where a select
  stroke starts a new selection (the studio's plain drag, at its first sample): every shown
  strand is deselected before the sample selects. Written only where true.
- ``pressure`` (per sample, optional, default 1.0): the pen's pressure in [0, 1] at that
  sample (a mouse presses 1.0). ``radius`` and ``strength`` are what the brush used there, the
  pressure already applied (the studio scales them by it where the brush's pressure toggles
  are on), so a replay reads them as they are and gives the same bytes; the pressure says how
  the stroke was drawn.
- ``view`` (per sample, optional): the camera's viewing direction, from the eye into the scene;
  only the strands facing that camera are touched. null or missing (older logs): every strand.
- ``eye`` (per sample, optional, written only where set): a perspective camera's eye, which the
  studio records in its 3-D view. By sight, each vertex's ray goes to it instead of against
  ``view`` (a wide brush near the edge of a perspective view judges each strand along its own
  line of sight), and add and density plant where the line from it through ``cursor`` first
  meets the head (else, as every log before it and every orthographic camera: around the head's
  point nearest the cursor, rays along ``view``).
- ``visible`` (per stroke, optional, default false): how a ``view`` judges which strands face
  the camera. true (the studio writes it): those the head mesh does not hide from the camera
  under the brush (:mod:`hairtool.frozen.brushes.sight`); false or missing (older logs, and
  every log without a head mesh): those whose root's outward normal faces the camera. Add and
  density with it plant only roots the head does not hide from the camera; without it, nothing
  where the head under the cursor faces away, and only where the surface faces the camera.
- ``falloff``: ``smooth``, ``linear``, ``constant``, or a curve ``[[t, w], ...]`` over t =
  distance / radius from 0 to 1 (align keeps the paper's own weighting and ignores it).
- ``symmetry``: ``"x"`` mirrors every sample across the plane x = ``mirror_x`` (default: the
  centre of the sphere fitted to the roots), into the same stroke; null for none.

Besides strokes, a log holds selection steps (:mod:`hairtool.frozen.selection`), each an
object with a ``selection`` field instead of ``brush``::

    {"selection": "all"}  {"selection": "none"}  {"selection": "invert"}
    {"selection": "hide_selected"}  {"selection": "hide_unselected"}  {"selection": "reveal"}
    {"selection": "box", "mode": "set", "matrix": [16 numbers], "rect": [x0, y0, x1, y1],
     "view": [vx, vy, vz], "visible": true}

- ``box``: the strands with a point inside the rectangle ``rect`` (normalised device
  coordinates, −1 … 1, y up) of the camera whose world-to-clip matrix is ``matrix`` (4×4,
  row-major); ``mode`` ``set`` (default), ``add`` or ``subtract``; ``view`` as a sample's;
  ``visible`` (optional, default false, written only where true) as a stroke's: with a head
  mesh, only the strands with a point inside the rectangle that the head does not hide from
  the camera; false or missing (older logs): those whose root normal faces the camera.
  ``to_eye`` (optional, default false, written only where true): by sight, each point's ray
  goes to the eye of ``matrix`` (a perspective camera's; the studio writes it there) instead
  of along ``view`` (every log before it).

Fields a reader does not know are ignored and missing optional ones take their defaults, so
logs written by older and newer versions stay readable.

Which field sits where, its log name and its default come from the sample descriptions of
:mod:`hairtool.frozen.sample_schema` (a brush's params: those its brush uses), which the
project's columns and the studio's samples use too.
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
    check_eye,
    check_pressure,
    check_sample,
    check_view,
    falloff_lut,
    mirrored_eye,
    mirrored_view,
)
from hairtool.frozen.pipeline import AlignSample
from hairtool.frozen.sample_schema import (
    ALIGN,
    BRUSH,
    REQUIRED,
    SELECTION,
    Field,
    SampleType,
    params_of,
    sample_type,
)
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
    new_selection: bool = False  # a select sample starts a new selection (False: it adds)
    eye: tuple[float, float, float] | None = None  # a perspective camera's eye (None: orthographic)


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
    visible: bool = False  # front faces only by sight (else by root normal, as logs before it)

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
        """The samples a pipeline applies, mirrored ones right after their originals.

        Parameters
        ----------
        default_mirror_x : float
            The mirror plane's x where the stroke names none (the centre of the sphere fitted to the
            roots).

        Returns
        -------
        list of AlignSample or BrushSample
            The samples, in the order the pipeline applies them.
        """
        self.validate()
        out: list[AlignSample | BrushSample] = []
        mirror = self.mirror_x if self.mirror_x is not None else default_mirror_x
        t = ALIGN if self.brush == "align" else BRUSH
        shared = {"brush": self.brush, "lut": tuple(falloff_lut(self.falloff).tolist())}
        for f in t.fields:  # what the stroke and its params give every sample
            if f.level == "stroke" and f.name not in shared:
                shared[f.name] = getattr(self, f.json)
            elif f.level == "params" and f.used(self.brush):
                value = f.in_log(self.params)
                if f.kind == "flag" and not isinstance(value, bool):
                    raise ParameterError(f"params.{f.json}", value, "true or false")
                number = f.kind == "number" and value is not None
                shared[f.name] = _number(f"params.{f.json}", value) if number else value
        for i, s in enumerate(self.samples):
            values = dict(shared)
            for f in t.at("sample"):
                value = getattr(s, f.json)
                values[f.name] = f.default if value is None and f.quiet else value
            if "start" in values:  # missing: the stroke's first sample starts it
                values["start"] = (i == 0) if s.start is None else s.start
            sample = t.make(**{k: v for k, v in values.items() if k in _names(t)})
            if t is ALIGN:
                view, eye = check_view(s.view), check_eye(s.eye)
                sample = sample._replace(view=view, pressure=check_pressure(s.pressure), eye=eye)
                out.append(sample)
                if self.symmetry == "x":
                    cursor = (2.0 * mirror - s.cursor[0], s.cursor[1], s.cursor[2])
                    across = {"view": mirrored_view(view), "eye": mirrored_eye(eye, mirror)}
                    out.append(sample._replace(cursor=cursor, **across))
                continue
            sample = check_sample(sample)
            out.append(sample)
            if self.symmetry == "x":
                out.append(sample.mirrored(mirror))
        return out

    def to_dict(self) -> dict:
        falloff = self.falloff if isinstance(self.falloff, str) else [list(p) for p in self.falloff]
        flags = {}  # the stroke's flags, where they are not their defaults
        for f in BRUSH.at("stroke"):
            if f.kind == "flag" and getattr(self, f.json) != f.default:
                flags[f.json] = getattr(self, f.json)
        return {
            "brush": self.brush,
            "falloff": falloff,
            "symmetry": self.symmetry,
            "mirror_x": self.mirror_x,
            "params": dict(self.params),
            **flags,
            "samples": [_sample_dict(s) for s in self.samples],
        }


def _names(t: SampleType) -> frozenset[str]:
    return frozenset(f.name for f in t.fields)


#: A stroke log's sample fields, in its order (align's are among a brush's, strength its intensity).
LOG_SAMPLE = BRUSH.at("sample")


def _sample_dict(s: StrokeSample) -> dict:
    """A log sample's JSON object: every field, a start only where one is stated, a quiet flag
    only where it is not its default."""
    out: dict[str, Any] = {}
    for f in LOG_SAMPLE:
        value = getattr(s, f.json)
        if (f.kind == "flag" and value is None) or (f.quiet and value == f.default):
            continue
        out[f.json] = list(value) if f.kind in ("vector", "view", "point") and value is not None else value
    return out


@dataclass(frozen=True)
class SelectionStep:
    """One selection step of a log (:class:`~hairtool.frozen.selection.SelectionSample`)."""

    sample: SelectionSample

    def validate(self) -> SelectionStep:
        check_selection(self.sample)
        return self

    def pipeline_samples(self, default_mirror_x: float = 0.0) -> list[SelectionSample]:
        """The step as the one sample a pipeline applies (checked first).

        Parameters
        ----------
        default_mirror_x : float, default 0.0
            Unused: a selection step has no mirror (the same call as :meth:`Stroke.pipeline_samples`).

        Returns
        -------
        list of SelectionSample
            One sample.
        """
        return [self.validate().sample]

    def to_dict(self) -> dict:
        """The step's fields its op uses (a box's camera, rectangle, mode and view), by log name."""
        s, out = self.sample, {}
        for f in SELECTION.fields:
            value = getattr(s, f.name)
            if f.used(s.op) and not (f.quiet and value == f.default):  # (logs before it stay)
                out[f.json] = list(value) if isinstance(value, tuple) else value
        return out


def strokes_from_log(
    log: Sequence[AlignSample | BrushSample | SelectionSample],
) -> list[Stroke | SelectionStep]:
    """A pipeline's log as strokes that replay to the same bytes: runs of samples of one brush
    and falloff become one stroke, mirrored samples stay explicit (no symmetry flag); each
    selection step stays one.

    Parameters
    ----------
    log : sequence of AlignSample, BrushSample or SelectionSample
        A pipeline's samples, in order.

    Returns
    -------
    list of Stroke or SelectionStep
        What :func:`write_strokes` writes.
    """
    runs: list[tuple[tuple, Stroke | SelectionStep]] = []
    for s in log:
        t = sample_type(s)
        if t is SELECTION:
            runs.append((("selection", len(runs)), SelectionStep(s)))
            continue
        by = t.which(s)
        once = [f for f in t.fields if f.level in ("stroke", "params")]
        key: tuple = (by, *(getattr(s, f.name) for f in once))
        fields = {}
        for f in t.at("sample"):
            if f.used(by):
                value = getattr(s, f.name)
                if f.kind in ("view", "point"):
                    value = _view_of(value)
                elif f.kind == "vector":
                    value = tuple(value)
                fields[f.json] = value
        if "start" in fields:
            fields["start"] = bool(fields["start"])
        sample = StrokeSample(**fields)
        falloff = _falloff_of(s.lut) if t is BRUSH else "smooth"
        flags = {f.json: getattr(s, f.name) for f in t.at("stroke") if f.kind == "flag"}
        start = Stroke(by, (sample,), falloff=falloff, params=params_of(t, by, s), **flags)
        # a snake hook's start (not its mirror's) begins a new stroke, with its own strands; so
        # does a new selection
        last = runs[-1][1] if runs else None
        split = bool(sample.start) and isinstance(last, Stroke) and not last.samples[-1].start
        split = split or bool(sample.new_selection)
        if runs and runs[-1][0] == key and not split:
            last = runs[-1][1]
            runs[-1] = (key, replace(last, samples=(*last.samples, sample)))
        else:
            runs.append((key, start))
    return [stroke for _, stroke in runs]


def _view_of(view: Sequence[float] | None) -> tuple[float, float, float] | None:
    return None if view is None else (float(view[0]), float(view[1]), float(view[2]))


def _log_value(f: Field, raw: dict, at: str) -> Any:
    """A log sample's field ``f`` from its JSON object, checked as its kind says."""
    where, value = f"{at}.{f.json}", raw.get(f.json)
    if f.kind == "vector":
        default = None if f.log_default is REQUIRED else f.log_default
        return _vector(where, value, default)
    if f.kind in ("view", "point"):
        return None if value is None else _vector(where, value)
    if f.kind == "flag":
        return _flag(where, value)
    if f.name == "pressure":
        return _pressure(where, raw.get(f.json, f.default))
    return _number(where, value)


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


_STEP_SHAPES = {
    "matrix": (16, "16 numbers (a 4×4 matrix, row-major)"),
    "rect": (4, "four numbers [x0, y0, x1, y1]"),
}


def selection_from_dict(d: dict, where: str = "stroke") -> SelectionStep:
    """A :class:`SelectionStep` from its JSON form; ParameterError naming the field.

    Parameters
    ----------
    d : dict
        The step's JSON object.
    where : str, default "stroke"
        Where it is in the log (``stroke 3``), named in a refusal.

    Returns
    -------
    SelectionStep
        The step.
    """
    op = d.get("selection")
    values: dict[str, Any] = {"op": op}
    for f in SELECTION.fields:
        if f.name == "op" or not f.used(op):
            continue
        value = f.in_log(d)
        if f.name in _STEP_SHAPES:
            size, expected = _STEP_SHAPES[f.name]
            if not isinstance(value, list) or len(value) != size:
                raise ParameterError(f"{where}.{f.json}", _short(value), expected)
            value = tuple(_number(f"{where}.{f.json}", v) for v in value)
        elif f.kind == "view":
            value = None if value is None else _vector(f"{where}.{f.json}", value)
        elif f.kind == "flag":
            value = _flag(f"{where}.{f.json}", value) is True
        values[f.name] = value
    try:
        return SelectionStep(SELECTION.make(**values)).validate()
    except ParameterError as e:
        raise ParameterError(f"{where}.{e.name}", _short(e.value), str(e).split("expected ", 1)[-1]) from None


def stroke_from_dict(d: Any, where: str = "stroke") -> Stroke | SelectionStep:
    """A :class:`Stroke` (or :class:`SelectionStep`) from its JSON form; ParameterError naming
    the field on anything wrong.

    Parameters
    ----------
    d : Any
        The stroke's JSON object.
    where : str, default "stroke"
        Where it is in the log, named in a refusal.

    Returns
    -------
    Stroke or SelectionStep
        The stroke, checked.
    """
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
        samples.append(StrokeSample(**{f.json: _log_value(f, s, at) for f in LOG_SAMPLE if f.json in s or
                                       f.default is REQUIRED or f.log_default is not REQUIRED}))  # fmt: skip
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
        visible=_flag(f"{where}.visible", d.get("visible")) is True,
    )
    try:
        stroke.pipeline_samples(0.0)  # every sample checked (radius, strength range) as it will run
        return stroke
    except ParameterError as e:
        raise ParameterError(f"{where}.{e.name}", _short(e.value), str(e).split("expected ", 1)[-1]) from None


def read_strokes(path: str | os.PathLike[str]) -> list[Stroke | SelectionStep]:
    """A stroke log file; :class:`FormatError` naming the file and the bad entry.

    Parameters
    ----------
    path
        A JSON stroke log: a list of strokes and selection steps, or an object whose
        ``strokes`` is that list. At most 256 MB.

    Returns
    -------
    list of Stroke or SelectionStep
        The entries in order, each checked as it will run; unknown fields are ignored and
        missing ones take their defaults, so older logs read.

    Raises
    ------
    FormatError
        The file is unreadable, not JSON, too large or too deep, or an entry is bad; the message
        names the file and the entry (``strokes[3]``).
    """
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
    """Write a stroke log (atomically).

    Parameters
    ----------
    path
        The JSON file to write; a temporary file beside it is renamed into place.
    strokes
        Strokes and selection steps, in order, as :func:`read_strokes` gives them back.

    Raises
    ------
    FormatError
        The file cannot be written, or a value is not finite; the message names the file.
    """
    try:
        with atomic_open(path, "w", encoding="utf-8") as f:
            json.dump([s.to_dict() for s in strokes], f, indent=1, allow_nan=False)
            f.write("\n")
    except (OSError, ValueError) as e:
        raise FormatError(path, f"cannot write the strokes: {e}") from None
