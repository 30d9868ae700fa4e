"""A stroke log as columns, one array per field (a project's ``strokes/*.npy``), from the
sample descriptions of :mod:`hairtool.frozen.sample_schema`.

Every column holds one row per sample of the log, whatever its type; a sample whose type has
no field in a column stores the column's fill there. Columns come in groups, each stored only
when the log needs it (a log of align samples alone is written as a version 1 project was), and
the manifest's ``strokes`` section names the groups stored: ``brushes`` (the brush, direction
and falloff columns, with ``falloffs``, the table of distinct falloff curves), ``views``,
``collide``, ``plants`` (add and density's count, seed and spacing), ``starts``,
``only_selected``, ``pressure``, ``any_segment`` (a delete's rule: stored only where a
sample takes Blender's, so older projects, which meant the root rule, read as they did),
``new_selection`` (a select sample that starts a new selection: stored only where one does, so
older projects, whose select strokes added, read as they did), ``visible`` (front faces only by
sight: stored only where a sample judges so, so older projects, which judged by the root normal,
read as they did), ``to_eye`` (a box judged by sight along each point's own line to a
perspective camera's eye: stored only where a box does, so older projects, whose boxes traced
every ray along the view, read as they did), ``eye`` (a perspective camera's eye, in ``eye``
with ``has_eye`` saying which samples hold one: stored only where a sample does, so older
projects, whose samples had none, read as they did) and
``selection`` (a step's op, and a box's matrix, rectangle
and mode in ``box``). Choices are stored as indices into a list: the align modes in ``modes``,
the brushes in ``brushes``, the steps in ``selection``.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from hairtool.frozen.brushes import BRUSHES, LUT_SIZE
from hairtool.frozen.sample_schema import ALIGN, BRUSH, SELECTION, Field, SampleType, sample_type
from hairtool.frozen.selection import BOX_MODES, OPS

BOX_WIDTH = 21  # a box selection's matrix (16), rectangle (4) and mode
_BOX_PARTS = {"matrix": slice(0, 16), "rect": slice(16, 20), "mode": slice(20, 21)}


@dataclass(frozen=True)
class Column:
    name: str
    group: str | None  # the manifest flag it is stored under; None: always stored
    dtype: type
    width: int  # numbers per sample; 0: one, as a 1-d array
    fill: Any  # what a sample with no field here stores


COLUMNS = (
    Column("cursor", None, np.float64, 3, (0.0, 0.0, 0.0)),
    Column("radius", None, np.float64, 0, 0.0),
    Column("intensity", None, np.float64, 0, 0.0),
    Column("mode", None, np.int64, 0, -1),
    Column("brush", "brushes", np.int64, 0, -1),
    Column("direction", "brushes", np.float64, 3, (0.0, 0.0, 0.0)),
    Column("falloff", "brushes", np.int64, 0, -1),
    Column("view", "views", np.float64, 3, (0.0, 0.0, 0.0)),
    Column("has_view", "views", np.int64, 0, 0),
    Column("collide", "collide", np.int64, 0, 1),
    Column("count", "plants", np.int64, 0, 1),
    Column("seed", "plants", np.int64, 0, 0),
    Column("spacing", "plants", np.float64, 0, 0.0),
    Column("start", "starts", np.int64, 0, 0),
    Column("only_selected", "only_selected", np.int64, 0, 0),
    Column("pressure", "pressure", np.float64, 0, 1.0),
    Column("any_segment", "any_segment", np.int64, 0, 0),
    Column("new_selection", "new_selection", np.int64, 0, 0),
    Column("visible", "visible", np.int64, 0, 0),
    Column("selection", "selection", np.int64, 0, -1),
    Column("box", "selection", np.float64, BOX_WIDTH, (0.0,) * BOX_WIDTH),
    Column("to_eye", "to_eye", np.int64, 0, 0),
    Column("eye", "eye", np.float64, 3, (0.0, 0.0, 0.0)),
    Column("has_eye", "eye", np.int64, 0, 0),
)
GROUPS = (
    "brushes", "views", "collide", "plants", "starts", "only_selected", "pressure", "any_segment",
    "new_selection", "visible", "selection", "to_eye", "eye",
)  # fmt: skip

#: The columns that say which samples hold a field of a kind that may be None (``view``, ``point``)
_PRESENT = {"has_view": "view", "has_eye": "eye"}


def _differs(log: Sequence, name: str, fill: Any) -> bool:
    return any(any(getattr(s, f.name) != fill for f in sample_type(s).by_column(name)) for s in log)


def _stored(group: str, log: Sequence, types: list[SampleType]) -> bool:
    """Whether the log needs a group's columns (as the writers before the schema decided)."""
    if group == "brushes":
        return any(t is not ALIGN for t in types)
    if group == "views":
        return any(s.view is not None for s in log)
    if group == "eye":
        return any(getattr(s, "eye", None) is not None for s in log)
    if group == "plants":  # a brush that plants strands, whatever its numbers
        pairs = zip(log, types, strict=True)
        return any(t.by_column("seed") and t.field("seed").used(t.which(s)) for s, t in pairs)
    if group == "selection":
        return any(t is SELECTION for t in types)
    name = "start" if group == "starts" else group  # a flag or number stored when not its fill
    return _differs(log, name, next(c.fill for c in COLUMNS if c.name == name))


