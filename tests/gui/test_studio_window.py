"""The main window: opening on the sample, files (good, corrupt, dropped), settings between runs."""

from __future__ import annotations

import numpy as np
import pytest
from PySide6.QtCore import QMimeData, QPointF, QSettings, Qt, QUrl
from PySide6.QtGui import QDragEnterEvent, QDropEvent
from PySide6.QtWidgets import QApplication

from hairtool import io, samples

pytestmark = pytest.mark.gui


def test_window_opens_on_the_sample_groom(make_window):
    w = make_window()
    sample = samples.sample(samples.DEFAULT_SAMPLE)
    assert np.array_equal(w.scene.rest.points, sample.points)
    assert w.viewport.camera.ortho  # the portrait sample is planar: 2-D view
    assert f"{sample.strand_count:,} strands" in w.counts_label.text()
    assert f"{sample.vertex_count:,} vertices" in w.counts_label.text()
    assert w.viewport.renderer is not None
    menus = [a.text().replace("&", "") for a in w.menuBar().actions()]
    assert menus[:3] == ["File", "Edit", "View"]


def test_corrupt_file_shows_the_readers_message_and_keeps_the_scene(make_window, tmp_path):
    w = make_window()
    rest, result = w.scene.rest, w.scene.result
    bad = tmp_path / "broken.hair"
    bad.write_bytes(b"HAIR" + b"\x07" * 13)
    assert not w.open_path(bad)
    assert len(w.errors) == 1 and "broken.hair" in w.errors[0][1]
    assert w.scene.rest is rest and w.scene.result is result
    assert not w.open_path(tmp_path / "missing.usda")
    assert len(w.errors) == 2 and w.scene.rest is rest


def test_open_a_written_groom_and_drop_a_file(make_window, tmp_path):
    w = make_window()
    groom = samples.scalp(strands=50, vertices=8)
    path = tmp_path / "scalp.npz"
    io.write(path, groom)
    assert w.open_path(path), w.errors
    np.testing.assert_array_equal(w.scene.rest.points, groom.points)
    assert not w.viewport.camera.ortho  # 3-D groom: perspective
    assert w.scene.path == path and "scalp.npz" in w.windowTitle()

    other = tmp_path / "comb.npz"
    io.write(other, samples.comb(strands=9, vertices=5))
    mime = QMimeData()
    mime.setUrls([QUrl.fromLocalFile(str(other))])
    enter = QDragEnterEvent(QPointF(10, 10), Qt.DropAction.CopyAction, mime, Qt.MouseButton.LeftButton,
                            Qt.KeyboardModifier.NoModifier)  # fmt: skip
    QApplication.sendEvent(w, enter)
    assert enter.isAccepted()
    drop = QDropEvent(QPointF(10, 10), Qt.DropAction.CopyAction, mime, Qt.MouseButton.LeftButton,
                      Qt.KeyboardModifier.NoModifier)  # fmt: skip
    QApplication.sendEvent(w, drop)
    assert w.scene.rest.strand_count == 9 and not w.errors


def test_real_tressfx_groom_opens(make_window, grooms_dir):
    w = make_window()
    assert w.open_path(grooms_dir / "ponytail_tail.tfx"), w.errors
    assert w.scene.rest.strand_count > 1
    assert w.viewport.grabFramebuffer().width() > 0


def test_layout_recent_files_and_last_directory_persist(make_window, settings_path, tmp_path):
    path = tmp_path / "sub" / "g.npz"
    path.parent.mkdir()
    io.write(path, samples.comb(strands=4, vertices=3))
    first = make_window()
    first.addDockWidget(Qt.DockWidgetArea.LeftDockWidgetArea, first.dock)
    assert first.open_path(path)
    first.close()
    second = make_window()
    assert second.dockWidgetArea(second.dock) == Qt.DockWidgetArea.LeftDockWidgetArea
    assert second.last_dir() == str(path.parent.resolve())
    assert second.recent_files()[0] == str(path.resolve())
    second.new_from_sample("comb")
    second._fill_recent_menu()
    second.recent_menu.actions()[0].trigger()  # File → Open Recent → g.npz
    assert second.scene.path == path and second.scene.rest.strand_count == 4
    assert QSettings(settings_path, QSettings.Format.IniFormat).value("last_dir") == str(
        path.parent.resolve()
    )


def test_new_from_sample_and_save(make_window, tmp_path, monkeypatch):
    w = make_window()
    w.new_from_sample("comb")
    assert w.scene.rest.strand_count == samples.comb().strand_count
    target = tmp_path / "saved.hair"
    monkeypatch.setattr(w, "ask_save_path", lambda *a, **k: str(target))
    assert w.save()  # untitled: Save asks for a name
    assert w.scene.path == target and target.is_file()
    np.testing.assert_allclose(io.read_groom(target).points, w.scene.result.points, atol=1e-6)


def test_head_mesh_loads_under_the_hair_and_bad_mesh_is_reported(ui, make_window, grooms_dir, tmp_path):
    w = make_window()
    assert w.open_path(grooms_dir / "sintel_hair.tfx"), w.errors
    ui.leave(w.viewport)
    hair_only = ui.grab(w.viewport)
    assert w.load_mesh(grooms_dir / "sintel_head.obj"), w.errors
    assert w.scene.mesh is not None
    with_head = ui.grab(w.viewport)
    assert ui.hair_mask(with_head).sum() > ui.hair_mask(hair_only).sum()  # the head fills in pixels
    bad = tmp_path / "bad.obj"
    bad.write_text("v 0 0 nan\nf 1 2 3\n")
    assert not w.load_mesh(bad)
    assert w.errors and "bad.obj" in w.errors[-1][1]
    assert w.scene.mesh is not None  # the loaded head stays


def test_a_file_that_fails_at_start_up_leaves_the_sample_open(qtbot, settings_path, tmp_path, monkeypatch):
    from app.ui.window import MainWindow

    errors = []
    monkeypatch.setattr(MainWindow, "show_error", lambda self, title, message: errors.append(message))
    bad = tmp_path / "nothing.tfx"
    bad.write_bytes(b"\x00\x01")
    window = MainWindow(bad, settings=QSettings(settings_path, QSettings.Format.IniFormat))
    qtbot.addWidget(window)
    assert len(errors) == 1 and "nothing.tfx" in errors[0]
    assert window.scene.rest.strand_count == samples.sample(samples.DEFAULT_SAMPLE).strand_count
    assert window.scene.path is None


def test_first_run_opens_sintel_on_her_head_untitled(make_window, tmp_path, monkeypatch):
    from app import resources as bundled

    w = make_window()
    assert w.open_bundled_sample(), w.errors
    assert (w.scene.rest.strand_count, w.scene.rest.vertex_count) == (228, 228 * 32)
    assert w.scene.mesh is not None and len(w.scene.mesh.vertices) > 1000
    assert w.scene.path is None  # untitled: Save never writes into the installed package
    target = tmp_path / "sintel.usda"
    monkeypatch.setattr(w, "ask_save_path", lambda *a, **k: str(target))
    before = bundled.path(bundled.SINTEL_HAIR).read_bytes()
    assert w.save() and target.is_file()
    assert bundled.path(bundled.SINTEL_HAIR).read_bytes() == before
    w.new_from_sample("portrait")  # a procedural sample is a new scene: no head
    assert w.scene.mesh is None
