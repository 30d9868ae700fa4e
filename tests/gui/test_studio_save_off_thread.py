"""Saves written off the GUI thread: the window answers while a slow writer runs and shows it in
the status bar; an edit made meanwhile is not in the file and leaves the work unsaved; a write
that fails says so and keeps the work unsaved, the autosave still working; Quit waits for the
write and says so; and, generated, edits interleaved with saves and exports whose writes end
later: every file reads back to the snapshot its save took.

The slow disk is a gate the writer waits at until the test opens it, so nothing here is timed.
"""

from __future__ import annotations

import tempfile
import threading
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from hairtool import io, samples
from hairtool import project as pf

pytestmark = pytest.mark.gui


class Gate:
    """Stands in for a slow disk: a wrapped writer waits until :meth:`open` (at most 30 s)."""

    def __init__(self) -> None:
        self.opened, self.entered = threading.Event(), threading.Event()

    def wrap(self, write):
        def held(*args, **kwargs):
            self.entered.set()
            if not self.opened.wait(30):
                raise TimeoutError("the test never opened the gate")
            return write(*args, **kwargs)

        return held

    def open(self) -> None:
        self.opened.set()

    def close(self) -> None:
        self.opened.clear()
        self.entered.clear()


@pytest.fixture
def gate(monkeypatch):
    """Both writers (the project's and the groom file's) held at one gate."""
    import app.ui.window as window_module

    held = Gate()
    monkeypatch.setattr(pf, "save", held.wrap(pf.save))
    monkeypatch.setattr(window_module, "write_groom_apart", held.wrap(window_module.write_groom_apart))
    yield held
    held.open()  # a writer still held never outlives the test


def _window(make_window):
    return make_window(groom=samples.portrait(strands=20, vertices=8))


def _stiffness(w, value: float) -> None:
    """One edit of the document: an engine parameter, one undo step."""
    w.scene.set_params(w.scene.with_param("bend_stiffness", float(value)), "bend_stiffness")


def _menu_action(w, text: str):
    file = next(a.menu() for a in w.menuBar().actions() if a.text() == "&File")
    return next(a for a in file.actions() if a.text() == text)


def test_the_window_answers_while_a_slow_save_writes(ui, qtbot, make_window, gate, tmp_path):
    from PySide6.QtCore import QTimer

    w = _window(make_window)
    _stiffness(w, 5.0)
    path = tmp_path / "slow.hairproj"
    w.ask_save_path = lambda *args, **kwargs: str(path)
    _menu_action(w, "Save Project As…").trigger()  # returns at once: the write waits at the gate
    assert gate.entered.wait(10) and not path.exists()
    ticks: list[int] = []
    QTimer.singleShot(0, lambda: ticks.append(1))
    qtbot.waitUntil(lambda: ticks == [1], timeout=2000)  # the GUI thread answers meanwhile
    assert w.job_status.isVisible() and "slow.hairproj" in w.job_status.label.text()
    assert not w.job_status.cancel_button.isVisible()  # a file is written whole or not at all
    w.jobs.cancel()  # (as the walk's Cancel): a write runs on
    assert [i.state for i in w.writes.pending] == ["writing"] and w.project.has_unsaved_changes()
    _stiffness(w, 8.0)  # an edit meanwhile
    gate.open()
    assert w.writes.wait()
    assert pf.load(path).params.bend_stiffness == 5.0 and w.project.path == path
    assert w.project.has_unsaved_changes()
    w.undo_stack.undo()  # back to the state the file holds: saved
    assert not w.project.has_unsaved_changes() and w.errors == []


def test_an_edit_during_a_groom_save_is_not_in_the_file_and_stays_unsaved(make_window, gate, tmp_path):
    from hairtool.frozen.pipeline import FrozenParams

    w = _window(make_window)
    s = w.scene
    s.set_params(FrozenParams(freeze=False, clump=False, keep_lengths=True))
    snapshot = s.export_groom().points.copy()
    path = tmp_path / "groom.usda"
    assert w.export_groom(tmp_path / "other.usda", wait=False)  # a write queued before
    w.ask_save_path = lambda *args, **kwargs: str(path)
    assert w.save_as(wait=False)
    assert gate.entered.wait(10)
    assert [i.state for i in w.writes.pending] == ["writing", "queued"]
    before = s.snapshot()  # an Align stroke while the file is written
    tip = s.result.tips[0].astype(np.float64)
    s.align(tip + np.array([0.6, 0.0, 0.0]))
    s.end_stroke(before)
    assert not np.array_equal(s.result.points, snapshot)
    gate.open()
    assert w.writes.wait()
    assert np.array_equal(io.read_groom(path).points, snapshot)
    assert s.path == path and "*" in w.windowTitle() and w.project.has_unsaved_changes()
    w.undo_stack.undo()
    assert not w.project.has_unsaved_changes()


