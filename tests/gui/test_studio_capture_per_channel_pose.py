"""A joint dragged with per-channel keys on (issue 30 points 3 and 5): the IK poses the layer the
studio shows, each channel it turns keyed on that channel's own keys, so the dragged joint lands
on the cursor there; one undo step, a live preview, kept in projects, and `hairtool keys --edit`
on the project's edits writes the same BVH."""

from __future__ import annotations

import json

import numpy as np
import pytest

from app.ui.animation_io import skeleton_animation
from hairtool.mocap import ik
from hairtool.mocap.bvh import read_bvh, write_bvh
from hairtool.mocap.channel_edit import ChannelEditor
from hairtool.mocap.pose_edit import ChannelEdit, PoseEdit

pytestmark = pytest.mark.gui

HAND = "mixamorig:LeftHand"
ARM = "mixamorig:LeftForeArm"


def _handle(w, joint):
    j = w.capture.original.joint_names.index(joint)
    return w.viewport.project(w.capture.pose_positions()[j][None])[0]


def _shown_at(w, joint):
    """Where the studio draws ``joint`` now: its handle's point, the edited capture's joint."""
    c = w.capture
    j = c.original.joint_names.index(joint)
    f = w.animation.frame
    return c.pose_positions()[j], c.motion().joint_positions()[f, j]


def test_a_joint_drag_with_per_channel_keys_lands_on_the_cursor_and_replays_through_the_cli(
    ui, make_window, motion_dir, tmp_path, capsys
):
    from hairtool.cli import main

    path = motion_dir / "freebvh.bvh"
    motion = read_bvh(path)
    h = ik.figure_height(motion)
    w = make_window(path)
    c, m = w.capture, w.animation
    w.graph_editor.show()
    w.graph_editor.view.resize(700, 260)
    c.select(ARM)
    w.graph_editor.per_channel.setChecked(True)
    assert c.per_channel and c.layered
    # a forearm channel's own key before the pose key moved in value: the layer over the pose
    # keys changes the forearm at the pose key, where a pose-key IK below it would miss the cursor
    f = int(c.editor.keys[1])
    m.set_frame(f)
    arm = motion.joint_names.index(ARM)
    cols, _ = ik.rotation_columns(motion, arm)
    own = c.column_keys(cols)[0]
    assert f not in own  # this pose key is no key of the channel: the IK pose adds one there
    k = int(own[np.searchsorted(own, f) - 1])
    name = motion.channels[arm][cols[0] - int(motion._starts[arm])]
    assert c.commit_channel([ChannelEdit(k, ARM, name, float(motion.values[k, cols[0]]) + 15.0)], "arm key")
    assert w.undo_stack.count() == 1 and c.edits == []
    assert not np.array_equal(c.motion().values[f], c.editor.motion().values[f])
    before = c.motion().values.copy()
    start = _handle(w, HAND)
    seen = []
    c.preview_changed.connect(lambda: seen.append((len(c.ghosts), c._preview is not None)))
    ui.drag(w.viewport, start, start + np.array([35.0, -30.0]))
    # previewed while dragging, the neighbouring frames as ghosts
    assert seen and max(g for g, _ in seen) > 0 and any(p for _, p in seen)
    assert w.undo_stack.count() == 2 and c.edits == [] and not w.errors
    target = c.drag.last_target
    hand = motion.joint_names.index(HAND)
    assert c.channel_edits[-1] == PoseEdit(f, HAND, tuple(target), 2)
    assert np.linalg.norm(target - motion.joint_positions()[f, hand]) > 0.01 * h
    # what is displayed: the handle, the edited capture and the timeline's skeleton
    for got in _shown_at(w, HAND):
        assert np.linalg.norm(got - target) < 1e-4 * h
    edited = c.motion()
    np.testing.assert_array_equal(m.animation.frames, skeleton_animation(edited).frames)
    assert "reached on its channels' own keys" in c.report.text()
    assert np.array_equal(edited.offsets, motion.offsets)
    # the library's layer: the per-channel keys over the pose keys, the pose allowed at a pose key;
    # the forearm's channels drawn with the key the pose added at the pose key
    lib = ChannelEditor(c.editor.motion(), c.channel_layer()._keys0, c.editor.interp, pose_keys=c.editor.keys)
    lib.apply_all(c.channel_edits)
    assert np.array_equal(edited.values, lib.motion().values)
    c.select(ARM)
    ui.curves_match(w.graph_editor.view, lib, ARM)
    assert all(f in cv.keys for cv in w.graph_editor.view.curves)
    # one undo step: the drag goes, the key edit before it stays; redo brings it back
    w.undo_stack.undo()
    assert len(c.channel_edits) == 1 and np.array_equal(c.motion().values, before)
    np.testing.assert_array_equal(m.animation.frames, skeleton_animation(c.motion()).frames)
    w.undo_stack.redo()
    assert np.array_equal(c.motion().values, edited.values)

    # a project keeps it and opens on the same motion
    project = tmp_path / "per_channel_pose.hairproj"
    assert w.project.save_to(project)
    w2 = make_window()
    assert w2.open_path(project) and not w2.errors
    c2 = w2.capture
    assert c2.channel_edits == c.channel_edits and c2.edits == c.edits
    np.testing.assert_array_equal(c2.motion().values, edited.values)
    w2.animation.set_frame(f)
    for got in _shown_at(w2, HAND):
        assert np.linalg.norm(got - target) < 1e-4 * h

    # the CLI on the project's capture object writes the studio's BVH, byte for byte
    studio = tmp_path / "studio.bvh"
    write_bvh(studio, edited)
    edits = tmp_path / "capture.json"
    edits.write_text(json.dumps(c.to_settings()))
    src = tmp_path / "in.bvh"
    src.write_text(c.to_settings()["bvh"])
    out = tmp_path / "cli.bvh"
    keys = m.solved_keys
    argv = ["keys", str(src), "--keys", str(keys.size), "--pin", ",".join(map(str, keys.tolist()))]
    argv += ["--interp", c.editor.interp, "--edit", str(edits), "--export", str(out)]
    argv += ["--channel-price", str(m.settings.tau)]
    assert main(argv) == 0, capsys.readouterr().err
    assert out.read_bytes() == studio.read_bytes()
    # and the effector is on the cursor in the written capture too (BVH keeps 6 decimals)
    back = read_bvh(out).joint_positions()[f, hand]
    assert np.linalg.norm(back - target) < 1e-4 * h


def test_without_per_channel_keys_a_joint_drag_stays_on_the_pose_keys(ui, make_window, motion_dir):
    path = motion_dir / "freebvh.bvh"
    w = make_window(path)
    c = w.capture
    w.animation.set_frame(int(c.editor.keys[1]))
    assert not c.layered
    start = _handle(w, HAND)
    ui.drag(w.viewport, start, start + np.array([30.0, -20.0]))
    assert len(c.edits) == 1 and c.channel_edits == [] and isinstance(c.edits[0], PoseEdit)
