"""A key dragged in value (a graph editor's edit): one rotation channel of a key pose set, carried
to the frames around it with the residuals kept, like an IK edit."""

from __future__ import annotations

import numpy as np
import pytest

from hairtool.errors import FormatError, ParameterError
from hairtool.mocap import ik
from hairtool.mocap.bvh import read_bvh
from hairtool.mocap.pose_edit import ChannelEdit, PoseEdit, PoseEditor, TangentEdit, parse_edit_list


@pytest.fixture(scope="module")
def walk(motion_dir):
    m = read_bvh(motion_dir / "freebvh.bvh")
    keys = np.r_[np.arange(0, m.n_frames - 1, 12), m.n_frames - 1]
    return m, keys


@pytest.mark.parametrize("interp", ["linear", "hermite", "hermite-fit"])
def test_a_channel_key_moves_and_fades_to_the_neighbouring_keys(walk, interp):
    m, keys = walk
    joint = "mixamorig:LeftForeArm"
    j = m.joint_names.index(joint)
    cols, _ = ik.rotation_columns(m, j)
    f = int(keys[2])
    channel = m.channels[j][cols[1] - int(m._starts[j])]
    editor = PoseEditor(m, keys, interp)
    value = float(m.values[f, cols[1]] + 25.0)
    report = editor.apply_channel(ChannelEdit(f, joint, channel, value))
    out = editor.motion()
    lo, hi = int(keys[1]), int(keys[3])
    assert (report.first, report.last) == (lo + 1, hi - 1)
    # At the key: the dragged channel has its new value, the joint's other angles are kept.
    np.testing.assert_allclose(
        out.values[f, cols], [m.values[f, cols[0]], value, m.values[f, cols[2]]], atol=1e-6
    )
    # Elsewhere the capture bit for bit; every other joint too.
    outside = np.r_[0 : lo + 1, hi : m.n_frames]
    assert np.array_equal(out.values[outside], m.values[outside])
    others = np.setdiff1d(np.arange(m.n_channels), cols)
    assert np.array_equal(out.values[:, others], m.values[:, others])
    # The change fades from the key toward its neighbours.
    change = np.abs(out.values[lo + 1 : hi, cols[1]] - m.values[lo + 1 : hi, cols[1]])
    assert change[f - lo - 1] == pytest.approx(25.0, abs=1e-6)
    assert change[0] < 25.0 * 0.5 and change[-1] < 25.0 * 0.5
    # The key curve passes through the new key value and undo gives the capture back.
    curve = editor.key_curve(j, out.values[:, cols])
    assert curve[f, 1] == pytest.approx(value, abs=1e-6)
    assert editor.undo() == ChannelEdit(f, joint, channel, value)
    assert np.array_equal(editor.motion().values, m.values)


def test_channel_and_pose_edits_compose_from_a_list(walk):
    m, keys = walk
    f = int(keys[3])
    hand = "mixamorig:LeftHand"
    p = m.joint_positions()[f, m.joint_names.index(hand)]
    h = ik.figure_height(m)
    data = [
        {"frame": f, "joint": hand, "target": (p + np.array([0.03, 0.05, 0.0]) * h).tolist(), "chain": 2},
        {"frame": f, "joint": m.joint_names[2], "channel": m.channels[2][-1], "value": 10.0},
    ]
    edits = parse_edit_list(data, m)
    assert isinstance(edits[0], PoseEdit) and isinstance(edits[1], ChannelEdit)
    assert [e.to_dict() for e in edits] == data
    a, b = PoseEditor(m, keys, "hermite"), PoseEditor(m, keys, "hermite")
    a.apply_all(edits)
    b.apply(edits[0])
    b.apply_channel(edits[1])
    assert np.array_equal(a.motion().values, b.motion().values)


