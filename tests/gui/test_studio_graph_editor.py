"""The graph editor's key drags in time and handle drags (issue 30 points 4 and 5): a key dragged
sideways moves to a whole frame strictly between its neighbours, one undo step; the edited
capture (or hair), the keys, the dope sheet and the errors are the library's edit exactly."""

from __future__ import annotations

import numpy as np
import pytest
from PySide6.QtCore import Qt

from app.ui.animation_io import skeleton_animation
from hairtool.keys.edit import retime_key
from hairtool.mocap.bvh import read_bvh
from hairtool.mocap.pose_edit import ChannelEdit, PoseEditor, RetimeEdit

pytestmark = pytest.mark.gui

ARM = "mixamorig:LeftForeArm"
#: mouse moves in a drag of a capture's key: each move previews the edited capture (about a second
#: of CPU on the 69 frames here), and what these tests check is where the key lands and that the
#: moves make one undo step, which a move halfway and one at the end show as eight moves do
CAPTURE_STEPS = 2


@pytest.fixture
def graph(make_window, motion_dir):
    """A window on the 69-frame freebvh capture, the forearm selected, the graph editor shown."""
    path = motion_dir / "freebvh.bvh"
    w = make_window(path)
    c = w.capture
    w.animation.set_frame(int(c.editor.keys[1]))
    w.graph_editor.show()
    view = w.graph_editor.view
    view.resize(700, 260)
    c.select(ARM)
    assert len(view.curves) == 3
    return w, view, read_bvh(path)


def _frames_px(view, frames: float) -> float:
    """Pixels across ``frames`` at the view's zoom."""
    return float(view.to_px(frames, 0.0)[0] - view.to_px(0.0, 0.0)[0])


def _library(w, motion, edits):
    lib = PoseEditor(motion, w.animation.solved_keys, w.capture.editor.interp)
    lib.apply_all(edits)
    return lib


@pytest.mark.slow(seconds=12)
def test_a_key_dragged_sideways_moves_in_time_like_the_librarys_edit(ui, graph):
    w, view, motion = graph
    c, m = w.capture, w.animation
    keys = c.editor.keys.copy()
    k = 2
    f0 = int(keys[k])
    p = np.array(view.key_point(1, k))
    ui.drag(view, p, p + np.array([_frames_px(view, 3), 0.0]), steps=CAPTURE_STEPS)
    assert w.undo_stack.count() == 1 and c.edits == [RetimeEdit(f0, f0 + 3)]
    lib = _library(w, motion, c.edits)
    assert np.array_equal(c.motion().values, lib.motion().values)
    ui.curves_match(view, lib, ARM)
    # the keys, the dope sheet, the errors and the viewport follow the moved key
    assert m.dp_keys.tolist() == lib.keys.tolist() and f0 + 3 in m.dp_keys and f0 not in m.dp_keys
    assert m.dp_keys.tolist() == w.doc.keys.tolist()  # the document's keys
    assert np.array_equal(m.solved_keys, keys)
    assert w.timeline.view.drawn_keys["dp"] == lib.keys.tolist()
    assert m.analysis is not None and m.analysis.dp.keys.tolist() == lib.keys.tolist()
    np.testing.assert_array_equal(m.animation.frames, skeleton_animation(lib.motion()).frames)
    assert m.frame == f0 + 3 and view.curves[1].keys[k] == f0 + 3
    w.undo_stack.undo()
    assert c.edits == [] and np.array_equal(m.dp_keys, keys)
    assert np.array_equal(c.motion().values, motion.values)
    w.undo_stack.redo()
    assert m.dp_keys.tolist() == lib.keys.tolist()


