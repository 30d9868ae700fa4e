"""Selection and hiding through the studio: the Select brush paints the selection (a plain
drag starts a new one, Shift adds, Ctrl deselects), B then a drag box-selects, A / Alt+A /
Ctrl+I select all, none and invert, H / Shift+H / Alt+H hide and reveal (hidden strands are not
drawn, unselected ones dimmed), a brush with Affect selection only leaves the unselected strands
alone, each step is one undo step, and a saved project reopens with the same selection, hiding
and toggle."""

from __future__ import annotations

import numpy as np
import pytest
from PySide6.QtCore import Qt

from hairtool import samples

pytestmark = pytest.mark.gui

CTRL = Qt.KeyboardModifier.ControlModifier
SHIFT = Qt.KeyboardModifier.ShiftModifier


def flat(make_window):
    """A comb of 8 × 8 strands seen from its front and a little above: columns across the
    screen (front faces only off: seen from above, a comb's roots all face away)."""
    w = make_window(groom=samples.comb(64, 10))
    w.scene.set_params(w.scene.params.replace(freeze=False, clump=False))
    w.scene.set_front_only(False)
    return w


def columns(w):
    """Screen x of each strand's root."""
    return w.viewport.project(w.scene.result.roots)[:, 0]


def test_box_select_then_hide_unselected_and_reveal(ui, make_window):
    w = flat(make_window)
    s, v = w.scene, w.viewport
    assert s.selected.all()
    x = columns(w)
    tips = v.project(s.result.tips)
    left = x < np.median(x)
    a = (x.min() - 5.0, min(tips[:, 1].min(), v.project(s.result.roots)[:, 1].min()) - 5.0)
    b = (np.median(x) - 1.0, max(tips[:, 1].max(), v.project(s.result.roots)[:, 1].max()) + 5.0)
    w.selection.actions["none"].trigger()
    assert not s.selected.any()
    w.selection.actions["box"].trigger()
    assert v.box_armed
    ui.drag(v, a, b, steps=5)
    assert not v.box_armed  # one box per B, as in Blender
    np.testing.assert_array_equal(s.selected, left)
    ui.drag(v, a, b, steps=5)  # disarmed: a plain drag is the brush again (align), selection kept
    np.testing.assert_array_equal(s.selected, left)
    drawn_before = v.drawn().strand_count
    w.selection.actions["hide_unselected"].trigger()
    np.testing.assert_array_equal(s.hidden, ~left)
    d = v.drawn()
    assert d.strand_count == left.sum() < drawn_before  # hidden strands are not drawn
    v.repaint()
    w.selection.actions["reveal"].trigger()
    assert not s.hidden.any() and s.selected.all()  # revealed strands come back selected
    assert v.drawn().strand_count == drawn_before
    texts = []
    for _ in range(5):  # reveal, hide, the align stroke, box, none: one undo step each
        texts.append(w.undo_stack.undoText())
        w.undo_stack.undo()
    assert texts == ["Reveal hidden", "Hide unselected", "Align stroke", "Box select", "Select none"]
    assert s.selected.all() and not s.hidden.any()
    w.undo_stack.redo()
    assert not s.selected.any()


def test_ctrl_box_deselects_and_escape_cancels(ui, make_window):
    w = flat(make_window)
    s, v = w.scene, w.viewport
    x = columns(w)
    ys = v.project(s.result.points)[:, 1]
    a, b = (x.min() - 5.0, ys.min() - 5.0), (np.median(x) - 1.0, ys.max() + 5.0)
    w.selection.actions["box"].trigger()
    ui.drag(v, a, b, steps=4, modifiers=CTRL)
    np.testing.assert_array_equal(s.selected, x >= np.median(x))
    w.selection.actions["invert"].trigger()
    np.testing.assert_array_equal(s.selected, x < np.median(x))
    w.selection.actions["box"].trigger()
    ui.send_mouse(v, "move", (10, 10))
    from PySide6.QtTest import QTest

    QTest.keyClick(v, Qt.Key.Key_Escape)
    assert not v.box_armed


