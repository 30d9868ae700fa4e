"""Key poses of real captures edited by IK, carried to every frame with the residuals kept."""

from __future__ import annotations

import json

import numpy as np
import pytest

from hairtool.errors import FormatError, ParameterError
from hairtool.mocap import ik
from hairtool.mocap import quaternion as quat
from hairtool.mocap.bvh import read_bvh, write_bvh
from hairtool.mocap.costs import reconstruct_motion
from hairtool.mocap.pose_edit import PoseEdit, PoseEditor, parse_edits, read_edits

#: capture: (keys every N frames, a hand and a foot)
CAPTURES = {
    "pymo_walk.bvh": (120, "LeftHand", "RightFoot"),
    "mocapbank_walk.bvh": (40, "LeftWrist", "RightAnkle"),
    "freebvh.bvh": (12, "mixamorig:LeftHand", "mixamorig:RightFoot"),
}


@pytest.fixture(scope="module", params=sorted(CAPTURES))
def capture(request, motion_dir):
    m = read_bvh(motion_dir / request.param)
    step, hand, foot = CAPTURES[request.param]
    keys = np.r_[np.arange(0, m.n_frames - 1, step), m.n_frames - 1]
    return m, keys, hand, foot


def _edit(m, keys, joint, push, chain=2, which=2):
    """An edit at the ``which``-th key moving ``joint`` by ``push`` figure heights."""
    f = int(keys[which])
    p = m.joint_positions()[f, m.joint_names.index(joint)]
    return PoseEdit(f, joint, tuple(p + np.asarray(push) * ik.figure_height(m)), chain)


def _below(m, joints):
    """Joints with one of ``joints`` among their ancestors: the ones those joints' turns move."""
    out: set[int] = set()
    for j in range(1, m.n_joints):
        if m.parents[j] in out or m.parents[j] in joints:
            out.add(j)
    return out


@pytest.mark.parametrize("interp", ["linear", "hermite", "hermite-fit"])
def test_an_edit_reaches_its_target_and_spreads_between_the_neighbouring_keys(capture, interp):
    m, keys, hand, _ = capture
    h = ik.figure_height(m)
    editor = PoseEditor(m, keys, interp)
    edit = _edit(m, keys, hand, [0.05, 0.08, 0.04])
    report = editor.apply(edit)
    out = editor.motion()
    f = edit.frame
    e = m.joint_names.index(hand)
    p0, p1 = m.joint_positions(end_sites=True), out.joint_positions(end_sites=True)

    # The effector is on its target at the key.
    assert np.linalg.norm(p1[f, e] - edit.target) < 1e-4 * h
    assert report.miss_share < 1e-4 and report.method == "two-bone"
    # Same skeleton; bone lengths unchanged at every frame (End Sites too).
    assert out.joint_names == m.joint_names and out.channels == m.channels
    assert np.array_equal(out.offsets, m.offsets) and np.array_equal(out.end_offsets, m.end_offsets)
    assert out.frame_time == m.frame_time
    ends = np.r_[np.arange(1, m.n_joints), m.n_joints + np.arange(len(m.end_parents))]
    parent = np.r_[m.parents[1:], m.end_parents]
    bones0 = np.linalg.norm(p0[:, ends] - p0[:, parent], axis=2)
    bones1 = np.linalg.norm(p1[:, ends] - p1[:, parent], axis=2)
    np.testing.assert_allclose(bones1, bones0, rtol=0, atol=1e-9 * h)
    # Frames outside the neighbouring keys are the capture bit for bit, and so is every channel
    # of a joint the edit did not turn.
    a = int(np.flatnonzero(keys == f)[0])
    lo, hi = int(keys[a - 1]), int(keys[a + 1])
    assert (report.first, report.last) == (lo + 1, hi - 1)
    outside = np.r_[0 : lo + 1, hi : m.n_frames]
    assert np.array_equal(out.values[outside], m.values[outside])
    turned = ik.ancestors(m, e, 2)
    cols = [c for j in turned for c in ik.rotation_columns(m, j)[0]]
    others = np.setdiff1d(np.arange(m.n_channels), cols)
    assert np.array_equal(out.values[:, others], m.values[:, others])
    # Joints off the edited chain stay put at the key (bit for bit: their channels did not move).
    moved = _below(m, turned)
    still = [j for j in range(m.n_joints) if j not in moved]
    assert np.array_equal(p1[f, still], p0[f, still])
    # The change fades from the key to nothing at its neighbours.
    q0, q1 = m.local_rotations(), out.local_rotations()
    change = quat.distance(q0[:, turned], q1[:, turned]).max(axis=1)  # (F,)
    assert change[f] > 0 and change.max() < 1.02 * change[f]  # the most at the key, to the residual
    assert change[lo + 1] < 0.2 * change[f] and change[hi - 1] < 0.2 * change[f]
    half = (lo + f) // 2
    assert change[lo + 1] < change[half] < change[f]
    # Continuous: frame to frame the edited rotations turn as the capture's do, give or take the
    # edit spread over its frames, and their angles take no whole turns or jumps to the other Euler family.
    step0 = quat.distance(q0[1:, turned], q0[:-1, turned])
    step1 = quat.distance(q1[1:, turned], q1[:-1, turned])
    assert np.max(step1 - step0) < 4.0 * change[f] / min(f - lo, hi - f)  # the spread's slope
    jump = np.abs(np.diff(out.values, axis=0) - np.diff(m.values, axis=0))
    for j in turned:
        cols, _ = ik.rotation_columns(m, j)
        big = np.flatnonzero(jump[:, cols].max(axis=1) >= 90.0)
        # Only where the turn passes through gimbal lock (the middle angle within 3° of ±90°),
        # there the first and third angles alone may jump: the same turn written the other way.
        middle = np.abs(out.values[:, cols[1]] % 180.0 - 90.0)
        assert np.all(np.minimum(middle[big], middle[big + 1]) < 3.0), (m.joint_names[j], big)
        assert np.all(jump[big, cols[1]] < 10.0)
    assert jump.max() < 200.0


