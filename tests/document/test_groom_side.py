"""The groom side of the document, by example where the state machine cannot reach: a stroke the
engine thread applied and the studio records on release, the view settings (kept, saved, not a
step), a hide that would hide everything, a head that strokes still need, and Cancel."""

from __future__ import annotations

import numpy as np
import pytest

from app.document import project_io
from app.document.animation import Document
from app.document.groom import GroomState
from app.ui.brush_tool import BrushTool
from hairtool import samples
from hairtool.errors import HairtoolError, ParameterError
from hairtool.frozen.selection import SelectionSample

from .test_document_states import head, snapshot_arrays


def tiny() -> GroomState:
    return GroomState(samples.scalp(strands=12, vertices=4), mesh=head(), source="tiny.tfx")


def moves(brush: str, doc: Document, n: int = 2) -> list[list]:
    tool = BrushTool(brush=brush, only_selected=False)
    tool.reset_radius(0.8)
    at = doc.hair.pipeline.aligned.points[3].astype(np.float64)
    return [tool.samples(at + 0.1 * k, (0.2, 0.0, 0.0), None, 0.0, start=k == 0) for k in range(n)]


def test_a_stroke_the_engine_thread_applied_is_one_step_recorded_on_release():
    doc = Document(tiny())
    before = doc.hair.state
    for samples_ in moves("comb", doc, 3):  # what the engine thread does, move by move
        doc.hair.pipeline.apply_samples(samples_)
    doc.hair.record(before, "Comb stroke")
    doc.hair.end_stroke()
    assert doc.stack.index == 1 and doc.stack.undo_text == "Comb stroke" and doc.changed
    assert len(doc.hair.state.strokes.log) == 3
    after = snapshot_arrays(doc.hair.state)
    doc.undo()
    assert snapshot_arrays(doc.hair.state) == snapshot_arrays(before)
    assert doc.hair.pipeline.strokes == ()  # the engine follows the document back
    doc.redo()
    assert snapshot_arrays(doc.hair.state) == after
    doc.hair.record(doc.hair.state)  # nothing applied since: no step
    assert doc.stack.index == 1


def test_moves_of_one_stroke_merge_and_a_new_stroke_is_a_new_step():
    doc = Document(tiny())
    for samples_ in moves("smooth", doc):
        doc.hair.stroke(samples_, stroke=1)
    for samples_ in moves("puff", doc):
        doc.hair.stroke(samples_, stroke=2)
    assert doc.stack.index == 2
    doc.undo()
    assert len(doc.hair.state.strokes.log) == 2


def test_view_settings_are_saved_but_not_a_step(tmp_path):
    doc = Document(tiny())
    doc.hair.set_view(ortho=True, camera={"yaw": 30.0})
    assert doc.stack.index == 0 and not doc.changed
    project_io.save(doc, tmp_path / "v.hairproj")
    back = project_io.load(tmp_path / "v.hairproj")
    assert dict(back.hair.view) == {"ortho": True, "camera": {"yaw": 30.0}}


def test_refusals_change_nothing():
    doc = Document(tiny())
    assert doc.hair.select(SelectionSample("all")) is False  # all are selected already: no step
    with pytest.raises(ParameterError, match="hide"):
        doc.hair.select(SelectionSample("hide_selected"))  # every strand would be hidden
    doc.hair.stroke(moves("slide", doc, 1)[0])
    state = doc.hair.state
    with pytest.raises(HairtoolError):
        doc.hair.set_mesh(None)  # the slide stroke needs its head
    assert doc.hair.state is state and doc.stack.index == 1
    assert doc.hair.pipeline.surface is not None


def test_cancel_keeps_the_groom_and_opening_one_closes_its_simulation():
    from hairtool.simulate.options import SimulateOptions, run_simulation

    doc = Document(tiny())
    g = doc.groom
    sim = run_simulation(g, SimulateOptions(frames=3, substeps=1), lambda *a: None, lambda: False)
    doc.replace_animation(sim, "simulation")
    other = GroomState(samples.scalp(strands=8, vertices=4, seed=1))
    assert not doc.open_groom(other, confirm=lambda: False)
    assert doc.groom is g and doc.state.animation is sim
    assert doc.open_groom(other, confirm=lambda: True)
    assert doc.groom is other.rest and doc.state.animation is None
    doc.undo()  # one step brings both back
    assert doc.groom is g and doc.state.animation is sim


def test_before_the_engine_is_built_edits_need_none_and_a_slider_drag_is_one_step():
    """A first start edits parameters, the up axis and the head while its kernels compile: each
    is a step that builds no engine; the engine made later is made on all of them."""
    doc = Document(tiny())
    side = doc.hair
    for k in (4.0, 5.0, 6.0):  # one slider drag
        side.set_params(side.state.params.replace(bend_stiffness=k), "Change bend stiffness", drag=1)
    side.set_params(side.state.params.replace(seed=9), "Change seed", drag=2)
    side.set_up_axis("Z")
    side.set_mesh(None)
    assert side._pipeline is None  # (nothing compiled or built)
    assert doc.stack.index == 4 and doc.stack.undo_text == "Head mesh"
    made = side.pipeline
    assert made.rest.metadata.up_axis == "Z" and made.params.bend_stiffness == 6.0 and made.surface is None
    for _ in range(3):
        doc.undo()
    assert side.state.params.bend_stiffness == 6.0 and side.state.params.seed != 9
    doc.undo()
    assert side.state.params == tiny().params and side.pipeline.params == tiny().params


def test_a_document_opened_is_no_step_and_clump_children_is_one():
    doc = Document(tiny())
    other = GroomState(samples.scalp(strands=9, vertices=4, seed=3), mesh=head())
    heard = []
    doc.hair.observe(lambda: heard.append(doc.hair.state))
    doc.hair.reset(other)
    assert doc.hair.state is other and heard == [other] and doc.stack.count == 0
    doc.hair.set_clump_children(True)
    assert doc.hair.state.clump_children and doc.stack.undo_text == "Clump children"
    doc.undo()
    assert doc.hair.state is other


def test_an_undo_in_the_middle_of_a_stroke_drops_its_moves_not_the_document():
    """Ctrl+Z while the mouse still drags: the step before is undone, the rest of the stroke's
    moves are dropped on release, and the engine shows the document's state again."""
    doc = Document(tiny())
    first = doc.hair.state
    doc.hair.stroke(moves("comb", doc, 1)[0], stroke="first")
    shaped = doc.hair.state
    before = doc.hair.state
    doc.hair.pipeline.apply_samples(moves("length", doc, 1)[0])  # the engine thread's move
    doc.undo()  # Ctrl+Z mid-drag
    doc.hair.pipeline.apply_samples(moves("length", doc, 1)[0])  # a move after it
    doc.hair.record(before, "Length stroke")
    doc.hair.end_stroke()
    assert doc.hair.state is first and doc.stack.count == 1 and doc.stack.can_redo
    fresh = Document(first).hair.result
    assert doc.hair.result.points.tobytes() == fresh.points.tobytes()
    doc.redo()
    assert doc.hair.state is shaped