class _Tables:
    """The lists a choice column indexes: align modes (sorted), brushes, steps, falloff curves."""

    def __init__(self, log: Sequence, types: list[SampleType]) -> None:
        self.modes = sorted({s.mode for s, t in zip(log, types, strict=True) if t is ALIGN})
        self.luts: list[tuple] = []
        for s, t in zip(log, types, strict=True):
            if t is BRUSH and s.lut not in self.luts:
                self.luts.append(s.lut)

    def index(self, f: Field, t: SampleType, value: Any) -> int:
        if f.kind == "falloff":
            return self.luts.index(value)
        return (self.modes if t is ALIGN else BRUSHES if t is BRUSH else OPS).index(value)


def _cell(column: Column, s: Any, t: SampleType, tables: _Tables) -> Any:
    """Sample ``s``'s entry in ``column``."""
    if column.name in _PRESENT:
        return int(getattr(s, _PRESENT[column.name], None) is not None)
    fields = t.by_column(column.name)
    if not fields:
        return column.fill
    if column.name == "box":
        row = list(column.fill)
        if s.op == "box":
            for f in fields:
                value = getattr(s, f.name)
                row[_BOX_PARTS[f.name]] = [float(BOX_MODES.index(value))] if f.name == "mode" else value
        return row
    (f,) = fields
    value = getattr(s, f.name)
    if f.kind in ("choice", "falloff"):
        return tables.index(f, t, value)
    if f.kind in ("view", "point"):
        return column.fill if value is None else value
    return int(value) if f.kind == "flag" else value


def write_columns(log: Sequence, arrays: dict[str, np.ndarray]) -> dict:
    """The log's columns into ``arrays`` (by member name); returns the manifest's section."""
    n = len(log)
    types = [sample_type(s) for s in log]
    tables = _Tables(log, types)
    info: dict[str, Any] = {"count": n, "modes": tables.modes}
    stored = {None} | {g for g in GROUPS if _stored(g, log, types)}
    for column in COLUMNS:
        if column.group not in stored:
            continue
        shape = (n, column.width) if column.width else (n,)
        cells = [_cell(column, s, t, tables) for s, t in zip(log, types, strict=True)]
        arrays[f"strokes/{column.name}.npy"] = np.array(cells, column.dtype).reshape(shape)
        if column.name == "falloff":
            luts = np.array(tables.luts, np.float64).reshape(len(tables.luts), LUT_SIZE)
            arrays["strokes/falloffs.npy"] = luts
    for group in GROUPS:
        if group in stored:
            info[group] = {"brushes": _brush_table(log, types), "selection": list(OPS)}.get(group, True)
    return info


#: The brush table every project wrote before a brush was added after select: a project
#: whose strokes use none of the later brushes writes exactly that table, so its bytes stay.
_TABLE_BEFORE_CUT = BRUSHES[: BRUSHES.index("select") + 1]


def _brush_table(log: Sequence, types: list[SampleType]) -> list[str]:
    """The brush names the ``brush`` column indexes: those up to the last brush the log uses,
    and never fewer than :data:`_TABLE_BEFORE_CUT` (a table is read by name, so any length
    that covers the log reads back)."""
    used = [BRUSHES.index(s.brush) for s, t in zip(log, types, strict=True) if t is BRUSH]
    return list(BRUSHES[: max(len(_TABLE_BEFORE_CUT), max(used, default=-1) + 1)])


