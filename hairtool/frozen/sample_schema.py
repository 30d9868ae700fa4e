"""One description per stroke-sample type: its fields, their kinds, ranges and defaults, the
name a stroke log gives each, and the project column that stores it.

A stroke is saved three ways (a JSON stroke log, a project's columns, the studio's undo
history) and built a fourth (the studio's mouse moves). Each of those reads the description
here instead of listing the fields again, so a field added to a sample type is added once.
The sample classes themselves stay beside their kernels (:class:`BrushSample`,
:class:`AlignSample`, :class:`SelectionSample`); a test holds each class to its description.

``used_by`` says which brushes (or selection steps) a field means something to: a stroke log
writes it only for those, the studio sets it only for those, and the others keep the default.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property
from typing import Any

from hairtool.frozen.align import MODES
from hairtool.frozen.brushes import BRUSHES, MAX_COUNT, SIGNED, BrushSample
from hairtool.frozen.pipeline import AlignSample
from hairtool.frozen.selection import BOX_MODES, OPS, SelectionSample

REQUIRED = object()  # a field with no default: every sample states it


@dataclass(frozen=True)
class Field:
    """One field of a sample type.

    ``kind``: ``vector`` (three floats), ``number``, ``whole``, ``flag``, ``choice`` (one of
    ``choices``), ``view`` (a vector or None, not zero), ``point`` (a vector or None: a
    place, so zero too), ``falloff`` (a falloff table), ``matrix`` (16
    floats or None) or ``rect`` (four floats or None). ``low``/``high``: the closed range of a
    number or whole number (``low_open``: ``low`` itself refused). ``json``: its name in a stroke
    log, kept at ``level`` ``sample`` (each sample), ``stroke`` (once per stroke), ``params``
    (the stroke's params) or ``step`` (a selection step's own object). ``column``: the project
    array that stores it (``box`` holds a selection's matrix, rectangle and mode side by side).
    """

    name: str
    kind: str
    default: Any = REQUIRED
    json: str = ""
    level: str = "sample"
    column: str = ""
    low: float | None = None
    high: float | None = None
    low_open: bool = False
    choices: tuple[str, ...] = ()
    used_by: tuple[str, ...] | None = None  # None: every brush or step of the type
    log_default: Any = REQUIRED  # what a stroke log that leaves it out means (REQUIRED: default)
    quiet: bool = False  # a stroke log leaves it out at its default (logs before it stay as they were)

    def in_log(self, raw: dict) -> Any:
        """Its value in a stroke log's object ``raw`` (its default where left out)."""
        return raw.get(self.json, self.default if self.log_default is REQUIRED else self.log_default)

    def used(self, by: str) -> bool:
        return self.used_by is None or by in self.used_by


@dataclass(frozen=True, eq=False)  # (compared and hashed as itself: a dict key per sample)
class SampleType:
    """A sample class and its fields; ``key`` is the field that names the brush or the step."""

    name: str
    cls: type
    key: str | None
    fields: tuple[Field, ...]

    def field(self, name: str) -> Field:
        for f in self.fields:
            if f.name == name:
                return f
        raise KeyError(name)

    def by_column(self, column: str) -> tuple[Field, ...]:
        return self._columns.get(column, ())

    @cached_property
    def _columns(self) -> dict[str, tuple[Field, ...]]:  # (a project's save asks per sample)
        out: dict[str, tuple[Field, ...]] = {}
        for f in self.fields:
            out[f.column] = (*out.get(f.column, ()), f)
        return out

    def at(self, level: str) -> tuple[Field, ...]:
        return tuple(f for f in self.fields if f.level == level)

    def which(self, sample: Any) -> str:
        """The brush or step ``sample`` is (the type's name for align)."""
        return self.name if self.key is None else getattr(sample, self.key)

    def make(self, **values: Any) -> Any:
        """A sample of this type from field values by name; fields the brush or step does not
        use take their defaults, missing ones too (a missing required one is a TypeError)."""
        by = values.get(self.key, self.name) if self.key is not None else self.name
        args = {}
        for f in self.fields:
            if f.name in values and f.used(by):
                args[f.name] = values.pop(f.name)
            else:
                values.pop(f.name, None)
                if f.default is REQUIRED:
                    raise TypeError(f"the {self.name} sample needs {f.name}")
                args[f.name] = f.default
        if values:
            raise TypeError(f"a {self.name} sample has no field {sorted(values)[0]}")
        return self.cls(**args)


#: Brush samples, in a stroke log's order (brush, falloff, params, flags, then each sample's).
BRUSH = SampleType("brush", BrushSample, "brush", (
    Field("brush", "choice", json="brush", level="stroke", column="brush", choices=BRUSHES[1:]),
    Field("lut", "falloff", json="falloff", level="stroke", column="falloff"),
    Field("count", "whole", 1, "count", "params", "count", 1, MAX_COUNT, used_by=("add",)),
    Field("spacing", "number", 0.0, "spacing", "params", "spacing", 0.0, None, True, used_by=("density",)),
    Field("seed", "whole", 0, "seed", "params", "seed", 0, 2**32 - 1, used_by=("add", "density")),
    Field("any_segment", "flag", False, "any_segment", "params", "any_segment", used_by=("delete",),
          quiet=True),
    Field("collide", "flag", True, "collision", "stroke", "collide"),
    Field("only_selected", "flag", False, "only_selected", "stroke", "only_selected"),
    Field("visible", "flag", False, "visible", "stroke", "visible"),
    Field("cursor", "vector", json="cursor", column="cursor"),
    Field("direction", "vector", json="direction", column="direction", log_default=(0.0, 0.0, 0.0)),
    Field("radius", "number", json="radius", column="radius", low=0.0, low_open=True),
    Field("strength", "number", json="strength", column="intensity", low=-1.0, high=1.0),  # ≥ 0 unsigned
    Field("view", "view", None, "view", column="view"),
    Field("pressure", "number", 1.0, "pressure", column="pressure", low=0.0, high=1.0),
    Field("start", "flag", False, "start", column="start", used_by=("snake_hook",)),
    Field("new_selection", "flag", False, "new_selection", column="new_selection", used_by=("select",),
          quiet=True),
    Field("eye", "point", None, "eye", column="eye", quiet=True),
))  # fmt: skip

#: The paper's align samples: ``intensity`` is a stroke log's ``strength``, ``mode`` its params'.
ALIGN = SampleType("align", AlignSample, None, (
    Field("mode", "choice", json="mode", level="params", column="mode", choices=MODES, log_default=MODES[0]),
    Field("collide", "flag", True, "collision", "stroke", "collide"),
    Field("only_selected", "flag", False, "only_selected", "stroke", "only_selected"),
    Field("visible", "flag", False, "visible", "stroke", "visible"),
    Field("cursor", "vector", json="cursor", column="cursor"),
    Field("radius", "number", json="radius", column="radius", low=0.0, low_open=True),
    Field("intensity", "number", json="strength", column="intensity", low=0.0, high=1.0),
    Field("view", "view", None, "view", column="view"),
    Field("pressure", "number", 1.0, "pressure", column="pressure", low=0.0, high=1.0),
    Field("eye", "point", None, "eye", column="eye", quiet=True),
))  # fmt: skip

#: Selection steps; a box's camera, rectangle, mode and view mean nothing to the others.
SELECTION = SampleType("selection", SelectionSample, "op", (
    Field("op", "choice", json="selection", level="step", column="selection", choices=OPS),
    Field("mode", "choice", "set", "mode", "step", "box", choices=BOX_MODES, used_by=("box",)),
    Field("matrix", "matrix", None, "matrix", "step", "box", used_by=("box",)),
    Field("rect", "rect", None, "rect", "step", "box", used_by=("box",)),
    Field("view", "view", None, "view", "step", "view", used_by=("box",)),
    Field("visible", "flag", False, "visible", "step", "visible", used_by=("box",), quiet=True),
    Field("to_eye", "flag", False, "to_eye", "step", "to_eye", used_by=("box",), quiet=True),
))  # fmt: skip

TYPES = (ALIGN, BRUSH, SELECTION)


def sample_type(sample: Any) -> SampleType:
    """The description of ``sample``'s type (TypeError for anything else)."""
    for t in TYPES:
        if type(sample) is t.cls:
            return t
    raise TypeError(f"not a stroke sample: {type(sample).__name__}")


def strength_range(brush: str) -> tuple[float, float]:
    """The strengths a brush takes: signed brushes [-1, 1], the others [0, 1]."""
    return (-1.0 if brush in SIGNED else 0.0), 1.0


def params_of(t: SampleType, by: str, sample: Any) -> dict[str, Any]:
    """The params a stroke log writes for ``sample`` (a ``by`` brush): those its brush uses, in
    the description's order, by their log names (a quiet one only where it is not its default)."""
    return {
        f.json: getattr(sample, f.name)
        for f in t.at("params")
        if f.used(by) and not (f.quiet and getattr(sample, f.name) == f.default)
    }