@pytest.mark.slow(seconds=12)
def test_a_key_dragged_in_time_and_value_is_one_step_and_stops_before_its_neighbour(ui, graph):
    w, view, motion = graph
    c = w.capture
    keys = c.editor.keys.copy()
    k = 1
    f0, nxt = int(keys[k]), int(keys[k + 1])
    p = np.array(view.key_point(0, k))
    past = p + np.array([_frames_px(view, nxt - f0 + 5), -30.0])  # past the next key
    ui.drag(view, p, past, steps=CAPTURE_STEPS)
    assert w.undo_stack.count() == 1
    move, value = c.edits
    assert move == RetimeEdit(f0, nxt - 1)  # a key never passes its neighbour
    assert isinstance(value, ChannelEdit) and value.frame == nxt - 1 and value.channel == view.curves[0].name
    lib = _library(w, motion, c.edits)
    assert np.array_equal(c.motion().values, lib.motion().values)
    ui.curves_match(view, lib, ARM)
    assert view.curves[0].values[k] == pytest.approx(value.value, abs=1e-6)
    w.undo_stack.undo()
    assert c.edits == [] and np.array_equal(c.motion().values, motion.values)
    # Shift keeps one axis: a mostly sideways drag moves the key in time only
    p = np.array(view.key_point(0, k))
    shift = Qt.KeyboardModifier.ShiftModifier
    ui.drag(view, p, p + np.array([_frames_px(view, -2), -6.0]), steps=CAPTURE_STEPS, modifiers=shift)
    assert c.edits == [RetimeEdit(f0, f0 - 2)]


def test_the_first_and_last_keys_stay_on_their_frames(ui, graph):
    w, view, _ = graph
    p = np.array(view.key_point(0, 0))
    ui.drag(view, p, p + np.array([_frames_px(view, 2), 0.0]))
    assert w.undo_stack.count() == 0 and w.capture.edits == []


def test_on_hair_a_key_dragged_sideways_is_the_librarys_retime(ui, make_window):
    from hairtool import samples
    from hairtool.simulate.sway import sway_animation

    w = make_window(groom=samples.comb(strands=6, vertices=5))
    anim = sway_animation(w.scene.result, 30, 24.0, flick_frame=20)
    m = w.animation
    m.load_animation(anim, "sway")
    dock = w.graph_editor
    dock.show()
    view = dock.view
    view.resize(700, 260)
    keys = m.dp_keys.copy()
    k = 1
    f0 = int(keys[k])
    to = f0 + 1 if keys[k + 1] - f0 > 2 else f0 - 1
    p = np.array(view.key_point(0, k))
    ui.drag(view, p, p + np.array([_frames_px(view, to - f0), 0.0]))
    assert w.undo_stack.count() == 2  # (the new animation is the first step)
    start, block, new_keys = retime_key(anim.frames, keys, m.dp_poses.interp, f0, to)
    expected = np.array(anim.frames)
    expected[start : start + len(block)] = block
    np.testing.assert_array_equal(m.animation.frames, expected)
    assert m.dp_keys.tolist() == new_keys.tolist() and view.curves[0].keys[k] == to
    assert w.timeline.view.drawn_keys["dp"] == new_keys.tolist()
    w.undo_stack.undo()
    np.testing.assert_array_equal(m.animation.frames, anim.frames)
    assert np.array_equal(m.dp_keys, keys)


def _hair(make_window, interp="hermite"):
    from hairtool import samples
    from hairtool.simulate.sway import sway_animation

    w = make_window(groom=samples.comb(strands=6, vertices=5))
    anim = sway_animation(w.scene.result, 30, 24.0, flick_frame=20)
    w.animation.set_settings(interp=interp)
    w.animation.load_animation(anim, "sway")  # (with the interpolation: the first two undo steps)
    w.graph_editor.show()
    view = w.graph_editor.view
    view.resize(700, 260)
    return w, view, anim