def test_bad_channel_edits_are_refused_in_one_line(walk):
    m, keys = walk
    with pytest.raises(FormatError, match="edit 2: 'Xposition' is not a rotation channel"):
        parse_edit_list(
            [
                {"frame": 0, "joint": m.joint_names[1], "channel": m.channels[1][-1], "value": 1},
                {"frame": 0, "joint": m.joint_names[0], "channel": "Xposition", "value": 1},
            ],
            m,
            "p",
        )
    with pytest.raises(FormatError, match="edit 1: value"):
        parse_edit_list(
            [{"frame": 0, "joint": m.joint_names[1], "channel": m.channels[1][-1], "value": "x"}], m
        )
    with pytest.raises(FormatError, match="edit 1 lacks target"):
        parse_edit_list([{"frame": 0, "joint": m.joint_names[1], "chain": 1}], m)
    with pytest.raises(ParameterError):
        PoseEditor(m, keys).apply_channel(ChannelEdit(1, m.joint_names[1], m.channels[1][-1], 1.0))


@pytest.mark.parametrize("interp", ["hermite", "hermite-fit"])
@pytest.mark.parametrize("joint", ["mixamorig:LeftForeArm", "mixamorig:Hips"])
def test_a_handle_sets_the_key_curves_slope_and_fades_to_the_neighbouring_keys(walk, interp, joint):
    m, keys = walk
    j = m.joint_names.index(joint)
    cols, _ = ik.rotation_columns(m, j)
    f = int(keys[2])
    editor = PoseEditor(m, keys, interp)
    _, s_out = editor.key_slopes(j)
    channel = m.channels[j][cols[0] - int(m._starts[j])]
    slope = float(s_out[2, 0] + 3.0)
    report = editor.apply_tangent(TangentEdit(f, joint, channel, slope))
    out = editor.motion()
    lo, hi = int(keys[1]), int(keys[3])
    assert (report.first, report.last) == (lo + 1, hi - 1)
    # The slope at the key is the handle's, both sides; the joint's other angles keep theirs.
    n_in, n_out = editor.key_slopes(j)
    assert n_in[2, 0] == pytest.approx(slope, abs=1e-6) and n_out[2, 0] == pytest.approx(slope, abs=1e-6)
    np.testing.assert_allclose(n_out[2, 1:], s_out[2, 1:], atol=1e-6)
    np.testing.assert_allclose(np.delete(n_out, 2, axis=0), np.delete(s_out, 2, axis=0), atol=1e-9)
    # The key itself does not move; the frames beside it turn; elsewhere the capture bit for bit.
    np.testing.assert_allclose(out.values[f, cols], m.values[f, cols], atol=1e-6)
    assert abs(out.values[f + 1, cols[0]] - m.values[f + 1, cols[0]]) > 0.5
    outside = np.r_[0 : lo + 1, hi : m.n_frames]
    assert np.array_equal(out.values[outside], m.values[outside])
    others = np.setdiff1d(np.arange(m.n_channels), cols)
    assert np.array_equal(out.values[:, others], m.values[:, others])
    # The key curve's slope over the frames beside the key grew with the handle: a tangent
    # changed by Δ at a key L frames from both neighbours moves the frames beside it by
    # ±Δ·L·h10(1/L) (the Hermite basis), about 0.84 Δ here.
    before = PoseEditor(m, keys, interp).key_curve(j, m.values[:, cols])
    curve = editor.key_curve(j, out.values[:, cols])
    grew = (curve[f + 1, 0] - curve[f - 1, 0] - before[f + 1, 0] + before[f - 1, 0]) / 2
    assert 0.6 * 3.0 < grew < 1.05 * 3.0
    assert isinstance(editor.undo(), TangentEdit)
    assert np.array_equal(editor.motion().values, m.values)


def test_linear_keys_have_no_handles(walk):
    m, keys = walk
    editor = PoseEditor(m, keys, "linear")
    assert editor.key_slopes(1) is None
    with pytest.raises(ParameterError, match="linear keys have no handles"):
        editor.apply_tangent(TangentEdit(int(keys[1]), m.joint_names[1], m.channels[1][-1], 1.0))
    edits = parse_edit_list(
        [{"frame": 0, "joint": m.joint_names[1], "channel": m.channels[1][-1], "slope": 2}], m
    )
    assert edits == [TangentEdit(0, m.joint_names[1], m.channels[1][-1], 2.0)]