def test_the_empty_edit_and_undo_give_the_capture_back(capture):
    m, keys, hand, foot = capture
    editor = PoseEditor(m, keys, "hermite")
    assert np.array_equal(editor.motion().values, m.values)
    first = editor.apply(_edit(m, keys, hand, [0.0, 0.1, 0.0]))
    after_first = editor.motion().values
    second = _edit(m, keys, foot, [0.0, 0.08, 0.03], which=1)
    editor.apply(second)
    assert not np.array_equal(editor.motion().values, after_first)
    assert editor.undo() == second
    assert np.array_equal(editor.motion().values, after_first)
    assert editor.reports == [first]
    editor.reset()
    assert editor.undo() is None
    assert np.array_equal(editor.motion().values, m.values)


def test_edits_compose_each_on_the_pose_the_last_left(capture):
    m, keys, hand, foot = capture
    h = ik.figure_height(m)
    editor = PoseEditor(m, keys, "hermite")
    e1 = _edit(m, keys, hand, [0.05, 0.05, 0.0])
    e2 = _edit(m, keys, foot, [0.0, 0.1, 0.05], which=1)
    # A second edit of the same hand at the same key moves it on from where the first left it.
    e3 = PoseEdit(e1.frame, hand, tuple(np.add(e1.target, [0.0, 0.0, 0.03 * h])), 3)
    reports = editor.apply_all([e1, e2, e3])
    out = editor.motion().joint_positions()
    assert [r.edit for r in reports] == [e1, e2, e3]
    for ed in (e2, e3):
        assert np.linalg.norm(out[ed.frame, m.joint_names.index(ed.joint)] - ed.target) < 1e-4 * h
    assert reports[2].method == "damped least squares"


def test_an_edit_at_a_frame_that_is_not_a_key_names_the_keys(capture):
    m, keys, hand, _ = capture
    editor = PoseEditor(m, keys)
    with pytest.raises(ParameterError, match=f"a key frame: {keys[0]} {keys[1]}"):
        editor.apply(PoseEdit(int(keys[1]) + 1, hand, (0.0, 0.0, 0.0), 2))


