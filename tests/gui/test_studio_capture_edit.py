"""Posing a capture at its keys in the studio (issue 30 points 3 and 4): joint handles dragged by
IK, one undo step each, BVH export, projects keeping the edits, and the graph editor."""

from __future__ import annotations

import numpy as np
import pytest
from PySide6.QtCore import QPoint, QPointF, Qt
from PySide6.QtGui import QKeyEvent, QWheelEvent
from PySide6.QtWidgets import QApplication

from app.ui.animation_io import skeleton_animation
from hairtool.mocap import ik
from hairtool.mocap.bvh import read_bvh
from hairtool.mocap.pose_edit import ChannelEdit, PoseEdit, PoseEditor, TangentEdit

HAND = "mixamorig:LeftHand"


@pytest.fixture
def capture(make_window, motion_dir):
    """A window on the 69-frame freebvh capture at its second key."""
    path = motion_dir / "freebvh.bvh"
    w = make_window(path)
    c = w.capture
    assert c.attached and c.editor is not None
    w.animation.set_frame(int(c.editor.keys[1]))
    return w, read_bvh(path)


def _handle(w, joint):
    j = w.capture.original.joint_names.index(joint)
    return w.viewport.project(w.capture.pose_positions()[j][None])[0]


def _library(w, motion):
    c = w.capture
    return PoseEditor(motion, c.editor.keys, c.editor.interp)


def test_a_joint_drag_at_a_key_solves_ik_like_the_library_and_undoes(ui, capture):
    w, motion = capture
    c, f = w.capture, w.animation.frame
    assert c.handles.shown() and c.box.isVisibleTo(w.dock)
    start = _handle(w, HAND)
    seen = []
    c.preview_changed.connect(lambda: seen.append(len(c.ghosts)))
    ui.drag(w.viewport, start, start + np.array([40, -30]))
    assert seen and max(seen) > 0  # the neighbouring frames followed as ghosts during the drag
    assert w.undo_stack.count() == 1 and len(c.edits) == 1
    target = c.drag.last_target
    edit = c.edits[0]
    assert edit == PoseEdit(f, HAND, tuple(target), 2) and c.joint == HAND
    lib = _library(w, motion)
    lib.apply(edit)
    expected = lib.motion()
    assert np.array_equal(c.motion().values, expected.values)
    # the effector is on its target at the key, within 1e-4 of the figure's height
    j = motion.joint_names.index(HAND)
    got = c.motion().joint_positions()[f, j]
    assert np.linalg.norm(got - target) < 1e-4 * ik.figure_height(motion)
    assert np.linalg.norm(target - motion.joint_positions()[f, j]) > 0.01 * ik.figure_height(motion)
    # the timeline's skeleton is the edited capture
    np.testing.assert_array_equal(w.animation.animation.frames, skeleton_animation(expected).frames)
    w.undo_stack.undo()
    assert c.edits == [] and np.array_equal(c.motion().values, motion.values)
    np.testing.assert_array_equal(w.animation.animation.frames, skeleton_animation(motion).frames)
    w.undo_stack.redo()
    assert np.array_equal(c.motion().values, expected.values)


def test_the_joint_handles_are_drawn_in_the_view_at_a_key_only(ui, capture):
    # painted into the GL view's frames: a widget over the native GL window would be covered
    w, _ = capture
    colours = np.array([(255, 200, 60), (255, 90, 60)])  # a handle, the chosen joint's

    def handle_pixels() -> int:
        image = ui.grab(w.viewport).astype(int)
        x, y = np.round(_handle(w, HAND)).astype(int)
        patch = image[y - 2 : y + 3, x - 2 : x + 3].reshape(-1, 1, 3)
        return int((np.abs(patch - colours).max(axis=2) < 30).any(axis=1).sum())

    assert w.capture.handles.shown() and handle_pixels() > 4
    w.animation.set_frame(w.animation.frame + 1)  # between keys: no handles
    assert not w.capture.handles.shown() and handle_pixels() == 0


def test_alt_drag_turns_the_whole_limb_and_a_chain_follows_the_tool_dock(ui, capture):
    w, motion = capture
    c = w.capture
    depth = int(motion.depths()[motion.joint_names.index(HAND)])
    start = _handle(w, HAND)
    ui.drag(w.viewport, start, start + np.array([25, 10]), modifiers=Qt.KeyboardModifier.AltModifier)
    assert c.edits[-1].chain == depth - 1
    c.chain_spin.setValue(3)
    start = _handle(w, HAND)
    ui.drag(w.viewport, start, start + np.array([-10, 15]))
    assert c.edits[-1].chain == 3 and w.undo_stack.count() == 2
    lib = _library(w, motion)
    lib.apply_all(c.edits)
    assert np.array_equal(c.motion().values, lib.motion().values)


