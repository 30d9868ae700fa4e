"""A capture's key moved in time (issue 30: a graph editor key dragged sideways): the whole pose
key moves, every channel follows between the neighbouring keys with the residuals retimed, and
it composes with the other edits and undoes."""

from __future__ import annotations

import numpy as np
import pytest

from hairtool.errors import ParameterError
from hairtool.keys.edit import retime_key
from hairtool.mocap import ik
from hairtool.mocap.bvh import read_bvh
from hairtool.mocap.pose_edit import ChannelEdit, PoseEditor, RetimeEdit, TangentEdit, parse_edit_list


@pytest.fixture(scope="module")
def walk(motion_dir):
    m = read_bvh(motion_dir / "freebvh.bvh")
    keys = np.r_[np.arange(0, m.n_frames - 1, 12), m.n_frames - 1]
    return m, keys


@pytest.mark.parametrize("interp", ["linear", "hermite", "hermite-fit"])
def test_a_key_moved_in_time_holds_its_pose_there_and_changes_only_between_its_neighbours(walk, interp):
    m, keys = walk
    f, to = int(keys[2]), int(keys[2]) + 4
    lo, hi = int(keys[1]), int(keys[3])
    editor = PoseEditor(m, keys, interp)
    report = editor.apply_retime(RetimeEdit(f, to))
    assert (report.first, report.last) == (lo + 1, hi - 1)
    assert editor.keys.tolist() == [*keys[:2].tolist(), to, *keys[3:].tolist()]
    out = editor.motion()
    outside = np.r_[0 : lo + 1, hi : m.n_frames]
    assert np.array_equal(out.values[outside], m.values[outside])
    # at its new frame the figure stands in the key's pose (joint positions, any Euler wraps)
    h = ik.figure_height(m)
    got, want = out.joint_positions()[to], m.joint_positions()[f]
    assert np.abs(got - want).max() < 1e-6 * h
    assert np.abs(m.joint_positions()[to] - want).max() > 1e-3 * h
    # the channels no joint turns (the root's position) are the array retime of them
    others = editor._other_columns()
    start, block, _ = retime_key(m.values[:, others], keys, interp, f, to)
    np.testing.assert_allclose(out.values[start : start + len(block), others], block, atol=1e-9)
    assert editor.undo() == RetimeEdit(f, to)
    assert np.array_equal(editor.motion().values, m.values) and np.array_equal(editor.keys, keys)


def test_linear_keys_moved_in_time_are_the_capture_retimed(walk):
    m, keys = walk
    f, to = int(keys[2]), int(keys[2]) - 5
    editor = PoseEditor(m, keys, "linear")
    editor.apply_retime(RetimeEdit(f, to))
    out = editor.motion().joint_positions()
    pos = m.joint_positions()
    lo = int(keys[1])
    # halfway between the previous key and the new frame shows what halfway to the old one did
    t = lo + (to - lo) // 2
    u = lo + (t - lo) * (f - lo) / (to - lo)
    i = int(np.floor(u))
    expected = pos[i] + (u - i) * (pos[i + 1] - pos[i])
    assert np.abs(out[t] - expected).max() < 0.02 * ik.figure_height(m)


def test_edits_after_a_move_name_the_new_frame_and_everything_undoes(walk):
    m, keys = walk
    f, to = int(keys[3]), int(keys[3]) + 3
    joint = "mixamorig:LeftForeArm"
    j = m.joint_names.index(joint)
    cols, _ = ik.rotation_columns(m, j)
    channel = m.channels[j][cols[1] - int(m._starts[j])]
    editor = PoseEditor(m, keys, "hermite")
    edits = [
        RetimeEdit(f, to),
        ChannelEdit(to, joint, channel, float(m.values[f, cols[1]] + 20.0)),
        TangentEdit(to, joint, channel, 1.5),
    ]
    editor.apply_all(edits)
    out = editor.motion()
    assert out.values[to, cols[1]] == pytest.approx(m.values[f, cols[1]] + 20.0, abs=1e-6)
    assert editor.key_curve(j, out.values[:, cols])[to, 1] == pytest.approx(out.values[to, cols[1]], abs=1e-6)
    slopes_in, slopes_out = editor.key_slopes(j)
    np.testing.assert_allclose([slopes_in[3, 1], slopes_out[3, 1]], 1.5, atol=1e-6)
    with pytest.raises(ParameterError, match="a key frame"):
        editor.apply_channel(ChannelEdit(f, joint, channel, 0.0))  # no longer a key
    # the list form (a project's edits) reads back the same edits
    assert parse_edit_list([e.to_dict() for e in edits], m) == edits
    assert edits[0].to_dict() == {"frame": f, "to": to}
    editor.reset()
    assert np.array_equal(editor.motion().values, m.values) and np.array_equal(editor.keys, keys)


def test_a_key_cannot_pass_its_neighbours(walk):
    m, keys = walk
    editor = PoseEditor(m, keys)
    with pytest.raises(ParameterError, match="strictly between"):
        editor.apply_retime(RetimeEdit(int(keys[2]), int(keys[3])))
    with pytest.raises(ParameterError, match="inner key"):
        editor.apply_retime(RetimeEdit(0, 2))
    assert editor.reports == []
