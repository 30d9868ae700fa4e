"""Nothing is lost: one "changed since the last save" (the undo stack's clean state); Open, New
from sample, a drop and Quit over changed work ask Save / Discard / Cancel, and opening a file
with no edit asks nothing; after a crash the next start offers the autosave with its time."""

from __future__ import annotations

import os
from datetime import datetime

import numpy as np
import pytest
from PySide6.QtCore import QMimeData, QPointF, QSettings, Qt, QUrl
from PySide6.QtGui import QAction, QDropEvent
from PySide6.QtWidgets import QApplication, QMessageBox

from hairtool import io, samples

pytestmark = pytest.mark.gui

GROOM = "tests/data/grooms/ponytail_tail.tfx"


def _stroke(ui, w) -> None:
    v = w.viewport
    start = v.project(w.scene.result.tips[3:4])[0]
    ui.drag(v, start, start + np.array([-60.0, -40.0]), steps=4)
    assert w.undo_stack.count() == 1 and not w.undo_stack.isClean()


def _answering(w, answer: str) -> list[int]:
    asked: list[int] = []
    w.ask_save_changes = lambda: asked.append(1) or answer
    return asked


def _action(w, text: str):
    return next(a for a in w.findChildren(QAction) if a.text() == text)


def _drop(w, path: str) -> None:
    data = QMimeData()
    data.setUrls([QUrl.fromLocalFile(os.path.abspath(path))])
    event = QDropEvent(QPointF(20, 20), Qt.DropAction.CopyAction, data, Qt.MouseButton.NoButton,
                       Qt.KeyboardModifier.NoModifier)  # fmt: skip
    w.dropEvent(event)


def test_a_stroke_then_open_asks_and_cancel_keeps_the_strokes_and_their_undo(ui, make_window):
    w = make_window(groom=samples.portrait(strands=12, vertices=6))
    _stroke(ui, w)
    edited = w.scene.result.points.copy()
    opened = []
    w.ask_open_path = lambda *a, **k: opened.append(1) or GROOM
    asked = _answering(w, "cancel")
    w.open_dialog()
    _action(w, "Comb").trigger()  # File ▸ New from sample ▸ Comb
    _drop(w, GROOM)
    w.settings.setValue("recent", [os.path.abspath(GROOM)])
    w.recent_menu.aboutToShow.emit()
    w.recent_menu.actions()[0].trigger()
    assert asked == [1, 1, 1, 1] and opened == []  # Cancel: no file dialog, nothing opened
    assert w.scene.path is None and np.array_equal(w.scene.result.points, edited)
    assert w.undo_stack.count() == 1 and w.undo_stack.canUndo() and "*" in w.windowTitle()

    asked = _answering(w, "discard")
    w.open_dialog()
    assert asked == [1] and opened == [1] and w.scene.path.name == "ponytail_tail.tfx"
    assert w.undo_stack.count() == 0 and w.undo_stack.isClean() and "*" not in w.windowTitle()
    assert w.errors == []


def test_save_runs_the_normal_save_before_opening(ui, make_window, tmp_path):
    path = tmp_path / "mine.usda"
    io.write(path, samples.portrait(strands=12, vertices=6))
    w = make_window(path=path)
    _stroke(ui, w)
    edited = w.scene.export_groom().points.copy()
    _answering(w, "save")
    _drop(w, GROOM)  # a drop over changed work: Save writes the groom's own file, then it opens
    assert w.scene.path.name == "ponytail_tail.tfx" and w.errors == []
    np.testing.assert_allclose(io.read_groom(path).points, edited, atol=1e-6)

    assert w.open_path("tests/data/motion/freebvh.bvh")  # a capture: its keys steered
    key = int(w.animation.dp_keys[1])
    assert w.animation_ui.steer_keys(f"Pin key {key}", pin=key) and not w.undo_stack.isClean()
    project = tmp_path / "walk.hairproj"
    w.ask_save_path = lambda title, filters, suggested="": str(project)
    _drop(w, GROOM)  # Save keeps the animation: a project, not the static groom
    assert project.is_file() and w.scene.path.name == "ponytail_tail.tfx" and w.errors == []


def test_opening_a_file_asks_nothing_afterwards(ui, make_window):
    w = make_window(groom=samples.portrait(strands=12, vertices=6))
    w.sources.apply_anime()  # an animation made here: unsaved work, an undo step
    assert w.project.has_unsaved_changes() and "*" in w.windowTitle()
    asked = _answering(w, "discard")
    assert w.open_path(GROOM)
    assert asked == [] and w.undo_stack.isClean()  # open_path itself never asks; the menus do
    w.close()  # Quit right after opening: no question
    assert asked == [] and not w.isVisible()

    w = make_window()
    assert w.open_path("tests/data/motion/freebvh.bvh")
    asked = _answering(w, "cancel")
    w.close()
    assert asked == [] and not w.isVisible()


def test_quit_over_changed_work_asks_and_cancel_stays(ui, make_window):
    w = make_window(groom=samples.portrait(strands=12, vertices=6))
    _stroke(ui, w)
    w.undo_stack.undo()  # back where the file was: nothing changed
    asked = _answering(w, "cancel")
    w.undo_stack.redo()
    w.close()
    assert asked == [1] and w.isVisible()
    w.undo_stack.undo()
    w.close()
    assert asked == [1] and not w.isVisible()


def test_after_a_crash_the_next_start_offers_the_autosave_with_its_time(
    ui, make_window, settings_path, monkeypatch
):
    from app.ui.window import MainWindow

    w = make_window(groom=samples.portrait(strands=12, vertices=6))
    w._on_param_edited("seed", 11, None)
    assert w.project.autosave(wait=True)
    recovery = w.project.recovery_path
    saved = datetime(2026, 1, 5, 9, 41).timestamp()
    os.utime(recovery, (saved, saved))
    shown = []

    def answer(box) -> int:  # the real question, answered Restore
        shown.append((box.windowTitle(), box.text(), [b.text() for b in box.buttons()]))
        next(b for b in box.buttons() if b.text() == "Restore").click()
        return 0

    monkeypatch.setattr(QMessageBox, "exec", answer)
    # the first window is never closed, as in a crash: a new session finds its autosave
    w2 = MainWindow(None, settings=QSettings(settings_path, QSettings.Format.IniFormat))
    try:
        w2.show_error = lambda *a: pytest.fail(str(a))
        QApplication.processEvents()  # the offer comes once the event loop runs
        assert len(shown) == 1
        title, text, buttons = shown[0]
        assert title == "Restore autosaved work"
        assert "on 5 January 2026 at 09:41" in text and str(recovery) in text
        assert sorted(buttons) == ["Discard", "Restore"]
        assert w2.scene.params.seed == 11 and w2.project.has_unsaved_changes()
        w2.ask_save_changes = lambda: "discard"
    finally:
        w2.close()
        w2.deleteLater()
    assert not recovery.exists()  # a clean quit removes it


def test_the_question_itself_names_the_work_and_maps_its_buttons(make_window, monkeypatch):
    from app.ui.window import MainWindow

    w = make_window()
    assert w.open_path(GROOM)
    shown, b = [], QMessageBox.StandardButton
    for pressed, expected in ((b.Save, "save"), (b.Discard, "discard"), (b.Cancel, "cancel")):
        answer = int(pressed.value)
        monkeypatch.setattr(QMessageBox, "exec", lambda box, a=answer: shown.append(box.text()) or a)
        assert MainWindow.ask_save_changes(w) == expected
    assert all("ponytail_tail.tfx has changes that are not saved" in text for text in shown)
