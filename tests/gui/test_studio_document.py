"""A groom is a document that owns its surface, its up axis and its project path: opening another
groom shows that groom's head or none, Load / Remove head mesh are undo steps, a project keeps
the mesh and the camera, Save Project after another groom asks for a path, and a project opens
from the command line and by drag-and-drop."""

from __future__ import annotations

import numpy as np
import pytest
from PySide6.QtCore import QMimeData, QPointF, Qt, QUrl
from PySide6.QtGui import QDragEnterEvent, QDropEvent
from PySide6.QtWidgets import QApplication

from hairtool import io, samples
from hairtool import project as pf
from hairtool.io.obj import read_mesh
from hairtool.io.usd_mesh import add_mesh

pytestmark = pytest.mark.gui


def _small_head_groom(grooms_dir, tmp_path):
    """A USD groom (a few strands) with Sintel's head as a Mesh prim beside the curves."""
    path = tmp_path / "on_head.usda"
    io.write(path, samples.scalp(12, 5, seed=2))
    add_mesh(path, read_mesh(grooms_dir / "sintel_head.obj"))
    return path


def test_opening_another_groom_shows_its_own_head_or_none(make_window, grooms_dir, tmp_path):
    w = make_window()
    assert w.open_bundled_sample(), w.errors
    sintel_head = w.scene.mesh
    assert sintel_head is not None
    assert w.open_path(grooms_dir / "ratboy_mohawk.tfx"), w.errors
    assert w.scene.mesh is None  # the mohawk does not float over Sintel's head
    usd = _small_head_groom(grooms_dir, tmp_path)
    assert w.open_path(usd), w.errors
    head = w.scene.mesh
    assert head is not None and len(head.vertices) == len(sintel_head.vertices)
    assert head is not sintel_head  # the file's own head, read from its Mesh prim
    px = w.viewport.project(head.vertices)
    assert px.min() >= 0 and np.all(px.max(axis=0) <= (w.viewport.width(), w.viewport.height()))  # in view
    w.new_from_sample("comb")
    assert w.scene.mesh is None

    # Groom ▸ Load head mesh… and Remove head mesh are undo steps of this groom
    assert not w.remove_mesh_action.isEnabled()
    assert w.load_mesh(grooms_dir / "sintel_head.obj"), w.errors
    assert w.scene.mesh is not None and w.remove_mesh_action.isEnabled()
    w.remove_mesh()
    assert w.scene.mesh is None and w.undo_stack.undoText() == "Remove head mesh"
    w.undo_stack.undo()
    assert w.scene.mesh is not None
    w.undo_stack.undo()
    assert w.scene.mesh is None and w.undo_stack.isClean()


def test_saving_a_groom_as_usd_keeps_its_head(make_window, grooms_dir, tmp_path):
    w = make_window()
    assert w.open_path(_small_head_groom(grooms_dir, tmp_path)), w.errors
    out = tmp_path / "saved.usdc"
    assert w.export_groom(out), w.errors
    w.new_from_sample("comb")
    assert w.open_path(out) and w.scene.mesh is not None, w.errors
    assert len(w.scene.mesh.faces) == len(read_mesh(grooms_dir / "sintel_head.obj").faces)


def test_a_project_restores_the_head_mesh_and_the_camera(make_window, grooms_dir, tmp_path):
    w = make_window(groom=samples.scalp(20, 6, seed=3))
    assert w.load_mesh(grooms_dir / "sintel_head.obj"), w.errors
    v = w.viewport
    v.camera.orbit(40.0, -25.0)
    v.camera.zoom(2.0)
    saved = v.camera.state()
    path = tmp_path / "look.hairproj"
    assert w.project.save_to(path), w.errors
    assert pf.load(path).mesh.faces.tobytes() == w.scene.mesh.faces.tobytes()

    w2 = make_window()
    assert w2.project.open_project(path), w2.errors
    assert w2.scene.mesh is not None
    assert w2.scene.mesh.vertices.tobytes() == w.scene.mesh.vertices.tobytes()
    restored = w2.viewport.camera.state()
    for key, value in saved.items():
        if isinstance(value, (str, bool)):
            assert restored[key] == value, key
        else:
            np.testing.assert_allclose(restored[key], value, err_msg=key)
    w2.resize(w2.width() + 40, w2.height())  # a resize does not frame the restored view again
    QApplication.processEvents()
    np.testing.assert_allclose(w2.viewport.camera.distance, saved["distance"])


def test_save_project_after_opening_another_groom_asks_for_a_path(make_window, tmp_path, monkeypatch):
    w = make_window(groom=samples.scalp(10, 5, seed=1))
    first = tmp_path / "first.hairproj"
    assert w.project.save_to(first), w.errors
    before = first.read_bytes()
    w.new_from_sample("comb")
    asked = []
    second = tmp_path / "second.hairproj"
    monkeypatch.setattr(w, "ask_save_path", lambda *a, **k: asked.append(a) or str(second))
    assert w.project.save_project()
    assert asked and second.is_file() and first.read_bytes() == before  # the first is untouched
    assert pf.load(second).rest.strand_count == samples.comb().strand_count
    assert w.project.save_project() and len(asked) == 1  # now this document's own project