class ColumnError(ValueError):
    """A column that does not fit the log (the caller names the file)."""


def read_columns(info: dict, array: Callable[[str, int, str], np.ndarray]) -> list:
    """The samples of a manifest's ``strokes`` section; ``array(member, ndim, kinds)`` reads
    one member (checked). Raises :class:`ColumnError` on columns that disagree."""
    n, modes = info.get("count"), info.get("modes")
    if not isinstance(n, int) or n < 0 or not isinstance(modes, list):
        raise ColumnError("manifest.json: bad 'strokes' section")
    tables: dict[SampleType, Any] = {ALIGN: modes, BRUSH: info.get("brushes")}
    tables[SELECTION] = info.get("selection")
    for t, names in ((BRUSH, BRUSHES), (SELECTION, OPS)):
        table = tables[t]
        if table is not None and (not isinstance(table, list) or any(x not in names for x in table)):
            raise ColumnError(f"manifest.json: the strokes name an unknown {t.name}")
    cols: dict[str, np.ndarray] = {}
    for column in COLUMNS:
        shape = (n, column.width) if column.width else (n,)
        if column.group is None or info.get(column.group):
            kinds = "f" if column.dtype is np.float64 else "iu"
            a = array(f"strokes/{column.name}.npy", len(shape), kinds)
            if a.shape != shape:
                raise ColumnError(f"strokes/{column.name}.npy holds {a.shape}, not {shape} for {n} strokes")
            if kinds == "f" and not np.all(np.isfinite(a)):
                raise ColumnError(f"strokes/{column.name}.npy holds a value that is not finite")
        else:
            a = np.full(shape, column.fill, column.dtype)
        cols[column.name] = a
    luts = np.zeros((0, LUT_SIZE))
    if info.get("brushes"):
        luts = array("strokes/falloffs.npy", 2, "f")
        if luts.shape[1:] != (LUT_SIZE,) or not np.all(np.isfinite(luts)):
            raise ColumnError(f"strokes/falloffs.npy is not finite curves of {LUT_SIZE} samples")
    return [_sample(k, cols, tables, luts) for k in range(n)]


def _choice(k: int, table: list | None, index: int, what: str) -> Any:
    if table is None or not 0 <= index < len(table):
        raise ColumnError(f"stroke {k} names an unknown {what}")
    return table[index]


def _sample(k: int, cols: dict[str, np.ndarray], tables: dict, luts: np.ndarray) -> Any:
    """Stroke ``k`` from its row of every column (unchecked beyond the columns' own sense)."""
    if cols["selection"][k] >= 0:
        t = SELECTION
    elif cols["brush"][k] >= 0:
        t = BRUSH
    else:
        t = ALIGN
    values: dict[str, Any] = {}
    for f in t.fields:
        if f.column == "box":
            continue  # below, once the step is known
        cell = cols[f.column][k]
        if f.kind == "choice":
            values[f.name] = str(_choice(k, tables[t], int(cell), f.name))
        elif f.kind == "falloff":
            values[f.name] = tuple(_choice(k, list(luts), int(cell), "falloff").tolist())
        elif f.kind == "vector":
            values[f.name] = tuple(float(x) for x in cell)
        elif f.kind in ("view", "point"):
            values[f.name] = tuple(float(x) for x in cell) if cols[f"has_{f.column}"][k] else None
        elif f.kind == "flag":
            values[f.name] = bool(cell)
        elif f.kind == "whole":
            values[f.name] = int(cell)
        else:
            values[f.name] = float(cell)
    if t is SELECTION and values["op"] == "box":
        row = cols["box"][k]
        m = row[20]
        if m not in (0.0, 1.0, 2.0):
            raise ColumnError(f"stroke {k}: a box selection's mode is {m!r}")
        values["matrix"] = tuple(float(x) for x in row[:16])
        values["rect"] = tuple(float(x) for x in row[16:20])
        values["mode"] = BOX_MODES[int(m)]
    if t is BRUSH:  # a stored brush's fields as stored: the project keeps what the sample held
        return BRUSH.cls(**values)
    return t.make(**values)
