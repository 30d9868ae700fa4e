"""Per-channel keys (seed 003: each channel its own keys) moved as a graph editor drags them: in
value, in slope and in time, one channel at a time, the residuals kept, undoable."""

from __future__ import annotations

import numpy as np
import pytest

from hairtool.errors import ParameterError
from hairtool.keys.channels import per_channel_keys
from hairtool.keys.edit import retime_key
from hairtool.mocap import ik
from hairtool.mocap.bvh import read_bvh
from hairtool.mocap.channel_edit import ChannelEditor, ChannelRetimeEdit, channel_features
from hairtool.mocap.pose_edit import ChannelEdit, TangentEdit

ARM = "mixamorig:LeftForeArm"


@pytest.fixture(scope="module")
def keyed(motion_dir):
    m = read_bvh(motion_dir / "freebvh.bvh")
    keys = per_channel_keys(channel_features(m), 0.01, interp="hermite", relative=True).keys
    j = m.joint_names.index(ARM)
    col = ik.rotation_columns(m, j)[0][1]
    name = m.channels[j][col - int(m._starts[j])]
    return m, keys, col, name


def _inner(keys):
    """An inner key with room on both sides."""
    gaps = np.diff(keys)
    a = int(np.argmax(np.minimum(gaps[:-1], gaps[1:]))) + 1
    return a, int(keys[a])


@pytest.mark.parametrize("interp", ["linear", "hermite", "hermite-fit"])
def test_a_channel_key_moved_in_value_changes_that_channel_between_its_neighbours(keyed, interp):
    m, keys, col, name = keyed
    editor = ChannelEditor(m, keys, interp)
    k = editor.keys(col)
    a, f = _inner(k)
    value = float(m.values[f, col] + 15.0)
    report = editor.apply_channel(ChannelEdit(f, ARM, name, value))
    assert (report.first, report.last) == (int(k[a - 1]) + 1, int(k[a + 1]) - 1)
    out = editor.motion()
    assert out.values[f, col] == pytest.approx(value, abs=1e-9)
    others = np.setdiff1d(np.arange(m.n_channels), [col])
    assert np.array_equal(out.values[:, others], m.values[:, others])
    outside = np.r_[0 : k[a - 1] + 1, k[a + 1] : m.n_frames]
    assert np.array_equal(out.values[outside, col], m.values[outside, col])
    assert editor.key_curve(col)[f] == pytest.approx(value, abs=1e-9)
    assert editor.undo() == ChannelEdit(f, ARM, name, value)
    assert np.array_equal(editor.motion().values, m.values)


@pytest.mark.parametrize("interp", ["hermite", "hermite-fit"])
def test_a_channel_handle_turned_sets_its_slope_and_keeps_the_keys(keyed, interp):
    m, keys, col, name = keyed
    editor = ChannelEditor(m, keys, interp)
    k = editor.keys(col)
    a, f = _inner(k)
    before = editor.key_slopes(col)[1][a]
    editor.apply_tangent(TangentEdit(f, ARM, name, before + 2.0))
    assert editor.key_slopes(col)[1][a] == pytest.approx(before + 2.0, abs=1e-9)
    out = editor.motion()
    assert np.array_equal(out.values[k, col], m.values[k, col])  # the key values stay
    assert not np.allclose(out.values[:, col], m.values[:, col])
    outside = np.r_[0 : k[a - 1] + 1, k[a + 1] : m.n_frames]
    assert np.array_equal(out.values[outside, col], m.values[outside, col])
    editor.reset()
    with pytest.raises(ParameterError, match="no handles"):
        ChannelEditor(m, keys, "linear").apply_tangent(TangentEdit(f, ARM, name, 1.0))


