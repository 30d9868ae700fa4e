"""Hypothesis strategies for stroke samples of every type, drawn from their descriptions
(:mod:`hairtool.frozen.sample_schema`): a field added there is drawn here with no edit."""

from __future__ import annotations

from typing import Any

from hypothesis import strategies as st

from hairtool.frozen.brushes import BRUSHES, FALLOFFS, falloff_lut
from hairtool.frozen.sample_schema import ALIGN, BRUSH, REQUIRED, SELECTION, Field, SampleType, strength_range

_coord = st.floats(-2.0, 2.0, allow_nan=False, allow_infinity=False)
_vector = st.tuples(_coord, _coord, _coord)
_view = _vector.filter(lambda v: any(x != 0.0 for x in v))


@st.composite
def _falloff(draw) -> tuple[float, ...]:
    """A preset's table, or an artist's curve of a few points from t = 0 to 1."""
    if draw(st.booleans()):
        return tuple(falloff_lut(draw(st.sampled_from(FALLOFFS))).tolist())
    inner = sorted(draw(st.sets(st.floats(0.01, 0.99), max_size=4)))
    ts = [0.0, *inner, 1.0]
    ws = draw(st.lists(st.floats(0.0, 1.0), min_size=len(ts), max_size=len(ts)))
    return tuple(falloff_lut([[t, w] for t, w in zip(ts, ws, strict=True)]).tolist())


def _number(f: Field, by: str) -> st.SearchStrategy[float]:
    low, high = strength_range(by) if f.name == "strength" else (f.low, f.high)
    low = 0.0 if low is None else low
    high = 2.0 if high is None else high
    if f.low_open:
        low = max(low, 1e-3)
    return st.floats(low, high, allow_nan=False, allow_infinity=False)


def _field(f: Field, by: str) -> st.SearchStrategy[Any]:
    if not f.used(by):
        return st.just(f.default)
    kind = f.kind
    if kind == "vector":
        return _vector
    if kind == "view":
        return st.none() | _view
    if kind == "point":
        return st.none() | _vector
    if kind == "number":
        return _number(f, by)
    if kind == "whole":
        return st.integers(int(f.low), min(int(f.high), 2**32 - 1))
    if kind == "flag":
        return st.booleans()
    if kind == "choice":
        return st.sampled_from(f.choices)
    if kind == "falloff":
        return _falloff()
    if kind == "matrix":
        return st.tuples(*[_coord] * 16)
    if kind == "rect":
        return st.tuples(*[_coord] * 4)
    raise AssertionError(f"no strategy for a {kind} field")


@st.composite
def sample_of(draw, t: SampleType, by: str | None = None) -> Any:
    """One sample of type ``t`` (of brush or step ``by``, else any), every field it uses drawn."""
    if t.key is not None:
        by = by or draw(st.sampled_from(t.field(t.key).choices))
    else:
        by = t.name
    values = {f.name: draw(_field(f, by)) for f in t.fields if f.name != t.key}
    if t.key is not None:
        values[t.key] = by
    for f in t.fields:
        assert f.default is not REQUIRED or f.name in values
    return t.make(**values)


BRUSH_NAMES = BRUSHES[1:]
any_sample = st.one_of(sample_of(ALIGN), sample_of(BRUSH), sample_of(SELECTION))
logs = st.lists(any_sample, max_size=12).map(tuple)