def test_off_a_key_or_off_a_handle_a_drag_poses_nothing(ui, capture):
    w, motion = capture
    c = w.capture
    start = _handle(w, HAND)
    w.animation.set_frame(int(c.editor.keys[1]) + 1)  # not a key
    assert not c.handles.shown()
    selected = c.original.joint_names[0]
    c.select(selected)  # not the hand: a press on the hand's place would select it
    ui.drag(w.viewport, _handle(w, HAND), _handle(w, HAND) + np.array([30, 0]))
    assert c.joint == selected  # no handle is drawn there: the press selects nothing
    w.animation.set_frame(int(c.editor.keys[1]))
    ui.drag(w.viewport, start + np.array([200, 200]), start + np.array([230, 200]))  # empty space: no edit
    assert c.edits == [] and w.undo_stack.count() == 0
    assert np.array_equal(w.animation.animation.frames, skeleton_animation(motion).frames)


def test_export_animation_writes_the_edited_capture_as_bvh(ui, capture, tmp_path):
    w, motion = capture
    start = _handle(w, HAND)
    ui.drag(w.viewport, start, start + np.array([30, -25]))
    out = tmp_path / "edited.bvh"
    assert w.exporter.export_animation(out) is True and not w.errors
    back = read_bvh(out)
    edited = w.capture.motion()
    assert back.joint_names == motion.joint_names and back.channels == motion.channels
    np.testing.assert_allclose(back.offsets, motion.offsets, atol=1e-6)
    assert back.frame_time == pytest.approx(motion.frame_time)
    np.testing.assert_allclose(back.values, edited.values, atol=1e-6)  # BVH keeps 6 decimals
    assert not np.allclose(back.values, motion.values, atol=1e-3)


def test_a_project_keeps_the_capture_and_its_edits(ui, capture, make_window, tmp_path):
    w, motion = capture
    c = w.capture
    start = _handle(w, HAND)
    ui.drag(w.viewport, start, start + np.array([30, -25]))
    c.commit(ChannelEdit(w.animation.frame, "mixamorig:Spine", "Xrotation", 12.5), "channel")
    edited = c.motion().values
    path = tmp_path / "posed.hairproj"
    assert w.project.save_to(path)
    w2 = make_window()
    assert w2.open_path(path) and not w2.errors
    c2 = w2.capture
    assert c2.attached and c2.edits == c.edits
    np.testing.assert_array_equal(c2.motion().values, edited)
    np.testing.assert_array_equal(c2.original.values, motion.values)
    np.testing.assert_allclose(w2.animation.animation.frames, w.animation.animation.frames, atol=1e-6)


def _wheel(widget, delta, pos=(150, 60)):
    p = QPointF(*pos)
    event = QWheelEvent(p, widget.mapToGlobal(p), QPoint(0, 0), QPoint(0, delta), Qt.MouseButton.NoButton,
                        Qt.KeyboardModifier.NoModifier, Qt.ScrollPhase.NoScrollPhase, False)  # fmt: skip
    QApplication.sendEvent(widget, event)


def test_the_graph_editor_drags_a_key_like_the_library_and_navigates(ui, capture, qtbot):
    w, motion = capture
    w.graph_editor.show()
    w.graph_editor.raise_()
    view = w.graph_editor.view
    view.resize(600, 260)
    c = w.capture
    start = _handle(w, "mixamorig:LeftForeArm")
    ui.send_mouse(w.viewport, "press", start, Qt.MouseButton.LeftButton, Qt.MouseButton.LeftButton)
    ui.send_mouse(w.viewport, "release", start, Qt.MouseButton.LeftButton)
    assert c.joint == "mixamorig:LeftForeArm" and len(view.curves) == 3 and c.edits == []
    curve = view.curves[1]
    col = ik.rotation_columns(motion, motion.joint_names.index("mixamorig:LeftForeArm"))[0][1]
    np.testing.assert_array_equal(curve.original, motion.values[:, col])
    np.testing.assert_array_equal(curve.keys, c.editor.keys)
    k = 2
    p = np.array(view.key_point(1, k))
    ui.drag(view, p, p + np.array([0, -40]))
    assert w.undo_stack.count() == 1
    edit = c.edits[-1]
    assert isinstance(edit, ChannelEdit) and edit.frame == int(curve.keys[k]) and edit.channel == curve.name
    assert edit.value > curve.values[k]
    lib = _library(w, motion)
    lib.apply_channel(edit)
    assert np.array_equal(c.motion().values, lib.motion().values)
    ui.curves_match(view, lib, "mixamorig:LeftForeArm")  # the curves drawn are the library's
    assert w.animation.frame == edit.frame
    np.testing.assert_array_equal(w.animation.animation.frames, skeleton_animation(lib.motion()).frames)
    assert view.curves[1].values[k] == pytest.approx(edit.value, abs=1e-6)
    w.undo_stack.undo()
    assert np.array_equal(c.motion().values, motion.values)

    # zoom, pan and Home change the view range
    home = (view.x_range, view.y_range)
    _wheel(view, 240)
    assert view.x_range[1] - view.x_range[0] < home[0][1] - home[0][0]
    zoomed = view.x_range
    ui.drag(view, (200, 100), (260, 120), button=Qt.MouseButton.MiddleButton)
    assert view.x_range[0] < zoomed[0] and view.x_range[1] - view.x_range[0] == pytest.approx(
        zoomed[1] - zoomed[0]
    )
    y = view.y_range
    ui.drag(view, (200, 100), (200, 60), button=Qt.MouseButton.MiddleButton,
            modifiers=Qt.KeyboardModifier.ControlModifier)  # fmt: skip
    assert view.y_range[1] - view.y_range[0] < y[1] - y[0]
    QApplication.sendEvent(
        view, QKeyEvent(QKeyEvent.Type.KeyPress, Qt.Key.Key_Home, Qt.KeyboardModifier.NoModifier)
    )
    assert (view.x_range, view.y_range) == home