def test_without_edits_the_key_curve_is_reconstruct_motion(motion_dir):
    """The curve the edit rebuilds is the reduced motion's: at the keys the two agree, and the
    edited capture's change at a frame is the change of that curve there."""
    m = read_bvh(motion_dir / "mocapbank_walk.bvh")
    keys = np.r_[np.arange(0, 450, 30), 454]
    for interp in ("linear", "hermite"):
        editor = PoseEditor(m, keys, interp)
        j = m.joint_names.index("LeftElbow")
        r = reconstruct_motion(m, keys, interp).local_rotations()[:, j]
        mine = editor._curve(j, editor._key_q[:, j], np.arange(m.n_frames))
        assert np.max(quat.distance(quat.normalize(mine), r)) < 1e-7


def test_an_edited_capture_round_trips_through_bvh(tmp_path, motion_dir):
    m = read_bvh(motion_dir / "pymo_walk.bvh")
    keys = np.r_[np.arange(0, 1063, 100), 1063]
    editor = PoseEditor(m, keys, "hermite")
    editor.apply(_edit(m, keys, "RightFoot", [0.0, 0.1, 0.02], which=3))
    out = editor.motion()
    write_bvh(tmp_path / "e.bvh", out)
    back = read_bvh(tmp_path / "e.bvh")
    assert back.joint_names == m.joint_names and back.channels == m.channels
    assert np.array_equal(back.offsets, m.offsets) and back.frame_time == m.frame_time
    assert np.array_equal(back.end_offsets, m.end_offsets) and np.array_equal(back.parents, m.parents)
    np.testing.assert_allclose(back.values, out.values, rtol=0, atol=5e-7)
    d = np.linalg.norm(back.joint_positions() - out.joint_positions(), axis=2)
    assert d.max() < 1e-6 * ik.figure_height(m)


def _bad(m, edits):
    with pytest.raises(FormatError) as err:
        parse_edits(edits, m, "EDITS.json")
    return str(err.value)


def test_bad_edits_are_one_line_naming_the_edit(motion_dir, tmp_path):
    m = read_bvh(motion_dir / "mocapbank_walk.bvh")
    ok = {"frame": 0, "joint": "LeftWrist", "target": [1.0, 2.0, 3.0], "chain": 2}
    assert parse_edits([ok], m) == [PoseEdit(0, "LeftWrist", (1.0, 2.0, 3.0), 2)]
    assert parse_edits({"edits": [ok]}, m) == parse_edits([ok], m)
    assert parse_edits([], m) == []
    cases = {
        "unknown joint": ({**ok, "joint": "LeftTentacle"}, "joint 'LeftTentacle' is not in the skeleton"),
        "NaN target": ({**ok, "target": [0, float("nan"), 0]}, "not finite"),
        "short target": ({**ok, "target": [0, 1]}, "is not [x, y, z]"),
        "string target": ({**ok, "target": "up"}, "is not [x, y, z]"),
        "long chain": ({**ok, "chain": 7}, "chain 7 is not a whole number 1..6"),
        "zero chain": ({**ok, "chain": 0}, "chain 0"),
        "float chain": ({**ok, "chain": 2.0}, "chain 2.0"),
        "bool frame": ({**ok, "frame": True}, "frame True"),
        "frame beyond": ({**ok, "frame": 455}, "frame 455 is not a frame number 0..454"),
        "missing": ({"frame": 0, "joint": "LeftWrist", "target": [0, 0, 0]}, "lacks chain"),
        "typo": ({**ok, "tagret": [0, 0, 0]}, "unknown fields tagret"),
    }
    for case, (edit, words) in cases.items():
        msg = _bad(m, [ok, edit])
        assert msg.startswith("EDITS.json: edit 2") and words in msg and "\n" not in msg, case
    assert "a list of edits" in _bad(m, {"frame": 0})
    assert "edit 1 is not an object" in _bad(m, [3])
    path = tmp_path / "edits.json"
    path.write_text("[{")
    with pytest.raises(FormatError, match="not valid JSON"):
        read_edits(path, m)
    path.write_text(json.dumps([ok]))
    assert read_edits(path, m) == [PoseEdit(0, "LeftWrist", (1.0, 2.0, 3.0), 2)]


