"""Projects in the window: save and reopen the same scene, atomic saves, the close question,
autosave and the recovery offer after a crash."""

from __future__ import annotations

import numpy as np
import pytest
from PySide6.QtCore import QSettings
from PySide6.QtWidgets import QApplication

from hairtool import samples

pytestmark = pytest.mark.gui


def _edit(ui, w):
    """A stroke, a parameter change, display settings and an anime cycle: a scene worth saving."""
    from hairtool.anime.settings import AnimeSettings

    v, scene = w.viewport, w.scene
    w._on_param_edited("seed", 11, None)
    start = v.project(scene.result.tips[3:4])[0]
    ui.drag(v, start, start + np.array([-60.0, -40.0]), steps=4)
    scene.set_colour_mode("strand")
    scene.set_line_width(3.5)
    scene.set_intensity(0.55)
    w.sources.dock.set_settings(AnimeSettings(cycles=1, hold=3, seed=2))
    assert w.sources.apply_anime()
    w.animation.set_key_count(3)
    w.animation.set_frame(4)
    # the parameter, the stroke, the cycle and the key count: one step each
    assert w.undo_stack.count() == 4 and w.project.has_unsaved_changes()


def test_saved_project_reopens_as_the_same_scene(ui, make_window, tmp_path):
    w = make_window(groom=samples.portrait(strands=14, vertices=7))
    _edit(ui, w)
    path = tmp_path / "look.hairproj"
    assert w.project.save_to(path), w.errors
    assert not w.project.has_unsaved_changes() and "look.hairproj" in w.windowTitle()

    w2 = make_window()  # a fresh window on the default sample
    assert w2.project.open_project(path), w2.errors
    s1, s2 = w.scene, w2.scene
    assert s2.rest.points.tobytes() == s1.rest.points.tobytes()
    assert np.array_equal(s2.rest.counts, s1.rest.counts)
    assert s2.params == s1.params and s2.params.seed == 11
    assert s2.pipeline.strokes == s1.pipeline.strokes
    assert s2.result.points.tobytes() == s1.result.points.tobytes()
    assert (s2.colour_mode, s2.line_width, s2.intensity) == ("strand", 3.5, 0.55)
    a1, a2 = w.animation, w2.animation
    assert a2.animation.frames.tobytes() == a1.animation.frames.tobytes()
    assert a2.animation.fps == a1.animation.fps and a2.source == a1.source
    assert a2.settings == a1.settings and a2.dp_keys.tolist() == a1.dp_keys.tolist()
    assert a2.frame == 4
    assert w2.sources.dock.settings() == w.sources.dock.settings()
    assert w2.undo_stack.count() == 0 and not w2.project.has_unsaved_changes()
    assert w2.errors == []


def test_interrupted_save_keeps_the_previous_project(ui, make_window, tmp_path, monkeypatch):
    from hairtool import project as pf

    w = make_window(groom=samples.portrait(strands=10, vertices=6))
    path = tmp_path / "p.hairproj"
    assert w.project.save_to(path)
    before = path.read_bytes()
    _edit(ui, w)
    real, calls = np.lib.format.write_array, []

    def failing(*args, **kwargs):
        calls.append(1)
        if len(calls) == 4:
            raise OSError(28, "No space left on device")
        return real(*args, **kwargs)

    monkeypatch.setattr(np.lib.format, "write_array", failing)
    assert not w.project.save_to(path)
    assert "p.hairproj" in w.errors[-1][1] and "No space left" in w.errors[-1][1]
    assert path.read_bytes() == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["p.hairproj", "studio.ini"]
    assert w.project.has_unsaved_changes()  # the work is still not saved
    monkeypatch.undo()
    assert pf.load(path).strokes == ()


def test_a_bad_project_file_is_reported_and_the_scene_kept(make_window, tmp_path):
    w = make_window()
    rest = w.scene.rest
    bad = tmp_path / "bad.hairproj"
    bad.write_bytes(b"PK\x03\x04 not really")
    assert not w.project.open_project(bad)
    assert "bad.hairproj" in w.errors[-1][1] and w.scene.rest is rest


