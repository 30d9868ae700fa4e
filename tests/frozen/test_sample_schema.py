"""One description per stroke-sample type: the classes match it, and logs of every type,
generated from it, go through a stroke log and a project and come back equal, bytes and all."""

from __future__ import annotations

import dataclasses
import io

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from hairtool import project as pf
from hairtool import samples
from hairtool.frozen.brushes import BrushSample, falloff_lut
from hairtool.frozen.pipeline import AlignSample
from hairtool.frozen.sample_schema import ALIGN, BRUSH, REQUIRED, SELECTION, TYPES, sample_type
from hairtool.frozen.selection import SelectionSample
from hairtool.frozen.strokes import (
    Stroke,
    StrokeSample,
    read_strokes,
    stroke_from_dict,
    strokes_from_log,
    write_strokes,
)

from .sample_strategies import BRUSH_NAMES, logs, sample_of

ROUND_TRIPS = settings(
    max_examples=60, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
REST = samples.portrait(strands=6, vertices=4)
LUT = tuple(falloff_lut("smooth").tolist())


def _class_fields(cls) -> dict:
    if dataclasses.is_dataclass(cls):
        none = dataclasses.MISSING
        return {f.name: (REQUIRED if f.default is none else f.default) for f in dataclasses.fields(cls)}
    return {name: cls._field_defaults.get(name, REQUIRED) for name in cls._fields}


@pytest.mark.parametrize("t", TYPES, ids=lambda t: t.name)
def test_each_sample_class_holds_the_fields_of_its_description(t):
    described = {f.name: f.default for f in t.fields}
    assert _class_fields(t.cls) == described
    assert len({f.name for f in t.fields}) == len(t.fields)
    assert all(f.column and f.json and f.level in ("sample", "stroke", "params", "step") for f in t.fields)


def test_a_stroke_logs_sample_holds_the_log_fields_of_brush_and_align_samples():
    """StrokeSample is a log's sample: one field per log name of a brush's (and align's) sample fields."""
    from hairtool.frozen.strokes import LOG_SAMPLE

    names = [f.name for f in dataclasses.fields(StrokeSample)]
    assert sorted(names) == sorted(f.json for f in LOG_SAMPLE)
    assert {f.json for f in ALIGN.at("sample")} <= set(names)


def test_make_fills_defaults_and_leaves_what_a_brush_does_not_use():
    d = (0.0, 0.0, 0.0)
    s = BRUSH.make(
        brush="comb", cursor=(0, 1, 0), direction=d, radius=0.1, strength=0.5, lut=LUT, count=9, start=True
    )
    assert s == BrushSample(
        "comb", (0, 1, 0), (0.0, 0.0, 0.0), 0.1, 0.5, LUT
    )  # count and start: add's, hook's
    s = BRUSH.make(
        brush="add", cursor=(0, 1, 0), direction=d, radius=0.1, strength=0.5, lut=LUT, count=9, seed=4
    )
    assert (s.count, s.seed, s.start) == (9, 4, False)
    with pytest.raises(TypeError, match="radius"):
        BRUSH.make(brush="comb", cursor=(0, 1, 0), direction=d, strength=0.5, lut=LUT)
    with pytest.raises(TypeError, match="colour"):
        ALIGN.make(cursor=(0, 1, 0), radius=0.1, intensity=0.5, mode="paper", colour=1)
    assert sample_type(SelectionSample("all")) is SELECTION


# -- the faults of issue 43: a log mixing planting brushes with NamedTuple samples ----------
MIXED = (
    AlignSample((0.0, 0.1, 0.0), 0.06, 0.4, "paper"),
    BrushSample("add", (0.0, 0.1, 0.0), (0.0, 0.0, 0.0), 0.05, 0.5, LUT, count=3, seed=7),
    SelectionSample("invert"),
    BrushSample("density", (0.0, 0.1, 0.0), (0.0, 0.0, 0.0), 0.05, 0.5, LUT, seed=2, spacing=0.01),
    AlignSample((0.0, 0.1, 0.0), 0.06, 0.4, "preserve-length", pressure=0.5),
)


@pytest.mark.parametrize("log", [MIXED[:2], MIXED[1:4], MIXED], ids=["add+align", "add+selection", "all"])
def test_a_project_with_add_or_density_beside_align_or_selection_saves_and_reads_back(tmp_path, log):
    path = tmp_path / "p.hairproj"
    pf.save(path, pf.Project(rest=REST, strokes=log))  # main: TypeError from tuple.count
    assert pf.load(path).strokes == log


# -- generated round trips ------------------------------------------------------------------
def _npy(array: np.ndarray) -> bytes:
    buf = io.BytesIO()
    np.lib.format.write_array(buf, np.ascontiguousarray(array), allow_pickle=False)
    return buf.getvalue()


@ROUND_TRIPS
@given(log=logs)
def test_any_log_goes_through_a_project_and_back(tmp_path_factory, log):
    path = tmp_path_factory.mktemp("p") / "p.hairproj"
    pf.save(path, pf.Project(rest=REST, strokes=log))
    back = pf.load(path)
    assert back.strokes == log
    (m1, a1), (m2, a2) = (
        pf.manifest_and_arrays(pf.Project(rest=REST, strokes=log)),
        pf.manifest_and_arrays(back),
    )
    assert m1["strokes"] == m2["strokes"] and m1["version"] == m2["version"]
    assert {n: _npy(a) for n, a in a1.items()} == {n: _npy(a) for n, a in a2.items()}


@ROUND_TRIPS
@given(log=logs)
def test_any_log_goes_through_a_stroke_log_and_back(tmp_path_factory, log):
    path = tmp_path_factory.mktemp("s") / "s.json"
    write_strokes(path, strokes_from_log(log))
    replayed = tuple(s for stroke in read_strokes(path) for s in stroke.pipeline_samples(0.0))
    assert replayed == log
    again = path.with_name("again.json")
    write_strokes(again, read_strokes(path))
    assert again.read_bytes() == path.read_bytes()


@st.composite
def strokes(draw) -> Stroke:
    """A stroke as an artist draws it: one brush, several samples, symmetry and a pen."""
    brush = draw(st.sampled_from(("align", *BRUSH_NAMES)))
    t = ALIGN if brush == "align" else BRUSH
    first = draw(sample_of(t, None if brush == "align" else brush))
    moves = draw(st.lists(sample_of(t, None if brush == "align" else brush), min_size=1, max_size=4))
    log = strokes_from_log([first])
    stroke = log[0]
    extra = strokes_from_log(moves)  # the same stroke's later samples, their own values
    samples_ = [*stroke.samples, *(s for e in extra for s in e.samples)]
    samples_ = [
        dataclasses.replace(s, start=None) if brush == "snake_hook" and i else s
        for i, s in enumerate(samples_)
    ]
    symmetry = draw(st.sampled_from((None, "x")))
    mirror = draw(st.none() | st.floats(-1.0, 1.0))
    return dataclasses.replace(stroke, samples=tuple(samples_), symmetry=symmetry, mirror_x=mirror)


@ROUND_TRIPS
@given(stroke=strokes(), default_mirror=st.floats(-1.0, 1.0))
def test_a_stroke_with_symmetry_and_pressure_reads_back_as_written(stroke, default_mirror):
    back = stroke_from_dict(stroke.to_dict())
    assert back == stroke
    assert back.pipeline_samples(default_mirror) == stroke.pipeline_samples(default_mirror)
    n = len(stroke.samples) * (2 if stroke.symmetry == "x" else 1)
    assert len(stroke.pipeline_samples(default_mirror)) == n
    assert all(isinstance(s, StrokeSample) for s in back.samples)
