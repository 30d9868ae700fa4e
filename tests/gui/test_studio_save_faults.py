"""Saves that never lose work (issue 43): Save Project after an Add stroke beside an Align
stroke writes the file; a save that fails says so in a dialog naming the file; Quit stays open
after a failed save; an autosave that fails says so in the status bar; and the recovery file
holds the latest document."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from hairtool import project as pf

pytestmark = pytest.mark.gui

DATA = Path(__file__).resolve().parents[1] / "data" / "grooms"


def _align_then_add(ui, make_window):
    """Sintel on its head with an Align stroke (the default brush) and an Add stroke."""
    from hairtool import io
    from hairtool.frozen.brushes import BrushSample, root_normals
    from hairtool.frozen.pipeline import AlignSample
    from hairtool.io.obj import read_mesh

    rest = io.read_groom(DATA / "sintel_hair.tfx")
    w = make_window(groom=rest)
    s, v = w.scene, w.viewport
    s.set_params(s.params.replace(freeze=False, clump=False))
    s.set_mesh(read_mesh(DATA / "sintel_head.obj"))
    front = int(np.argmin(root_normals(rest) @ v.camera.forward()))
    pos = v.project(rest.roots[front])[0]
    w.brush_actions["align"].trigger()
    s.set_radius(1.5)
    ui.drag(v, pos, pos + np.array([10.0, 0.0]), steps=2)
    w.brush_actions["add"].trigger()
    ui.drag(v, pos, pos + np.array([10.0, 0.0]), steps=2)
    kinds = {type(x) for x in s.pipeline.strokes}
    assert kinds == {AlignSample, BrushSample}
    assert any(isinstance(x, BrushSample) and x.brush == "add" for x in s.pipeline.strokes)
    assert w.project.has_unsaved_changes()
    return w


def test_save_project_after_add_and_align_writes_the_strokes(ui, make_window, tmp_path):
    w = _align_then_add(ui, make_window)
    path = tmp_path / "groom.hairproj"
    assert w.project.save_to(path), w.errors  # main: TypeError, nothing written
    assert pf.load(path).strokes == w.scene.pipeline.strokes
    assert not w.project.has_unsaved_changes() and w.errors == []


def _failing_save(monkeypatch):
    def fail(path, project, **kwargs):
        raise TypeError("'builtin_function_or_method' object cannot be interpreted as an integer")

    monkeypatch.setattr(pf, "save", fail)


def test_a_failed_save_shows_a_dialog_naming_the_file_and_the_reason(ui, make_window, tmp_path, monkeypatch):
    w = make_window()
    path = tmp_path / "look.hairproj"
    _failing_save(monkeypatch)
    assert not w.project.save_to(path)  # main: the TypeError escapes, no dialog
    title, message = w.errors[-1]
    assert title == "Cannot save project" and str(path) in message and "TypeError" in message
    assert not path.exists()


def test_quit_stays_open_after_a_failed_save(ui, make_window, tmp_path, monkeypatch):
    w = _align_then_add(ui, make_window)
    target = tmp_path / "kept.hairproj"
    w.ask_save_changes = lambda: "save"
    w.ask_save_path = lambda title, filters, suggested="": str(target)
    _failing_save(monkeypatch)
    w.close()  # Quit ▸ Save, and the save fails
    assert w.isVisible() and w.project.has_unsaved_changes()  # main: the window closed
    assert any(str(target) in message for _, message in w.errors)
    monkeypatch.undo()
    w.close()  # the save works now: the window closes with the work written
    assert not w.isVisible() and pf.load(target).strokes == w.scene.pipeline.strokes


def test_a_failed_autosave_shows_in_the_status_bar(ui, qtbot, make_window, monkeypatch):
    w = make_window()
    w.undo_stack.push(_Edit())  # something to autosave
    _failing_save(monkeypatch)
    assert w.project.autosave(wait=True)
    qtbot.waitUntil(lambda: "Autosave failed" in w.statusBar().currentMessage(), timeout=2000)
    assert str(w.project.recovery_path) in w.statusBar().currentMessage()
    monkeypatch.undo()
    assert w.project.autosave(wait=True)  # the next tick tries again, and writes
    assert w.project.recovery_path.is_file() and w.project.autosave_error is None


def test_the_recovery_file_holds_the_latest_strokes(ui, make_window):
    w = _align_then_add(ui, make_window)
    assert w.project.autosave(wait=True)  # main: the thread dies on the TypeError
    assert pf.load(w.project.recovery_path).strokes == w.scene.pipeline.strokes
    assert w.project.autosave_error is None


def _Edit():
    from PySide6.QtGui import QUndoCommand

    return QUndoCommand("an edit")


def test_quit_stays_open_when_the_save_question_itself_fails(ui, make_window, monkeypatch):
    """Any fault on the way to saving (here the groom file's own Save) keeps the window open."""
    w = make_window()
    w.undo_stack.push(_Edit())
    w.ask_save_changes = lambda: "save"

    def broken():
        raise RuntimeError("the writer broke")

    monkeypatch.setattr(w.project, "save_changes", broken)
    w.close()
    assert w.isVisible() and w.errors[-1][0] == "Cannot close" and "the writer broke" in w.errors[-1][1]
    monkeypatch.undo()
    w.ask_save_changes = lambda: "discard"
    w.close()
    assert not w.isVisible()