def test_a_box_with_front_faces_only_judges_by_sight(ui, make_window, monkeypatch):
    """The studio's box says ``visible`` where Front faces only gives it a camera, as its
    brushes do, and ``to_eye`` in the 3-D (perspective) view only (the step itself: hairtool's
    tests/frozen/test_sight_box_plant.py and test_sight_box_perspective.py)."""
    w = flat(make_window)
    s, v = w.scene, w.viewport
    x = columns(w)
    ys = v.project(s.result.points)[:, 1]
    a, b = (x.min() - 5.0, ys.min() - 5.0), (np.median(x) - 1.0, ys.max() + 5.0)
    steps = []
    monkeypatch.setattr(s, "selection_step", lambda sample, text="": steps.append(sample) or True)
    for front in (True, False):
        s.set_front_only(front)
        w.selection.actions["box"].trigger()
        ui.drag(v, a, b, steps=3)
    persp = not v.camera.ortho
    assert [(t.view is not None, t.visible, t.to_eye) for t in steps] == [
        (True, True, persp),
        (False, False, False),
    ]
    s.set_front_only(True)
    v.set_ortho(persp)  # the other camera
    w.selection.actions["box"].trigger()
    ui.drag(v, a, b, steps=3)
    assert len(steps) == 3 and steps[-1].visible and steps[-1].to_eye is not persp


def test_paint_select_and_brush_only_the_selection(ui, make_window):
    w = flat(make_window)
    s, v = w.scene, w.viewport
    s.set_brush("select")
    x = columns(w)
    mid = v.project(s.result.points[s.result.offsets[:-1] + 5])  # halfway down each strand
    target = int(np.argmin(np.abs(x - np.median(x))))
    s.set_radius(0.3 * float(np.ptp(s.result.roots[:, 0])))
    start = mid[target]
    ui.drag(v, start, start + np.array([1.0, 0.0]), steps=2, modifiers=CTRL)  # Ctrl: deselect under the brush
    off = ~s.selected
    assert 0 < off.sum() < s.result.strand_count
    assert w.undo_stack.undoText() == "Select stroke"
    assert s.tool.only_selected  # on by default, as Blender's selection toggle
    s.set_brush("comb")
    s.set_intensity(1.0)
    s.set_radius(2.0 * float(np.ptp(s.result.points, axis=0).max()))  # the brush covers everything
    before = s.result.points.copy()
    ui.drag(v, start, start + np.array([60.0, 0.0]), steps=6)
    moved = np.any(s.result.points != before, axis=1)
    per_strand = np.maximum.reduceat(moved, s.result.offsets[:-1]).astype(bool)
    np.testing.assert_array_equal(per_strand, ~off)  # the unselected strands stayed put
    w.selection.actions["only"].trigger()  # off: every strand
    assert not s.tool.only_selected
    ui.drag(v, start, start + np.array([60.0, 0.0]), steps=6)
    moved = np.any(s.result.points != before, axis=1)
    assert np.maximum.reduceat(moved, s.result.offsets[:-1]).all()