@pytest.mark.parametrize("interp", ["hermite", "hermite-fit"])
def test_on_hair_a_handle_drag_is_the_librarys_slope_edit_and_stays_where_dropped(ui, make_window, interp):
    from hairtool.keys.edit import key_slope_block

    w, view, anim = _hair(make_window, interp)
    m = w.animation
    assert view.on_hair and view.curves[0].slope_out is not None
    k = 1
    key = int(m.dp_keys[k])
    hair, asked = w.graph_editor.hair, []
    commit = hair.commit_slope
    hair.commit_slope = lambda axis, key, slope: (asked.append(slope), commit(axis, key, slope))
    before = float(view.curves[0].slope_out[k])
    p = np.array(view.handle_point(0, k, 1))
    ui.drag(view, p, p + np.array([0.0, -30.0]))
    assert w.undo_stack.count() == 3 and len(asked) == 1
    slope = asked[0]
    assert slope > before
    v = int(anim.topology.offsets[1]) - 1  # strand 0's tip: the dock's default vertex
    start, block = key_slope_block(anim.frames, m.dp_keys, interp, key, v * 3, slope)
    expected = np.array(anim.frames)
    expected[start : start + len(block)] = block
    np.testing.assert_allclose(m.animation.frames, expected, atol=1e-6)
    assert not np.allclose(m.animation.frames, anim.frames)
    # the handle stays where it was dropped: the frames' own tangent there is the slope
    assert view.curves[0].slope_out[k] == pytest.approx(slope, abs=1e-5)
    assert view.curves[0].slope_in[k] == pytest.approx(slope, abs=1e-5)
    w.undo_stack.undo()
    np.testing.assert_array_equal(m.animation.frames, anim.frames)


def test_per_channel_keys_show_each_channels_own_keys_and_drag_like_the_library(ui, graph):
    from hairtool.keys.channels import per_channel_keys
    from hairtool.mocap import ik
    from hairtool.mocap.channel_edit import ChannelEditor, ChannelRetimeEdit, channel_features
    from hairtool.mocap.pose_edit import TangentEdit

    w, view, motion = graph
    dock, c = w.graph_editor, w.capture
    assert dock.per_channel.isVisibleTo(dock)
    dock.per_channel.setChecked(True)
    j = motion.joint_names.index(ARM)
    cols, _ = ik.rotation_columns(motion, j)
    tau, interp = w.animation.settings.tau, c.editor.interp
    expected = per_channel_keys(channel_features(motion)[:, cols], tau, interp=interp, relative=True).keys
    assert [cv.keys.tolist() for cv in view.curves] == [k.tolist() for k in expected]
    assert len({tuple(cv.keys.tolist()) for cv in view.curves}) > 1  # the channels keep different keys
    for i, cv in enumerate(view.curves):
        np.testing.assert_array_equal(cv.original, motion.values[:, cols[i]])
        np.testing.assert_allclose(cv.key_curve[cv.keys], motion.values[cv.keys, cols[i]], atol=1e-9)
    # one channel's key dragged in time and value: one step, that channel's keys alone move
    i = 1
    keys = view.curves[i].keys.copy()
    k = int(np.argmax(np.minimum(np.diff(keys)[:-1], np.diff(keys)[1:]))) + 1
    f0 = int(keys[k])
    p = np.array(view.key_point(i, k))
    ui.drag(view, p, p + np.array([_frames_px(view, 1), -25.0]))
    assert w.undo_stack.count() == 1 and c.edits == []
    move, value = c.channel_edits
    name = view.curves[i].name
    assert move == ChannelRetimeEdit(f0, ARM, name, f0 + 1) and value.frame == f0 + 1
    lib = ChannelEditor(motion, c.channel_layer()._keys0, interp)
    lib.apply_all(c.channel_edits)
    assert np.array_equal(c.motion().values, lib.motion().values)
    ui.curves_match(view, lib, ARM)
    assert view.curves[i].keys.tolist() == lib.keys(cols[i]).tolist()
    assert [cv.keys.tolist() for n, cv in enumerate(view.curves) if n != i] == [
        e.tolist() for n, e in enumerate(expected) if n != i
    ]
    np.testing.assert_array_equal(w.animation.animation.frames, skeleton_animation(lib.motion()).frames)
    # its handle
    if view.curves[i].slope_out is not None:
        h = np.array(view.handle_point(i, k, 1))
        ui.drag(view, h, h + np.array([0.0, -20.0]))
        assert w.undo_stack.count() == 2 and isinstance(c.channel_edits[-1], TangentEdit)
        lib.apply_all(c.channel_edits[2:])
        assert np.array_equal(c.motion().values, lib.motion().values)
        ui.curves_match(view, lib, ARM)
        w.undo_stack.undo()
    w.undo_stack.undo()
    assert c.channel_edits == [] and np.array_equal(c.motion().values, motion.values)
    dock.per_channel.setChecked(False)
    assert all(np.array_equal(cv.keys, c.editor.keys) for cv in view.curves)


