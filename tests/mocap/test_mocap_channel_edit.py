"""Per-channel keys of real captures (each BVH channel its own keys) and IK edits on them."""

from __future__ import annotations

import numpy as np
import pytest

from hairtool.errors import ParameterError
from hairtool.keys.channels import per_channel_keys
from hairtool.mocap import ik
from hairtool.mocap.bvh import read_bvh
from hairtool.mocap.channel_edit import ChannelEditor, channel_features, channel_key_curve
from hairtool.mocap.pose_edit import PoseEdit


@pytest.fixture(scope="module", params=["freebvh.bvh", "mocapbank_walk.bvh"])
def keyed(request, motion_dir):
    m = read_bvh(motion_dir / request.param)
    m = m.with_values(m.values[:240])  # the walk's first 8 s: 60 channels keyed in about a second
    keys = per_channel_keys(channel_features(m), 0.01, interp="hermite", relative=True).keys
    hand = "mixamorig:LeftHand" if request.param == "freebvh.bvh" else "LeftWrist"
    return m, keys, hand


def _edit(m, frame, joint, push, chain=2):
    p = m.joint_positions()[frame, m.joint_names.index(joint)]
    return PoseEdit(frame, joint, tuple(p + np.asarray(push) * ik.figure_height(m)), chain)


def test_channel_features_unwrap_the_angles_only(motion_dir):
    m = read_bvh(motion_dir / "pymo_walk.bvh")
    x = channel_features(m)
    assert np.abs(np.diff(m.values, axis=0)).max() > 300  # the capture wraps
    assert np.abs(np.diff(x, axis=0)).max() < 30
    assert np.array_equal(x[:, :3], m.values[:, :3])  # root position, not angles
    turns = (x - m.values) / 360.0
    np.testing.assert_allclose(turns, np.round(turns), atol=1e-9)


def test_the_per_channel_key_curve_is_the_capture_with_every_frame_a_key(motion_dir):
    m = read_bvh(motion_dir / "pymo_walk.bvh")
    every = [np.arange(m.n_frames)] * m.n_channels
    np.testing.assert_allclose(channel_key_curve(m, every, "hermite").values, m.values, rtol=0, atol=1e-9)


@pytest.mark.parametrize("interp", ["linear", "hermite"])
def test_an_edit_on_per_channel_keys_reaches_its_target_and_moves_only_its_channels_near_their_keys(
    keyed, interp
):
    m, keys, hand = keyed
    h = ik.figure_height(m)
    editor = ChannelEditor(m, keys, interp)
    f = int(editor.union[len(editor.union) // 2])
    edit = _edit(m, f, hand, [0.03, 0.08, 0.03])
    report = editor.apply(edit)
    out = editor.motion()
    e = m.joint_names.index(hand)
    assert np.linalg.norm(out.joint_positions()[f, e] - edit.target) < 1e-4 * h
    assert report.miss_share < 1e-4
    assert np.array_equal(out.offsets, m.offsets) and out.channels == m.channels
    turned = ik.ancestors(m, e, 2)
    cols = [c for j in turned for c in ik.rotation_columns(m, j)[0]]
    others = np.setdiff1d(np.arange(m.n_channels), cols)
    assert np.array_equal(out.values[:, others], m.values[:, others])
    moved = [c for c in cols if not np.array_equal(out.values[:, c], m.values[:, c])]
    assert moved
    for c in moved:
        k = editor.keys(c)
        assert f in k  # a key of the channel, or one the edit inserted
        a = int(np.searchsorted(k, f))
        lo = int(k[a - 1]) if a > 0 else -1
        hi = int(k[a + 1]) if a < k.size - 1 else m.n_frames
        outside = np.r_[0 : lo + 1, hi : m.n_frames]
        assert np.array_equal(out.values[outside, c], m.values[outside, c])
        d = np.abs(out.values[:, c] - m.values[:, c])
        assert d[f] == d.max() > 0
        if lo >= 0 and f - lo > 3:
            assert d[lo + 1] < d[(lo + f) // 2] < d[f]
    # Angles add: the edited channels move frame to frame as the capture's, plus the spread.
    step = np.abs(np.diff(out.values[:, moved] - m.values[:, moved], axis=0))
    assert step.max() < 0.5 * np.abs(out.values[f, moved] - m.values[f, moved]).max() + 1e-9


def test_edits_insert_keys_compose_and_undo(keyed):
    m, keys, hand = keyed
    h = ik.figure_height(m)
    editor = ChannelEditor(m, keys, "hermite")
    u = editor.union
    f1, f2 = int(u[len(u) // 3]), int(u[len(u) // 3 + 2])
    e = m.joint_names.index(hand)
    first = _edit(m, f1, hand, [0.0, 0.06, 0.02])
    editor.apply(first)
    after_first = editor.motion().values
    # The same limb at another frame: f1 is now a key of every channel the first edit moved, so
    # the second cannot move them there (a channel keyed at neither frame, a collar turned by a
    # longer chain, would carry the second edit across f1: per-channel keys are not shared).
    second = _edit(m, f2, hand, [0.02, 0.03, 0.03])
    editor.apply(second)
    p = editor.motion().joint_positions()
    # Both effectors on their targets: a key the second inserted keeps the first edit's value there.
    assert np.linalg.norm(p[f1, e] - first.target) < 1e-4 * h
    assert np.linalg.norm(p[f2, e] - second.target) < 1e-4 * h
    assert editor.undo() == second
    assert np.array_equal(editor.motion().values, after_first)
    editor.reset()
    assert np.array_equal(editor.motion().values, m.values) and editor.undo() is None


def test_a_frame_no_channel_keys_is_refused(motion_dir):
    m = read_bvh(motion_dir / "freebvh.bvh")
    last = m.n_frames - 1
    editor = ChannelEditor(m, [[0, 20, 40, last]] * m.n_channels)
    with pytest.raises(ParameterError, match=f"a key of some channel: 0 20 40 {last}"):
        editor.apply(_edit(m, 21, "mixamorig:LeftHand", [0.0, 0.05, 0.0]))
    with pytest.raises(ParameterError, match="one key list per channel"):
        ChannelEditor(m, [[0, last]])
    with pytest.raises(ParameterError, match="frames from 0"):
        ChannelEditor(m, [[0, 5]] * m.n_channels)