def test_a_select_drag_starts_a_new_selection_shift_adds_and_ctrl_deselects(ui, make_window):
    """Blender's Selection Paint on a new groom (every strand selected): a plain drag leaves only
    the strands it touched selected, Shift+drag adds others without panning the view, Ctrl+drag
    takes some away; each drag one undo step, undone in turn."""
    w = flat(make_window)
    s, v = w.scene, w.viewport
    s.set_brush("select")
    x = columns(w)
    mid = v.project(s.result.points[s.result.offsets[:-1] + 5])
    s.set_radius(0.2 * float(np.ptp(s.result.roots[:, 0])))
    left, right = mid[int(np.argmin(x))], mid[int(np.argmax(x))]
    assert s.selected.all()
    ui.drag(v, left, left + np.array([1.0, 0.0]), steps=2)
    first = s.selected.copy()
    assert 0 < first.sum() < 0.5 * s.result.strand_count
    assert first[int(np.argmin(x))] and not first[int(np.argmax(x))]
    eye = v.camera.view_projection(v.width(), v.height()).copy()
    ui.drag(v, right, right + np.array([1.0, 0.0]), steps=2, modifiers=SHIFT)
    assert np.array_equal(v.camera.view_projection(v.width(), v.height()), eye)  # no pan
    both = s.selected.copy()
    assert (both >= first).all() and both[int(np.argmax(x))] and both.sum() < s.result.strand_count
    ui.drag(v, left, left + np.array([1.0, 0.0]), steps=2, modifiers=CTRL)
    assert not s.selected[int(np.argmin(x))] and s.selected[int(np.argmax(x))]
    assert w.undo_stack.undoText() == "Select stroke"
    for was in (both, first):
        w.undo_action.trigger()
        np.testing.assert_array_equal(s.selected, was)
    s.set_brush("comb")  # any other brush: Shift+left-drag pans, as before
    ui.drag(v, left, left + np.array([30.0, 0.0]), steps=2, modifiers=SHIFT)
    assert not np.array_equal(v.camera.view_projection(v.width(), v.height()), eye)
    np.testing.assert_array_equal(s.selected, first)


def test_unselected_strands_are_dimmed_and_a_brush_with_nothing_selected_says_why(ui, make_window):
    w = flat(make_window)
    s, v = w.scene, w.viewport
    w.selection.actions["all"].trigger()
    assert v.drawn().colors is None  # everything selected: the plain ramp
    w.selection.actions["none"].trigger()
    assert v.drawn().colors is None  # nothing selected: nothing to tell apart
    messages = []
    s.refused.connect(messages.append)
    s.set_brush("comb")
    x = columns(w)
    y = v.project(s.result.points)[:, 1]
    ui.drag(v, (x.mean(), y.mean()), (x.mean() + 40, y.mean()), steps=3)
    assert messages and "no shown strand is selected" in messages[-1]
    s.set_brush("select")
    s.set_radius(0.05)
    top = s.result.offsets[:-1][0]
    p = v.project(s.result.points[top + 5 : top + 6])[0]
    ui.drag(v, p, p + np.array([1.0, 0.0]), steps=2)
    assert 0 < s.selected.sum() < s.result.strand_count
    colors = v.drawn().colors
    ramp = v.drawn(mask=False).colors
    assert colors is not None and ramp is None  # the dimming is a working overlay
    sel = np.repeat(s.selected, s.result.counts)
    assert colors[~sel].mean() < colors[sel].mean()
    w.selection.actions["hide_unselected"].trigger()
    w.selection.actions["hide_selected"].trigger()  # would hide everything: refused, said
    assert not s.hidden.all() and "every strand" in messages[-1]


def test_a_project_keeps_the_selection_hiding_and_toggle(ui, make_window, tmp_path):
    w = flat(make_window)
    s, v = w.scene, w.viewport
    x = columns(w)
    ys = v.project(s.result.points)[:, 1]
    w.selection.actions["box"].trigger()
    a, b = (x.min() - 5.0, ys.min() - 5.0), (np.median(x) - 1.0, ys.max() + 5.0)
    ui.drag(v, a, b, steps=4, modifiers=CTRL)
    w.selection.actions["hide_selected"].trigger()
    s.set_only_selected(False)
    selected, hidden = s.selected.copy(), s.hidden.copy()
    assert hidden.any() and not hidden.all()
    path = tmp_path / "sel.hairproj"
    assert w.project.save_to(path), w.errors
    w2 = make_window()
    assert w2.project.open_project(path), w2.errors
    s2 = w2.scene
    np.testing.assert_array_equal(s2.selected, selected)
    np.testing.assert_array_equal(s2.hidden, hidden)
    assert not s2.tool.only_selected and not w2.selection.actions["only"].isChecked()
    assert w2.viewport.drawn().strand_count == (~hidden).sum()
