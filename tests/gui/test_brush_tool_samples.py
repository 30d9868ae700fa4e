"""The studio's samples (the brush tool's mouse moves) hold what their description says each
brush uses, with every other field at its default, and go through a stroke log and a project
unchanged: the fourth encoding of a sample checked against the other three."""

from __future__ import annotations

from hypothesis import given, settings
from hypothesis import strategies as st

from app.ui.brush_tool import BrushTool, brushes
from hairtool import project as pf
from hairtool import samples
from hairtool.frozen.brushes import check_sample
from hairtool.frozen.sample_schema import REQUIRED, sample_type
from hairtool.frozen.strokes import read_strokes, strokes_from_log, write_strokes

REST = samples.portrait(strands=6, vertices=4)
_coord = st.floats(-1.0, 1.0, allow_nan=False)
_vector = st.tuples(_coord, _coord, _coord).filter(lambda v: any(x != 0.0 for x in v))


@st.composite
def moves(draw):
    tool = BrushTool(
        symmetry=draw(st.booleans()),
        front_only=draw(st.booleans()),
        only_selected=draw(st.booleans()),
        add_count=draw(st.integers(1, 20)),
        spacing=draw(st.floats(0.01, 0.5)),
        delete_any_segment=draw(st.booleans()),
        falloff=draw(st.sampled_from(("smooth", "linear", "constant"))),
        align_mode=draw(st.sampled_from(("paper", "preserve-length"))),
    )
    tool.reset_radius(draw(st.floats(0.01, 1.0)))
    tool.set_brush(draw(st.sampled_from(brushes())))
    tool.pressure_radius[tool.brush] = draw(st.booleans())
    tool.pressure_strength[tool.brush] = draw(st.booleans())
    per_move = []
    eye = draw(st.none() | _vector)  # a perspective camera's, or none (orthographic)
    for i in range(draw(st.integers(1, 3))):
        cursor, direction, view = draw(_vector), draw(_vector), draw(_vector)
        invert, pressure, add = draw(st.booleans()), draw(st.floats(0.0, 1.0)), draw(st.booleans())
        plane = draw(_coord)
        per_move.append(tool.samples(cursor, direction, view, plane, invert, i == 0, pressure, add, eye))
    return per_move


@settings(max_examples=40, deadline=None)
@given(per_move=moves())
def test_the_studios_samples_follow_their_description_and_round_trip(tmp_path_factory, per_move):
    log = tuple(s for move in per_move for s in move)
    for s in log:
        t = sample_type(s)
        by = t.which(s)
        for f in t.fields:
            if not f.used(by) and f.default is not REQUIRED:
                assert getattr(s, f.name) == f.default, (by, f.name)
        if t.key is not None:
            check_sample(s)
    folder = tmp_path_factory.mktemp("tool")
    pf.save(folder / "p.hairproj", pf.Project(rest=REST, strokes=log))
    assert pf.load(folder / "p.hairproj").strokes == log
    write_strokes(folder / "s.json", strokes_from_log(log))
    assert tuple(s for stroke in read_strokes(folder / "s.json") for s in stroke.pipeline_samples(0.0)) == log


def test_a_plain_select_drag_starts_a_new_selection_shift_adds_and_ctrl_deselects():
    """As Blender's Selection Paint: the first move of a plain drag starts a new selection (not
    its mirror, nor the later moves); Shift+drag adds, Ctrl+drag deselects. Only a brush whose
    spec starts anew takes Shift from the view's pan."""
    tool = BrushTool(symmetry=True)
    tool.reset_radius(0.1)
    tool.set_brush("select")
    assert tool.shift_adds()
    at, d = (0.3, 0.0, 0.0), (0.1, 0.0, 0.0)
    first, mirror = tool.samples(at, d, None, 0.0, start=True)
    assert first.new_selection and first.strength > 0 and not mirror.new_selection
    assert not any(s.new_selection for s in tool.samples(at, d, None, 0.0))
    shift = tool.samples(at, d, None, 0.0, start=True, add=True)[0]
    assert shift.strength > 0 and not shift.new_selection
    ctrl = tool.samples(at, d, None, 0.0, invert=True, start=True)[0]
    assert ctrl.strength < 0 and not ctrl.new_selection
    tool.set_brush("mask")
    assert not tool.shift_adds() and not tool.samples(at, d, None, 0.0, start=True)[0].new_selection