@pytest.mark.slow(seconds=9)
def test_a_project_keeps_the_moved_keys(ui, graph, make_window, tmp_path):
    w, view, _ = graph
    c = w.capture
    keys = c.editor.keys.copy()
    p = np.array(view.key_point(1, 2))
    # a pose key moved in time
    ui.drag(view, p, p + np.array([_frames_px(view, 2), 0.0]), steps=CAPTURE_STEPS)
    w.graph_editor.per_channel.setChecked(True)
    p = np.array(view.key_point(0, 1))
    ui.drag(view, p, p + np.array([0.0, -20.0]), steps=CAPTURE_STEPS)  # a per-channel key moved in value
    assert c.edits and c.channel_edits
    edited = c.motion().values
    path = tmp_path / "moved.hairproj"
    assert w.project.save_to(path)
    w2 = make_window()
    assert w2.open_path(path) and not w2.errors
    c2 = w2.capture
    assert c2.edits == c.edits and c2.channel_edits == c.channel_edits
    np.testing.assert_array_equal(c2.motion().values, edited)
    assert w2.animation.dp_keys.tolist() == w.animation.dp_keys.tolist() != keys.tolist()


def test_on_hair_the_strands_feature_channels_are_read_only_views_of_the_key_choice(ui, make_window):
    """Issue 30 point 4 on hair: the selected strand's feature channels (seed 000's space) drawn
    beside the vertex's coordinates, original faint behind the key curve through the keys;
    a press on one of their keys drags nothing and says why; they follow a vertex key's edit."""
    from app.ui.hair_channels import READ_ONLY
    from hairtool.keys.features import strand_features
    from hairtool.keys.reconstruct import interpolate_keys, key_poses

    w, view, anim = _hair(make_window, "hermite")
    m, dock = w.animation, w.graph_editor
    assert view.on_hair and dock.features.isVisibleTo(dock) and dock.features.isChecked()
    assert [c.name for c in view.curves] == ["x", "y", "z", "feature x", "feature y", "feature z"]
    assert [c.editable for c in view.curves] == [True] * 3 + [False] * 3
    options = m.settings.feature_options()
    sample = options.samples - 1  # the tip vertex: the last sample
    feats = strand_features(anim, 0, options)[:, sample]
    curve = interpolate_keys(key_poses(feats, m.dp_keys, "hermite"))
    for a, c in enumerate(view.curves[3:]):
        np.testing.assert_array_equal(c.original, feats[:, a])
        np.testing.assert_array_equal(c.result, feats[:, a])
        np.testing.assert_array_equal(c.key_curve, curve[:, a])
        assert c.keys.tolist() == m.dp_keys.tolist()
        np.testing.assert_array_equal(c.values, feats[m.dp_keys, a])
    # a press on a feature key (away from the vertex's keys) drags nothing and says why
    editable = np.concatenate([np.column_stack(view.to_px(c.keys, c.values)) for c in view.curves[:3]])
    picked = None
    for i in (3, 4, 5):
        for k in range(1, m.dp_keys.size - 1):
            p = np.array(view.key_point(i, k))
            if np.min(np.hypot(*(editable - p).T)) > 3 * 8.0:
                picked = p
                break
        if picked is not None:
            break
    assert picked is not None
    ui.drag(view, picked, picked + np.array([0.0, -30.0]))
    assert w.undo_stack.count() == 2 and view.refused == READ_ONLY
    np.testing.assert_array_equal(m.animation.frames, anim.frames)
    assert "read-only" in dock.features.toolTip().lower() or "not edited" in dock.features.toolTip()
    # a vertex key moved in value: the features follow the edited hair, the original stays
    k = 1
    p = np.array(view.key_point(1, k))
    ui.drag(view, p, p + np.array([0.0, -40.0]))
    assert w.undo_stack.count() == 3
    edited = strand_features(m.animation, 0, options)[:, sample]
    assert not np.array_equal(edited, feats)
    for a, c in enumerate(view.curves[3:]):
        np.testing.assert_array_equal(c.original, feats[:, a])
        np.testing.assert_array_equal(c.result, edited[:, a])
    # another strand, another sample along it; the box hides them
    dock.strand.setValue(3)
    dock.vertex.setValue(0)
    assert w.graph_editor.hair.sample() == 0
    root = strand_features(m.animation, 3, options)[:, 0]
    np.testing.assert_array_equal(view.curves[3].result, root[:, 0])
    dock.features.setChecked(False)
    assert [c.name for c in view.curves] == ["x", "y", "z"]


