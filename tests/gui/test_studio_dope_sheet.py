"""The DP key row as a dope sheet: a click pins or unpins a key, a drag moves it, Delete
excludes the current frame and Insert pins it; the keys are the engine's constrained optimum
at once, every edit is one undo step, and the pins travel in the project file."""

from __future__ import annotations

import numpy as np
import pytest
from PySide6.QtCore import Qt
from PySide6.QtTest import QTest

from app.ui.timeline_plots import EXCLUDE_COLOUR, PIN_COLOUR
from hairtool import samples
from hairtool.keys.constraints import KeyConstraints
from hairtool.keys.dp import select_keys
from hairtool.simulate.sway import sway_animation

pytestmark = pytest.mark.gui

N_FRAMES = 40
LEFT = Qt.MouseButton.LeftButton


@pytest.fixture
def studio(make_window):
    w = make_window(groom=samples.comb(strands=12, vertices=8), size=(1400, 900))
    anim = sway_animation(w.scene.result, N_FRAMES, 24.0, flick_frame=27)
    w.animation.load_animation(anim, "sway")
    w.animation.set_key_count(6)
    return w, anim


def click(ui, view, frame: int, to: int | None = None) -> None:
    y = view.row_rect("dp").center().y()
    ui.send_mouse(view, "press", (view.frame_to_x(frame), y), LEFT, LEFT)
    if to is not None:
        ui.send_mouse(view, "move", (view.frame_to_x(to), y), None, LEFT)
    ui.send_mouse(view, "release", (view.frame_to_x(frame if to is None else to), y), LEFT, None)


def engine(w, count: int) -> np.ndarray:
    s = w.animation.settings
    return select_keys(w.animation.key_solve.table, keys=count, constraints=s.constraints).keys


def colour_near(view, frame: int, colour) -> bool:
    from PySide6.QtGui import QImage

    image = view.grab().toImage().convertToFormat(QImage.Format.Format_RGB888)
    h, width = image.height(), image.width()
    data = np.frombuffer(image.constBits(), np.uint8, count=image.bytesPerLine() * h)
    rgb = data.reshape(h, image.bytesPerLine())[:, : width * 3].reshape(h, width, 3).astype(float)
    r, x = view.row_rect("dp"), round(view.frame_to_x(frame))
    band = rgb[r.top() : r.bottom() + 1, max(x - 9, 0) : x + 10]
    target = np.array([colour.red(), colour.green(), colour.blue()], float)
    return bool((np.abs(band - target).max(axis=2) < 40).any())


def test_a_click_on_a_key_pins_it_and_undo_unpins_it(ui, studio):
    w, _ = studio
    m, view = w.animation, w.timeline.view
    key = int(m.dp_keys[2])
    assert not colour_near(view, key, PIN_COLOUR)
    click(ui, view, key)
    assert m.settings.pins == (key,) and key in m.dp_keys and m.frame == key
    assert colour_near(view, key, PIN_COLOUR)
    assert w.undo_stack.undoText() == f"Pin key {key}"
    w.undo_stack.undo()
    assert m.settings.pins == ()
    w.undo_stack.redo()
    click(ui, view, key)  # a second click unpins
    assert m.settings.pins == () and w.undo_stack.undoText() == f"Unpin key {key}"


def test_dragging_a_key_moves_it_and_the_rest_re_solve(ui, studio):
    w, _ = studio
    m, view = w.animation, w.timeline.view
    before = m.dp_keys.copy()
    key = int(before[2])
    target = next(f for f in range(key + 3, N_FRAMES - 1) if f not in before)
    click(ui, view, key, to=target)
    assert m.settings.pins == (target,) and m.settings.excludes == (key,)
    assert target in m.dp_keys and key not in m.dp_keys and m.dp_keys.size == 6
    np.testing.assert_array_equal(m.dp_keys, engine(w, 6))
    assert colour_near(view, key, EXCLUDE_COLOUR)
    w.undo_stack.undo()
    np.testing.assert_array_equal(m.dp_keys, before)
    assert m.settings.pins == () and m.settings.excludes == ()


def test_the_default_count_is_held_while_steering(ui, make_window):
    """At the knee (no count chosen): pinning a key changes no key, a move keeps the count."""
    w = make_window(groom=samples.comb(strands=12, vertices=8), size=(1400, 900))
    w.animation.load_animation(sway_animation(w.scene.result, N_FRAMES, 24.0, flick_frame=27), "sway")
    m, view = w.animation, w.timeline.view
    assert m.settings.count == 0
    before = m.dp_keys.copy()
    knee = m.key_solve.knee
    assert before.size == knee > 4
    for key in before[1:-1]:
        click(ui, view, int(key))
    assert m.settings.pins == tuple(before[1:-1].tolist())
    np.testing.assert_array_equal(m.dp_keys, before)
    while w.undo_stack.undoText().startswith("Pin"):  # (the animation is the first step)
        w.undo_stack.undo()
    assert m.settings.pins == ()
    np.testing.assert_array_equal(m.dp_keys, before)
    key = int(before[2])
    target = next(f for f in range(key + 2, N_FRAMES - 1) if f not in before)
    click(ui, view, key, to=target)
    assert m.dp_keys.size == knee and target in m.dp_keys and key not in m.dp_keys
    np.testing.assert_array_equal(m.dp_keys, engine(w, knee))
    assert m.settings.count == 0 and w.timeline.controls.count_spin.value() == knee