@pytest.mark.parametrize("what", ["project", "groom"])
def test_a_failing_write_says_so_and_keeps_the_work_unsaved(make_window, tmp_path, what):
    w = _window(make_window)
    _stiffness(w, 5.0)
    gone = tmp_path / "gone"
    gone.write_text("a file where the folder was")
    path = gone / ("look.hairproj" if what == "project" else "look.usda")
    if what == "project":
        assert w.project.save_to(path, wait=False)
    else:
        w.ask_save_path = lambda *args, **kwargs: str(path)
        _menu_action(w, "Save &As…").trigger()
    assert not w.writes.wait()
    title, message = w.errors[-1]
    assert title == ("Cannot save project" if what == "project" else "Cannot write file")
    assert str(path) in message and "\n" not in message and len(w.errors) == 1
    assert w.project.has_unsaved_changes() and w.project.path is None and w.scene.path != path
    assert w.project.autosave(wait=True)  # the autosave keeps working
    assert pf.load(w.project.recovery_path).params.bend_stiffness == 5.0


def test_quit_during_a_write_waits_for_it_and_says_so(ui, make_window, gate, tmp_path):
    from PySide6.QtCore import QTimer

    w = _window(make_window)
    _stiffness(w, 5.0)
    path = tmp_path / "quit.hairproj"
    assert w.project.save_to(path, wait=False) and gate.entered.wait(10)
    said = ui.record(w.statusBar().messageChanged)
    asked: list[int] = []
    w.ask_save_changes = lambda: asked.append(1) or "cancel"
    QTimer.singleShot(50, gate.open)  # the disk catches up while Quit waits (the GUI answering)
    w.close()
    assert not w.isVisible() and asked == []  # written: nothing left to ask about
    assert any("quit.hairproj" in m and "before quitting" in m for (m,) in said)
    assert pf.load(path).params.bend_stiffness == 5.0


def test_a_document_replaced_while_its_save_writes_does_not_take_the_file(make_window, gate, tmp_path):
    w = _window(make_window)
    _stiffness(w, 5.0)
    path = tmp_path / "old.hairproj"
    assert w.project.save_to(path, wait=False) and gate.entered.wait(10)
    w.new_from_sample("comb")  # another document while the old one is written
    gate.open()
    assert w.writes.wait() and pf.load(path).params.bend_stiffness == 5.0
    assert w.project.path is None and w.scene.path is None and not w.project.has_unsaved_changes()


OPS = st.lists(
    st.one_of(
        st.tuples(st.just("edit"), st.integers(1, 12)),
        st.tuples(st.just("undo")),
        st.tuples(st.sampled_from(["save", "export"]), st.integers(0, 1)),
        st.tuples(st.just("flush")),
    ),
    min_size=1,
    max_size=10,
)


def test_every_saved_file_reads_back_to_its_snapshot(make_window, gate, tmp_path):
    """Saves (the project) and exports (the groom) to two names each, their writes held until a
    flush, between edits and undos: each file holds the snapshot of the last write asked of it,
    and the work reads as saved after a flush when nothing changed since the last save, and
    only in that save's state."""
    w = _window(make_window)

    @settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
    @given(ops=OPS)
    def interleaved(ops) -> None:
        folder = Path(tempfile.mkdtemp(dir=tmp_path))
        gate.close()
        projects: dict[Path, object] = {}
        grooms: dict[Path, np.ndarray] = {}
        saved, changed_since = None, False

        def flush() -> None:
            gate.open()
            assert w.writes.wait(), w.errors
            gate.close()
            if saved is not None and not changed_since:
                assert not w.project.has_unsaved_changes()
            if saved is not None and not w.project.has_unsaved_changes():
                assert w.scene.params == saved

        for op in ops:
            if op[0] == "edit":
                if w.scene.params.bend_stiffness != float(op[1]):
                    _stiffness(w, op[1])
                    changed_since = True
            elif op[0] == "undo":
                changed_since |= w.undo_stack.stack.can_undo
                w.undo_stack.undo()
            elif op[0] == "save":
                path = folder / f"p{op[1]}.hairproj"
                assert w.project.save_to(path, wait=False)
                projects[path], saved, changed_since = w.scene.params, w.scene.params, False
            elif op[0] == "export":
                path = folder / f"g{op[1]}.usda"
                grooms[path] = w.scene.export_groom().points
                assert w.export_groom(path, wait=False)
            else:
                flush()
        flush()
        for path, params in projects.items():
            assert pf.load(path).params == params
        for path, points in grooms.items():
            assert np.array_equal(io.read_groom(path).points, points)
        assert w.errors == []

    interleaved()