def test_a_project_opens_from_the_command_line_and_by_drop(make_window, qtbot, settings_path, tmp_path):
    from PySide6.QtCore import QSettings

    from app.main import open_window

    w = make_window(groom=samples.scalp(9, 5, seed=5))
    path = tmp_path / "cli.hairproj"
    assert w.project.save_to(path), w.errors
    settings = QSettings(settings_path, QSettings.Format.IniFormat)
    started = open_window(str(path), settings=settings)
    qtbot.addWidget(started)
    assert started.scene.rest.strand_count == 9 and started.project.path == path
    assert started.scene.path == path
    started.project.shutdown()

    w.new_from_sample("comb")
    mime = QMimeData()
    mime.setUrls([QUrl.fromLocalFile(str(path))])
    args = (QPointF(10, 10), Qt.DropAction.CopyAction, mime, Qt.MouseButton.LeftButton,
            Qt.KeyboardModifier.NoModifier)  # fmt: skip
    enter = QDragEnterEvent(*args)
    QApplication.sendEvent(w, enter)
    assert enter.isAccepted()
    QApplication.sendEvent(w, QDropEvent(*args))
    assert w.scene.rest.strand_count == 9 and w.project.path == path and not w.errors


def test_an_unknown_format_lists_every_format_the_studio_opens(make_window, tmp_path):
    w = make_window()
    bad = tmp_path / "x.abc"
    bad.write_text("nothing")
    assert not w.open_path(bad)
    message = w.errors[-1][1]
    for ext in (".bvh", ".hairproj", ".tfx", ".usda", ".hair", ".npz", ".obj"):
        assert ext in message, (ext, message)


def _z_up(groom):
    """The groom turned as a Z-up DCC holds it: (x, y, z) ↦ (x, −z, y)."""
    p = groom.points
    return groom.with_points(np.stack([p[:, 0], -p[:, 2], p[:, 1]], axis=1))


def test_up_axis_switch_for_a_z_up_hair_file(ui, make_window, tmp_path):
    path = tmp_path / "z_up.hair"
    io.write(path, _z_up(samples.scalp(40, 8, seed=6)))  # HAIR files say nothing of their up axis
    w = make_window()
    assert w.open_path(path), w.errors
    s, v = w.scene, w.viewport
    assert s.up_axis == "Z"  # inferred: her roots lie above her tips along Z
    w.up_axis_actions["Y"].trigger()  # overridden (and switched back below)
    assert s.up_axis == "Y" and w.up_axis_actions["Y"].isChecked()

    def crown_above_tips() -> float:
        roots, tips = v.project(s.result.roots).mean(axis=0), v.project(s.result.tips).mean(axis=0)
        return float(tips[1] - roots[1])  # pixels the tips hang below the crown

    lying = crown_above_tips()
    start = v.project(s.result.tips[5:6])[0]
    ui.drag(v, start, start + np.array([30.0, 20.0]), steps=3)
    strokes, shaped = s.pipeline.strokes, s.result.points.copy()
    assert strokes
    w.up_axis_actions["Z"].trigger()
    # the strokes are kept and replayed on the relabelled groom (the engine reads the up axis):
    # the groom shows what a save of it reopens (below)
    assert s.pipeline.strokes == strokes and s.result.points.tobytes() != shaped.tobytes()
    assert s.up_axis == "Z" and w.up_axis_actions["Z"].isChecked()
    assert v.camera.up_axis == "Z" and v.camera.basis()[1][2] > 0.9
    assert crown_above_tips() > max(lying, 0.0) + 20  # she stands up
    assert s.pipeline.rest.metadata.up_axis == s.result.metadata.up_axis == "Z"  # what the engines read
    assert w.undo_stack.undoText() == "Up axis Z"

    proj = tmp_path / "z.hairproj"
    assert w.project.save_to(proj), w.errors
    usd = tmp_path / "z.usda"
    assert w.export_groom(usd), w.errors
    assert io.read_groom(usd).metadata.up_axis == "Z"  # the stage's upAxis
    w2 = make_window()
    assert w2.project.open_project(proj), w2.errors
    assert w2.scene.up_axis == "Z" and w2.viewport.camera.up_axis == "Z"
    assert w2.scene.result.points.tobytes() == s.result.points.tobytes()  # as it was shown
    assert w2.open_path(usd) and w2.scene.up_axis == "Z" and w2.up_axis_actions["Z"].isChecked()

    w.undo_stack.undo()
    assert s.up_axis == "Y" and v.camera.up_axis == "Y"


def test_the_up_axis_switch_keeps_the_head_the_brushes_collide_with(make_window):
    """Relabelling the up axis rebuilds the engine on the relabelled groom: it keeps the head
    mesh's surface (it lost it once: strokes then went through the head, slide and add refused)."""
    w = make_window(size=(420, 320))
    assert w.open_bundled_sample(), w.errors
    s = w.scene
    head = s.pipeline.surface
    assert head is not None and s.mesh is not None
    w.up_axis_actions["Z"].trigger()
    assert s.up_axis == "Z" and s.pipeline.surface is head
    w.undo_stack.undo()
    assert s.up_axis == "Y" and s.pipeline.surface is head
