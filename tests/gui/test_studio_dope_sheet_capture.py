"""The dope sheet on real captures: a click pins a key without moving it (at 1,064 frames a pixel
is more than a frame), a drag moves it, Ctrl+wheel zooms about the cursor, a middle drag pans,
Home shows every frame; the key error shown is the objective the solve minimised, which a pin
and a move can only raise."""

from __future__ import annotations

import numpy as np
import pytest
from PySide6.QtCore import QPoint, QPointF, Qt
from PySide6.QtGui import QWheelEvent
from PySide6.QtTest import QTest
from PySide6.QtWidgets import QApplication

from hairtool.keys.dp import select_keys

pytestmark = pytest.mark.gui

LEFT, MIDDLE = Qt.MouseButton.LeftButton, Qt.MouseButton.MiddleButton
LONG = "tests/data/motion/pymo_walk.bvh"  # 1,064 frames at 120 fps
WALK = "tests/data/motion/mocapbank_walk.bvh"  # 455 frames


def _open(make_window, path):
    w = make_window(size=(1100, 800))
    assert w.open_path(path), w.errors
    assert w.animation.dp_keys is not None
    return w, w.animation, w.timeline.view


def _wheel(view, x: float, notches: int, modifiers=Qt.KeyboardModifier.ControlModifier) -> None:
    local = QPointF(x, view.row_rect("curves").center().y())
    event = QWheelEvent(local, QPointF(view.mapToGlobal(local)), QPoint(0, 0), QPoint(0, 120 * notches),
                        Qt.MouseButton.NoButton, modifiers, Qt.ScrollPhase.NoScrollPhase, False)  # fmt: skip
    QApplication.sendEvent(view, event)


def test_a_click_pins_a_key_without_moving_it_on_a_long_capture(ui, make_window):
    w, m, view = _open(make_window, LONG)
    assert m.n_frames == 1064 and view._frames_per_px() > 1.0  # a pixel is more than a frame
    keys = m.dp_keys.copy()
    key = int(keys[len(keys) // 2])
    y = view.row_rect("dp").center().y()
    x = view.frame_to_x(key)
    wobble = QApplication.startDragDistance() - 1
    ui.send_mouse(view, "press", (x, y), LEFT, LEFT)
    ui.send_mouse(view, "move", (x + wobble, y), None, LEFT)
    ui.send_mouse(view, "release", (x + wobble, y), LEFT, None)
    assert w.undo_stack.undoText() == f"Pin key {key}" and m.settings.pins == (key,)
    assert m.settings.excludes == () and m.frame == key
    np.testing.assert_array_equal(m.dp_keys, keys)
    ui.drag(view, (x, y), (x + 3 * QApplication.startDragDistance(), y), steps=6)  # a drag moves
    assert w.undo_stack.undoText().startswith(f"Move key {key} to ") and key in m.settings.excludes


def test_zoom_about_the_cursor_middle_drag_pan_and_home(ui, make_window):
    _, m, view = _open(make_window, LONG)
    x = view.frame_to_x(700)
    _wheel(view, x, 3)
    v0, v1 = view.view_range
    assert view.zoomed and v1 - v0 == pytest.approx(1063 / 1.25**3)
    assert view.x_to_frame(x) == 700  # the frame under the cursor stays put
    assert all(int(k) in view.visible_frames() or not v0 <= k <= v1 for k in m.dp_keys)
    ui.drag(view, (x, 100), (x - 200, 100), steps=4, button=MIDDLE)  # pan toward later frames
    assert view.view_range[0] == pytest.approx(v0 + 200 * (v1 - v0) / (view.width() - 68), abs=0.5)
    assert m.frame == 0  # panning is not scrubbing
    _wheel(view, x, -1, Qt.KeyboardModifier.NoModifier)  # zoomed in, the wheel walks on
    assert view.view_range[0] > v0
    view.setFocus()
    QTest.keyClick(view, Qt.Key.Key_Home)
    assert not view.zoomed and view.view_range == (0.0, 1063.0) and m.frame == 0
    _wheel(view, view.frame_to_x(10), 8)
    m.set_frame(900)  # zoomed in, the view follows the playhead
    assert view.view_range[0] <= 900 <= view.view_range[1]


def test_the_key_error_shown_is_the_objective_solved_and_steering_only_raises_it(ui, make_window):
    w, m, view = _open(make_window, WALK)
    m.set_key_count(20)
    table, count = m.key_solve.table, 20
    free = select_keys(table, keys=count)  # the library's own DP, unconstrained
    np.testing.assert_array_equal(m.dp_keys, free.keys)
    e0, uniform0 = m.key_errors()
    assert e0 == free.cost and uniform0 == free.uniform_cost
    assert f"solved key error {e0:.4g} (uniform keys {uniform0:.4g})" in w.timeline.controls.summary.text()
    y = view.row_rect("dp").center().y()
    pinned, moved = int(m.dp_keys[5]), int(m.dp_keys[12])
    reach = 2 * QApplication.startDragDistance() * view._frames_per_px()  # a drag, not a click
    target = next(f for f in range(moved + round(reach), m.last_frame) if f not in m.dp_keys)
    ui.send_mouse(view, "press", (view.frame_to_x(pinned), y), LEFT, LEFT)
    ui.send_mouse(view, "release", (view.frame_to_x(pinned), y), LEFT, None)
    ui.drag(view, (view.frame_to_x(moved), y), (view.frame_to_x(target), y), steps=8)
    s = m.settings
    assert s.pins == tuple(sorted((pinned, target))) and s.excludes == (moved,)
    steered = select_keys(table, keys=count, constraints=s.constraints)
    np.testing.assert_array_equal(m.dp_keys, steered.keys)
    e1, _ = m.key_errors()
    assert e1 == steered.cost and e1 >= e0  # more constraints: never a smaller optimum
    assert f"solved key error {e1:.4g}" in w.timeline.controls.summary.text()
    assert "E = Σ e_ij" in w.timeline.controls.summary.toolTip()
    assert "moved away" in view.tooltip_at(QPointF(view.frame_to_x(moved), y))
    assert "pinned" in view.tooltip_at(QPointF(view.frame_to_x(pinned), y))
    assert "never a key" in w.timeline.legend.text()


def test_the_curve_marks_the_solved_error_of_the_current_count_under_pins(make_window):
    w, m, _ = _open(make_window, WALK)
    m.set_settings(pins=(40, 90, 150, 210, 300))  # at least 7 keys: the curve starts at 7
    m.set_key_count(9)
    assert m.key_solve.curve[0, 0] == 7
    assert w.timeline.plot.current_point() == (9, m.key_errors()[0])