def test_close_asks_about_unsaved_changes(ui, make_window, tmp_path):
    w = make_window(groom=samples.portrait(strands=10, vertices=6))
    asked = []
    w.ask_save_changes = lambda: asked.append(1) or "cancel"
    w.close()
    assert asked == [] and not w.isVisible()  # nothing changed: no question

    w = make_window(groom=samples.portrait(strands=10, vertices=6))
    start = w.viewport.project(w.scene.result.tips[2:3])[0]
    ui.drag(w.viewport, start, start + np.array([30.0, 30.0]), steps=3)
    w.ask_save_changes = lambda: asked.append(1) or "cancel"
    w.close()
    assert asked == [1] and w.isVisible()  # Cancel: the window stays

    target = tmp_path / "kept.hairproj"
    w.ask_save_changes = lambda: asked.append(2) or "save"
    w.ask_save_path = lambda title, filters, suggested="": str(target)
    w.close()
    assert asked == [1, 2] and not w.isVisible() and target.is_file()


def _window_with(settings_path, answer):
    """A window made like the fixture's, whose recovery question answers ``answer``."""
    from app.ui.window import MainWindow

    w = MainWindow(None, settings=QSettings(settings_path, QSettings.Format.IniFormat))
    offers = []
    w.errors = []
    w.show_error = lambda title, message: w.errors.append((title, message))
    w.ask_restore_recovery = lambda path: offers.append(path) or answer
    w.ask_save_changes = lambda: "discard"
    QApplication.processEvents()  # the offer is made once the event loop runs
    return w, offers


def test_autosave_is_offered_after_a_crash_and_not_after_a_clean_close(
    ui, make_window, tmp_path, settings_path
):
    w = make_window(groom=samples.portrait(strands=10, vertices=6))
    recovery = w.project.recovery_path
    assert recovery.parent == tmp_path  # beside the test's settings file, never the user's
    assert not w.project.autosave(wait=True)  # nothing changed yet: nothing written
    _edit(ui, w)
    assert w.project.autosave(wait=True) and recovery.is_file()
    assert not w.project.autosave(wait=True)  # no change since

    # the first window is still open, as after a crash: a new session offers the file
    w2, offers = _window_with(settings_path, True)
    try:
        assert offers == [str(recovery)]
        assert w2.scene.result.points.tobytes() == w.scene.result.points.tobytes()
        assert w2.animation.animation.frames.tobytes() == w.animation.animation.frames.tobytes()
        assert w2.project.has_unsaved_changes() and w2.project.path is None
    finally:
        w2.close()
        w2.deleteLater()
    assert not recovery.exists()  # a clean close removes it

    w.close()  # clean close of the first session, too
    w3, offers = _window_with(settings_path, True)
    try:
        assert offers == []
    finally:
        w3.close()
        w3.deleteLater()


def test_declined_recovery_is_removed(ui, make_window, settings_path):
    w = make_window(groom=samples.portrait(strands=10, vertices=6))
    _edit(ui, w)
    w.project.autosave(wait=True)
    w2, offers = _window_with(settings_path, False)
    try:
        assert len(offers) == 1 and not w.project.recovery_path.exists()
        assert w2.animation.animation is None
    finally:
        w2.close()
        w2.deleteLater()


def test_a_project_saved_with_gravity_in_scene_units_reopens_in_metres(make_window, tmp_path):
    """Projects written before gravity was in m/s² store the default 98.1 scene units/s² on
    0.1 m-per-unit samples: reopened, the Simulate dialog shows 9.81 m/s²."""
    import dataclasses

    from hairtool import project as project_file

    w = make_window(groom=samples.portrait(strands=14, vertices=7))
    path = tmp_path / "old.hairproj"
    assert w.project.save_to(path), w.errors
    saved = project_file.load(path)
    simulate = {k: v for k, v in saved.settings["simulate"].items() if k != "gravity_unit"}
    old = dataclasses.replace(saved, settings=saved.settings | {"simulate": simulate | {"gravity": 98.1}})
    project_file.save(path, old)
    assert w.scene.result.metadata.units_per_meter == pytest.approx(10.0)

    w2 = make_window()
    assert w2.project.open_project(path), w2.errors
    assert w2.sources.simulate_options.gravity == pytest.approx(9.81)
    assert w2.errors == []