def test_an_edit_the_error_budget_cannot_meet_is_refused_whole(ui, studio):
    w, _ = studio
    m, view = w.animation, w.timeline.view
    m.set_settings(mode="budget", budget=1e-6)  # every frame a key
    keys, settings, curve = m.dp_keys.copy(), m.settings, m.key_solve.curve.copy()
    steps, seen = w.undo_stack.count(), ui.record(m.keys_changed)
    m.set_frame(20)
    view.setFocus()
    QTest.keyClick(view, Qt.Key.Key_Delete)
    assert m.settings == settings and w.undo_stack.count() == steps and not seen
    np.testing.assert_array_equal(m.dp_keys, keys)
    np.testing.assert_array_equal(m.key_solve.curve, curve)
    message = w.statusBar().currentMessage()
    assert message.startswith("Exclude frame 20: not possible") and "error budget" in message
    assert "\n" not in message and "budget=" not in message and not w.errors
    QTest.keyClick(view, Qt.Key.Key_Insert)  # what the budget allows still works
    assert m.settings.pins == (20,) and w.undo_stack.undoText() == "Pin frame 20"


def test_delete_excludes_and_insert_pins_the_current_frame(ui, studio):
    w, _ = studio
    m, view = w.animation, w.timeline.view
    start = m.dp_keys.copy()
    key = int(m.dp_keys[3])
    m.set_frame(key)
    view.setFocus()
    QTest.keyClick(view, Qt.Key.Key_Delete)
    assert m.settings.excludes == (key,) and key not in m.dp_keys
    excluded = m.dp_keys.copy()
    free = next(f for f in range(1, N_FRAMES - 1) if f not in m.dp_keys and f != key)
    m.set_frame(free)
    QTest.keyClick(view, Qt.Key.Key_Insert)
    assert m.settings.pins == (free,) and free in m.dp_keys
    np.testing.assert_array_equal(m.dp_keys, engine(w, 6))
    assert KeyConstraints((free,), (key,)).allows(m.dp_keys)
    both = m.dp_keys.copy()
    w.undo_stack.undo()
    assert m.settings.pins == () and m.settings.excludes == (key,)
    np.testing.assert_array_equal(m.dp_keys, excluded)
    w.undo_stack.undo()
    assert m.settings.pins == () and m.settings.excludes == ()
    np.testing.assert_array_equal(m.dp_keys, start)
    w.undo_stack.redo()
    w.undo_stack.redo()
    np.testing.assert_array_equal(m.dp_keys, both)


def test_the_ends_cannot_be_excluded_and_the_refusal_is_shown(ui, studio):
    w, _ = studio
    m, view = w.animation, w.timeline.view
    m.set_frame(0)
    view.setFocus()
    before = w.undo_stack.count()
    QTest.keyClick(view, Qt.Key.Key_Delete)
    assert m.settings.excludes == () and w.undo_stack.count() == before
    assert "first (0)" in w.statusBar().currentMessage()


def test_pins_and_exclusions_are_saved_in_the_project(ui, studio, tmp_path, make_window):
    w, _ = studio
    m = w.animation
    key = int(m.dp_keys[2])
    assert w.animation_ui.steer_keys("Pin", pin=key) and w.animation_ui.steer_keys("Exclude", exclude=5)
    path = tmp_path / "steered.hairproj"
    assert w.project.save_to(path)
    other = make_window()
    assert other.project.open_project(path), other.errors
    s = other.animation.settings
    assert s.pins == (key,) and s.excludes == (5,)
    np.testing.assert_array_equal(other.animation.dp_keys, m.dp_keys)


def test_fitted_handles_are_offered_and_solved_like_the_engine(studio):
    from hairtool.keys.costs import cost_table
    from hairtool.keys.features import hair_features

    w, anim = studio
    m, c = w.animation, w.timeline.controls
    c.interp.setCurrentIndex(c.interp.findData("hermite-fit"))
    c.interp.activated.emit(c.interp.currentIndex())
    assert w.jobs.wait(30) and m.key_solve.table_key[1] == "hermite-fit"
    table = cost_table(hair_features(anim, m.settings.feature_options()), "hermite-fit")
    np.testing.assert_array_equal(m.dp_keys, select_keys(table, keys=6).keys)
    assert m.dp_poses.interp == "hermite-fit" and m.dp_poses.tangents_in is not None
    assert m.analysis is not None and m.analysis.dp.mean.shape == (N_FRAMES,)