def test_the_graph_editor_drags_a_handle_like_the_library(ui, capture):
    w, motion = capture
    w.animation.set_settings(interp="hermite")
    c = w.capture
    assert c.editor.interp == "hermite"
    w.animation.set_frame(int(c.editor.keys[1]))
    w.graph_editor.show()
    view = w.graph_editor.view
    view.resize(600, 260)
    c.select("mixamorig:LeftForeArm")
    assert len(view.curves) == 3 and view.curves[0].slope_out is not None
    k = 1
    p = np.array(view.handle_point(0, k, 1))
    before = float(view.curves[0].slope_out[k])
    ui.drag(view, p, p + np.array([0, -30]))
    edit = c.edits[-1]
    assert isinstance(edit, TangentEdit) and edit.channel == view.curves[0].name and edit.slope > before
    lib = _library(w, motion)
    lib.apply_tangent(edit)
    assert np.array_equal(c.motion().values, lib.motion().values)
    ui.curves_match(view, lib, "mixamorig:LeftForeArm")
    assert view.curves[0].slope_out[k] == pytest.approx(edit.slope, abs=1e-6)
    assert view.curves[0].slope_in[k] == pytest.approx(edit.slope, abs=1e-6)
    np.testing.assert_array_equal(w.animation.animation.frames, skeleton_animation(lib.motion()).frames)
    w.undo_stack.undo()
    assert np.array_equal(c.motion().values, motion.values)


def test_on_hair_the_graph_editor_moves_a_vertex_key_through_the_timelines_edit(ui, make_window):
    from hairtool import samples
    from hairtool.keys.edit import KeyEditor
    from hairtool.simulate.sway import sway_animation

    w = make_window(groom=samples.comb(strands=6, vertices=5))
    anim = sway_animation(w.scene.result, 30, 24.0, flick_frame=20)
    w.animation.load_animation(anim, "sway")
    dock = w.graph_editor
    dock.show()
    view = dock.view
    view.resize(600, 260)
    dock.strand.setValue(2)
    names = [c.name for c in view.curves]
    assert view.on_hair and names == ["x", "y", "z", "feature x", "feature y", "feature z"]
    v = int(anim.topology.offsets[3]) - 1  # strand 2's tip
    np.testing.assert_array_equal(view.curves[0].original, anim.frames[:, v, 0])
    keys = w.animation.dp_keys
    k = 1
    key = int(keys[k])
    p = np.array(view.key_point(0, k))
    ui.drag(view, p, p + np.array([0, -40]))
    assert w.undo_stack.count() == 2 and w.animation.frame == key
    got = w.animation.animation.frames
    value = float(got[key, v, 0])
    assert value > float(anim.frames[key, v, 0])
    pose = np.array(anim.frames[key], dtype=np.float64)
    pose[v, 0] = value
    editor = KeyEditor(anim.frames, keys, w.animation.dp_poses.interp)
    editor.set_key_pose(key, pose)
    np.testing.assert_allclose(got, editor.frames(np.float32), atol=1e-6)
    np.testing.assert_array_equal(view.curves[0].original, anim.frames[:, v, 0])  # still the opened one
    w.undo_stack.undo()
    np.testing.assert_array_equal(w.animation.animation.frames, anim.frames)