@pytest.mark.slow(seconds=9)
def test_a_projects_capture_edits_replay_through_the_cli_to_the_studios_motion(ui, graph, tmp_path, capsys):
    """Issue 30: ``hairtool keys --edit`` reads what the studio keeps of a capture (an IK drag, a
    pose key moved in time and value, a per-channel key moved in time and value) and writes the
    studio's edited capture, the same BVH bytes, given the studio's keys and price per key."""
    import json

    from hairtool.cli import main
    from hairtool.mocap.bvh import write_bvh

    w, view, motion = graph
    c, m = w.capture, w.animation
    j = motion.joint_names.index("mixamorig:LeftHand")
    start = w.viewport.project(c.pose_positions()[j][None])[0]
    ui.drag(w.viewport, start, start + np.array([30, -25]))  # an IK pose at the key
    assert len(c.edits) == 1
    c.select(ARM)  # the drag selected the hand
    keys = c.editor.keys.copy()
    k = 2
    p = np.array(view.key_point(1, k))
    # a pose key in time and value
    ui.drag(view, p, p + np.array([_frames_px(view, 1), -20.0]), steps=CAPTURE_STEPS)
    w.graph_editor.per_channel.setChecked(True)
    i = 2
    own = view.curves[i].keys
    k = int(np.argmax(np.minimum(np.diff(own)[:-1], np.diff(own)[1:]))) + 1
    p = np.array(view.key_point(i, k))
    ui.drag(view, p, p + np.array([_frames_px(view, -1), 25.0]), steps=CAPTURE_STEPS)  # one channel's key
    assert len(c.edits) == 3 and len(c.channel_edits) == 2 and w.undo_stack.count() == 3
    studio = tmp_path / "studio.bvh"
    write_bvh(studio, c.motion())
    path = tmp_path / "capture.json"
    path.write_text(json.dumps(c.to_settings()))  # the project's capture object as is
    out = tmp_path / "cli.bvh"
    src = tmp_path / "in.bvh"
    src.write_text(c.to_settings()["bvh"])  # the capture the project keeps
    argv = ["keys", str(src), "--keys", str(keys.size), "--pin", ",".join(map(str, m.solved_keys.tolist()))]
    argv += ["--interp", c.editor.interp, "--edit", str(path), "--export", str(out)]
    argv += ["--channel-price", str(m.settings.tau)]
    assert main(argv) == 0, capsys.readouterr().err
    assert out.read_bytes() == studio.read_bytes()
    assert not np.array_equal(read_bvh(out).values, motion.values)