def _hinged_arm(n=40):
    """A root, a ball shoulder, a hinge elbow (one Xrotation channel) and a hand joint without
    channels, swinging over ``n`` frames."""
    from hairtool.mocap.bvh import Motion

    t = np.linspace(0.0, 2.0 * np.pi, n)
    values = np.zeros((n, 10))
    values[:, 1] = 10.0 + 0.5 * np.sin(t)  # root height
    values[:, 3:6] = np.column_stack([20 * np.sin(t), 15 * np.cos(t), 5 * t])  # root ZXY
    values[:, 6:9] = np.column_stack([30 * np.sin(2 * t), 10 + 5 * t, -20 * np.cos(t)])  # shoulder ZXY
    values[:, 9] = 40 + 30 * np.sin(t)  # elbow hinge
    return Motion(
        ["root", "shoulder", "elbow", "hand"],
        np.array([-1, 0, 1, 2]),
        np.array([[0, 0, 0], [0, 5, 0], [0, 4, 0], [0, 3, 0]], dtype=float),
        [
            ["Xposition", "Yposition", "Zposition", "Zrotation", "Xrotation", "Yrotation"],
            ["Zrotation", "Xrotation", "Yrotation"],
            ["Xrotation"],
            [],
        ],
        values,
        1 / 30,
    )


@pytest.mark.parametrize("interp", ["linear", "hermite"])
def test_a_hinge_joint_is_solved_on_its_one_angle_and_the_ends_of_the_capture_edit_too(interp):
    m = _hinged_arm()
    h = ik.figure_height(m)
    keys = np.array([0, 10, 20, 30, 39])
    p = m.joint_positions()
    for f in (0, 20, 39):  # the first key, a middle one, the last
        editor = PoseEditor(m, keys, interp)
        # Where the hand is on another frame, relative to the shoulder: a pose the arm can take.
        g = (f + 7) % m.n_frames
        target = p[f, 1] + (p[g, 3] - p[g, 1]) * 0.98
        report = editor.apply(PoseEdit(f, "hand", tuple(target), 2))
        assert report.method == "damped least squares"  # no two-bone on a hinge
        out = editor.motion()
        assert np.linalg.norm(out.joint_positions()[f, 3] - target) < 1e-4 * h
        first, last = editor.span(f)
        a = int(np.searchsorted(keys, f))
        assert first == (0 if f == 0 else keys[a - 1] + 1)
        assert last == (m.n_frames - 1 if f == 39 else keys[a + 1] - 1)
        outside = np.setdiff1d(np.arange(m.n_frames), np.arange(first, last + 1))
        assert np.array_equal(out.values[outside], m.values[outside])
        assert np.array_equal(out.values[:, :6], m.values[:, :6])  # the root's channels
        moved = np.abs(out.values[:, 9] - m.values[:, 9])
        assert moved[f] == moved.max() > 0  # the hinge angle moved most at the key
        bones = np.linalg.norm(np.diff(out.joint_positions()[:, 1:], axis=1), axis=2)
        np.testing.assert_allclose(bones, [[4.0, 3.0]] * m.n_frames, atol=1e-9)


def test_targets_beyond_any_capture_and_hostile_json_are_refused(motion_dir, tmp_path):
    m = read_bvh(motion_dir / "mocapbank_walk.bvh")
    edit = {"frame": 0, "joint": "LeftWrist", "target": [0.0, 1e300, 0.0], "chain": 2}
    with pytest.raises(FormatError, match="beyond"):
        parse_edits([edit], m, "EDITS.json")
    path = tmp_path / "e.json"
    path.write_text('[{"frame": 0, "joint": "LeftWrist", "target": [1%s, 0, 0], "chain": 2}]' % ("0" * 400))
    with pytest.raises(FormatError, match="a number of 401 digits"):  # the limits jobs files get
        read_edits(path, m)
    path.write_text("[" * 100_000 + "]" * 100_000)
    with pytest.raises(FormatError, match="nested 100000 levels deep"):
        read_edits(path, m)
    path.write_bytes(b"\xff\xfe[")
    with pytest.raises(FormatError, match="not UTF-8 text"):
        read_edits(path, m)
    with pytest.raises(FormatError, match="not a regular file"):
        read_edits(tmp_path, m)