@pytest.mark.parametrize("interp", ["linear", "hermite", "hermite-fit"])
def test_a_channel_key_moved_in_time_is_the_array_retime_of_that_channel(keyed, interp):
    m, keys, col, name = keyed
    editor = ChannelEditor(m, keys, interp)
    k = editor.keys(col)
    a, f = _inner(k)
    to = f + max((int(k[a + 1]) - f) // 2, 1)
    editor.apply_retime(ChannelRetimeEdit(f, ARM, name, to))
    assert editor.keys(col).tolist() == [*k[:a].tolist(), to, *k[a + 1 :].tolist()]
    assert all(np.array_equal(editor.keys(c), keys[c]) for c in range(m.n_channels) if c != col)
    out = editor.motion()
    x = channel_features(m)[:, col : col + 1]
    start, block, _ = retime_key(x, k, interp, f, to)
    turns = m.values[:, col] - x[:, 0]
    span = slice(start, start + len(block))
    np.testing.assert_allclose(out.values[span, col], block[:, 0] + turns[span], atol=1e-9)
    others = np.setdiff1d(np.arange(m.n_channels), [col])
    assert np.array_equal(out.values[:, others], m.values[:, others])
    # then moved in value at its new frame, and its handle: each on the moved key
    editor.apply_channel(ChannelEdit(to, ARM, name, float(out.values[to, col] + 10.0)))
    assert editor.motion().values[to, col] == pytest.approx(out.values[to, col] + 10.0, abs=1e-9)
    if interp != "linear":
        editor.apply_tangent(TangentEdit(to, ARM, name, 0.5))
        assert editor.key_slopes(col)[1][a] == pytest.approx(0.5, abs=1e-9)
    with pytest.raises(ParameterError, match="a key of the"):
        editor.apply_channel(ChannelEdit(f, ARM, name, 0.0))  # no longer one of its keys
    with pytest.raises(ParameterError, match="strictly between"):
        editor.apply_retime(ChannelRetimeEdit(to, ARM, name, int(k[a + 1])))
    editor.reset()
    assert np.array_equal(editor.motion().values, m.values) and np.array_equal(editor.keys(col), k)
    as_dict = {"frame": f, "joint": ARM, "channel": name, "to": to}
    assert ChannelRetimeEdit(f, ARM, name, to).to_dict() == as_dict


def test_each_editor_refuses_the_other_ones_key_moves(keyed):
    """One dispatcher (pose_edit.apply_edits) for both editors: a pose key's move is no edit of
    per-channel keys, one channel's key move none of the pose keys (each read as the other
    before, or failed deep inside), and neither editor is changed by the refusal."""
    from hairtool.mocap.pose_edit import PoseEditor, RetimeEdit, apply_edits

    m, keys, col, name = keyed
    per = ChannelEditor(m, keys, "hermite")
    _, f = _inner(keys[col])
    with pytest.raises(ParameterError, match="an edit of per-channel keys"):
        per.apply_all([RetimeEdit(f, f + 1)])
    assert per.reports == [] and np.array_equal(per.motion().values, m.values)
    pose = PoseEditor(m, keys[col], "hermite")
    with pytest.raises(ParameterError, match="an edit of the pose keys"):
        pose.apply_all([ChannelRetimeEdit(f, ARM, name, f + 1)])
    assert pose.reports == [] and np.array_equal(pose.keys, keys[col])
    with pytest.raises(ParameterError, match="edit="):
        apply_edits(pose, ["retime"])
    assert [r.method for r in apply_edits(pose, [RetimeEdit(f, f + 1)])] == ["retime"]


@pytest.mark.parametrize("interp", ["linear", "hermite"])
def test_an_ik_pose_at_a_frame_a_moved_channel_key_stretched_adds_a_key_there(keyed, interp):
    """Issue 30 (stop 33 point 3): an IK pose at a frame inside a stretch a moved per-channel
    key retimed was refused; now each turned channel takes a key there on top of the stretch,
    the effector reaches its target, the change fades to nothing at that channel's neighbouring
    keys, the stretch keeps its retimed detail elsewhere, and it undoes."""
    from hairtool.mocap.pose_edit import PoseEdit

    m, keys, col, name = keyed
    editor = ChannelEditor(m, keys, interp)
    k = keys[col]
    a, f0 = _inner(k)
    to = f0 + 2 if k[a + 1] - f0 > 3 else f0 - 2
    editor.apply_retime(ChannelRetimeEdit(f0, ARM, name, to))
    retimed = editor.motion()
    lo, hi = int(k[a - 1]), int(k[a + 1])
    union = editor.union
    inside = [f for f in range(lo + 1, hi) if f != to and f in union and f not in editor.keys(col)]
    assert inside, "no frame of the stretch is a key of another channel"
    f = inside[len(inside) // 2]
    h = ik.figure_height(m)
    hand = m.joint_names.index("mixamorig:LeftHand")
    target = retimed.joint_positions()[f, hand] + [0.0, 0.05 * h, 0.03 * h]
    report = editor.apply(PoseEdit(f, "mixamorig:LeftHand", tuple(target), 2))
    out = editor.motion()
    assert np.linalg.norm(out.joint_positions()[f, hand] - target) < 1e-4 * h
    assert report.miss_share < 1e-4 and f in editor.keys(col)
    assert np.array_equal(out.offsets, m.offsets)
    # the stretched channel: a key at f now, changed only between its neighbouring keys
    ck = editor.keys(col)
    i = int(np.flatnonzero(ck == f)[0])
    outside = np.r_[0 : int(ck[i - 1]) + 1, int(ck[i + 1]) : m.n_frames]
    assert np.array_equal(out.values[outside, col], retimed.values[outside, col])
    assert out.values[f, col] != retimed.values[f, col]
    # channels the IK did not turn keep their values
    turned = {c for j in ik.ancestors(m, hand, 2) for c in ik.rotation_columns(m, j)[0]}
    assert col in turned
    still = [c for c in range(m.n_channels) if c not in turned]
    assert np.array_equal(out.values[:, still], retimed.values[:, still])
    # a second pose at the same frame refines that key; a value set there too
    higher = target + np.array([0.0, 0.01 * h, 0.0])
    editor.apply(PoseEdit(f, "mixamorig:LeftHand", tuple(higher), 2))
    again = editor.motion()
    assert np.linalg.norm(again.joint_positions()[f, hand] - higher) < 1e-4 * h
    editor.apply_channel(ChannelEdit(f, ARM, name, float(again.values[f, col]) + 5.0))
    assert editor.motion().values[f, col] == pytest.approx(again.values[f, col] + 5.0, abs=1e-9)
    slopes = editor.key_slopes(col)
    if slopes is not None:
        assert slopes[0].size == ck.size and np.all(np.isfinite(slopes[0]))
    # such a key moves in value only, and no key passes it
    with pytest.raises(ParameterError, match="moves in value only"):
        editor.apply_retime(ChannelRetimeEdit(f, ARM, name, f + 1))
    with pytest.raises(ParameterError, match="strictly between"):
        editor.apply_retime(ChannelRetimeEdit(to, ARM, name, f + (1 if f > to else -1)))
    for _ in range(3):
        editor.undo()
    assert np.array_equal(editor.motion().values, retimed.values)
    assert f not in editor.keys(col) and to in editor.keys(col)
