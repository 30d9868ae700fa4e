"""``hairtool keys IN.bvh --keys K [--edit EDITS.json] --export OUT.bvh``: the edited capture or the
key curve written as BVH, and every bad EDITS.json refused in one line with exit 2."""

from __future__ import annotations

import json

import numpy as np
import pytest

from hairtool.cli import main
from hairtool.mocap import ik
from hairtool.mocap.bvh import read_bvh
from hairtool.mocap.costs import reconstruct_motion


def _keys(capsys, bvh, *argv):
    assert main(["keys", str(bvh), *map(str, argv), "--json"]) == 0
    return json.loads(capsys.readouterr().out)


def _write(path, edits):
    path.write_text(json.dumps(edits))
    return path


@pytest.mark.parametrize("name", ["pymo_walk.bvh", "mocapbank_walk.bvh", "freebvh.bvh"])
def test_the_empty_edit_gives_the_capture_back(motion_dir, tmp_path, capsys, name):
    src = motion_dir / name
    out = tmp_path / "same.bvh"
    _keys(capsys, src, "--keys", 8, "--edit", _write(tmp_path / "none.json", []), "--export", out)
    a, b = read_bvh(src), read_bvh(out)
    assert b.joint_names == a.joint_names and b.channels == a.channels
    assert np.array_equal(b.parents, a.parents) and np.array_equal(b.offsets, a.offsets)
    assert np.array_equal(b.end_parents, a.end_parents) and np.array_equal(b.end_offsets, a.end_offsets)
    assert b.frame_time == a.frame_time
    # The captures print 2 to 4 decimals, the writer 6: the very same numbers come back.
    assert np.array_equal(b.values, a.values)


def test_an_edit_moves_the_joint_at_its_key_and_nothing_outside_the_neighbouring_keys(
    motion_dir, tmp_path, capsys
):
    src = motion_dir / "mocapbank_walk.bvh"
    m = read_bvh(src)
    h = ik.figure_height(m)
    keys = _keys(capsys, src, "--keys", 12, "--interp", "hermite")["keys"]
    f, g = keys[3], keys[6]
    wrist, ankle = m.joint_names.index("LeftWrist"), m.joint_names.index("RightAnkle")
    p = m.joint_positions()
    t1 = p[f, wrist] + [0.0, 0.15 * h, 0.0]
    t2 = p[g, ankle] + [0.0, 0.08 * h, 0.04 * h]
    edits = [
        {"frame": f, "joint": "LeftWrist", "target": t1.tolist(), "chain": 2},
        {"frame": g, "joint": "RightAnkle", "target": t2.tolist(), "chain": 3},
    ]
    out = tmp_path / "edited.bvh"
    path = _write(tmp_path / "e.json", edits)
    got = _keys(capsys, src, "--keys", 12, "--interp", "hermite", "--edit", path, "--export", out)
    assert [r["edit"]["frame"] for r in got["edits"]] == [f, g]
    assert got["edits"][0]["method"] == "two-bone"
    assert got["edits"][0]["turned"] == ["LeftElbow", "LeftShoulder"]
    assert all(r["miss_share"] < 1e-4 for r in got["edits"])
    e = read_bvh(out)
    q = e.joint_positions()
    # Written to 6 decimals, the effectors are still on their targets.
    assert np.linalg.norm(q[f, wrist] - t1) < 1e-4 * h and np.linalg.norm(q[g, ankle] - t2) < 1e-4 * h
    assert np.array_equal(e.offsets, m.offsets) and e.channels == m.channels and e.frame_time == m.frame_time
    assert np.array_equal(e.end_offsets, m.end_offsets) and np.array_equal(e.parents, m.parents)
    assert np.array_equal(e.end_parents, m.end_parents) and e.joint_names == m.joint_names
    changed = np.flatnonzero(np.any(np.abs(e.values - m.values) > 1e-9, axis=1))
    assert changed.min() > keys[2] and changed.max() < keys[7]
    assert not np.any(np.abs(e.values[keys[4] + 1 : keys[5]] - m.values[keys[4] + 1 : keys[5]]) > 1e-9)


def test_without_edit_the_bvh_export_is_the_key_curve(motion_dir, tmp_path, capsys):
    src = motion_dir / "freebvh.bvh"
    out = tmp_path / "reduced.bvh"
    keys = _keys(capsys, src, "--keys", 9, "--interp", "hermite", "--export", out)["keys"]
    r = reconstruct_motion(read_bvh(src), keys, "hermite")
    back = read_bvh(out)
    np.testing.assert_allclose(back.values, r.values, rtol=0, atol=5.1e-7)  # 6 decimals printed
    assert back.frame_time == r.frame_time and np.array_equal(back.offsets, r.offsets)


def _refused(capsys, tmp_path, argv, words):
    out = tmp_path / "out.bvh"
    assert main(["keys", *map(str, argv)]) == 2
    err = capsys.readouterr().err.strip()
    assert words in err and "\n" not in err and "Traceback" not in err, err
    assert not out.exists() and not list(tmp_path.glob(".*tmp*"))


def test_bad_edits_exit_2_with_one_line(motion_dir, tmp_path, capsys):
    src = motion_dir / "freebvh.bvh"
    m = read_bvh(src)
    keys = _keys(capsys, src, "--keys", 6)["keys"]
    ok = {"frame": keys[2], "joint": "mixamorig:LeftHand", "target": [0.0, 100.0, 0.0], "chain": 2}
    out = tmp_path / "out.bvh"
    base = [src, "--keys", 6, "--export", out, "--edit"]
    path = tmp_path / "edits.json"
    listed = " ".join(map(str, keys))
    depth = int(m.depths()[m.joint_names.index("mixamorig:LeftHand")])
    cases = [
        ({**ok, "frame": keys[2] + 1}, f"frame {keys[2] + 1} is not a key; the keys are {listed}"),
        ({**ok, "joint": "mixamorig:Tail"}, "joint 'mixamorig:Tail' is not in the skeleton"),
        ({**ok, "chain": depth + 1}, f"chain {depth + 1} is not a whole number 1..{depth}"),
        ({**ok, "chain": "2"}, "chain '2'"),
        ({**ok, "target": [0, 1, "2"]}, "is not [x, y, z]"),
        ({**ok, "frame": 2.5}, "frame 2.5"),
    ]
    for edit, words in cases:
        _write(path, [edit])
        _refused(capsys, tmp_path, [*base, path], f"{path}: edit 1")
        _refused(capsys, tmp_path, [*base, path], words)
    path.write_text(json.dumps([{**ok, "target": [0, float("nan"), 0]}]))  # NaN, as Python writes it
    _refused(capsys, tmp_path, [*base, path], "is not finite")
    path.write_text("{not json")
    _refused(capsys, tmp_path, [*base, path], "not valid JSON")
    _refused(capsys, tmp_path, [*base, tmp_path / "missing.json"], "cannot read")
    _write(path, [ok])
    _refused(capsys, tmp_path, [src, "--keys", 6, "--edit", path], "an --export OUT.bvh")
    as_json = [src, "--keys", 6, "--edit", path, "--export", tmp_path / "k.json"]
    _refused(capsys, tmp_path, as_json, "--export OUT.bvh")
    _refused(capsys, tmp_path, [*base, path, "--bake"], "bake")
    per = [src, "--penalty", 0.01, "--per-channel"]
    channels = "--bvh-features channels with --per-channel"
    _refused(capsys, tmp_path, [*per, "--edit", path, "--export", out], channels)
    _refused(capsys, tmp_path, [*per, "--export", out], channels)
    _refused(capsys, tmp_path, [*per, "--bvh-features", "channels", "--edit", path], "an --export OUT.bvh")
    x = tmp_path / "x.npz"
    np.savez(x, X=np.cumsum(np.ones((20, 2)), axis=0))
    _refused(capsys, tmp_path, [x, "--keys", 4, "--edit", path, "--export", out], "a .bvh input")
    _refused(capsys, tmp_path, [x, "--keys", 4, "--export", out], "a .bvh input to write a .bvh")


def test_per_channel_keys_of_the_bvh_channels_edit_the_same_way(motion_dir, tmp_path, capsys):
    src = motion_dir / "freebvh.bvh"
    m = read_bvh(src)
    h = ik.figure_height(m)
    per = [src, "--per-channel", "--penalty", 0.01, "--bvh-features", "channels", "--interp", "hermite"]
    out = tmp_path / "same.bvh"
    got = _keys(capsys, *per, "--edit", _write(tmp_path / "none.json", []), "--export", out)
    assert len(got["channels"]) == m.n_channels and got["edits"] == []
    assert np.array_equal(read_bvh(out).values, m.values)
    f = 30
    assert f in got["union"]
    e = m.joint_names.index("mixamorig:RightHand")
    target = m.joint_positions()[f, e] + [0.0, 0.06 * h, 0.03 * h]
    edit = {"frame": f, "joint": "mixamorig:RightHand", "target": target.tolist(), "chain": 2}
    got = _keys(capsys, *per, "--edit", _write(tmp_path / "e.json", [edit]), "--export", out)
    assert got["edits"][0]["miss_share"] < 1e-4
    edited = read_bvh(out)
    assert np.linalg.norm(edited.joint_positions()[f, e] - target) < 1e-4 * h
    assert np.array_equal(edited.offsets, m.offsets)
    # Without --edit: every channel its own key curve.
    reduced = tmp_path / "reduced.bvh"
    _keys(capsys, *per, "--export", reduced)
    from hairtool.mocap.channel_edit import channel_key_curve

    want = channel_key_curve(m, got["channels"], "hermite").values
    np.testing.assert_allclose(read_bvh(reduced).values, want, rtol=0, atol=5.1e-7)


def _bvh_bytes(path, motion):
    from hairtool.mocap.bvh import write_bvh

    write_bvh(path, motion)
    return path.read_bytes()


def _studio_kinds(m, keys):
    """One edit of every kind a project keeps of the pose keys: an IK pose, a key moved in time,
    a key's value at its new frame, a handle."""
    h = ik.figure_height(m)
    hand = m.joint_names.index("mixamorig:LeftHand")
    f = keys[3]
    target = (m.joint_positions()[f, hand] + [0.0, 0.1 * h, 0.02 * h]).tolist()
    gaps = np.diff(keys)
    k = next(i for i in range(1, len(keys) - 1) if i != 3 and gaps[i - 1] > 2 and gaps[i] > 2)
    to = keys[k] + 1
    arm = "mixamorig:LeftForeArm"
    c = m.channels[m.joint_names.index(arm)].index("Yrotation")
    col = int(m._starts[m.joint_names.index(arm)]) + c
    return [
        {"frame": f, "joint": "mixamorig:LeftHand", "target": target, "chain": 2},
        {"frame": keys[k], "to": to},
        {"frame": to, "joint": arm, "channel": "Yrotation", "value": float(m.values[to, col]) + 12.0},
        {"frame": keys[2], "joint": arm, "channel": "Zrotation", "slope": 1.5},
    ]


def test_every_edit_kind_of_a_project_replays_through_the_cli_as_in_the_library(motion_dir, tmp_path, capsys):
    """Issue 30 (--edit reads what the studio keeps): a list of pose-key edits of every kind, and
    a project's capture object with per-channel key edits over them, give the library's motion
    bit for bit (the same BVH bytes)."""
    from hairtool.keys.channels import per_channel_keys
    from hairtool.mocap.channel_edit import ChannelEditor, channel_features
    from hairtool.mocap.edit_file import parse_capture_edits
    from hairtool.mocap.pose_edit import PoseEditor

    src = motion_dir / "freebvh.bvh"
    m = read_bvh(src)
    argv = [src, "--keys", 10, "--interp", "hermite"]
    keys = _keys(capsys, *argv)["keys"]
    edits = _studio_kinds(m, keys)
    out = tmp_path / "cli.bvh"
    got = _keys(capsys, *argv, "--edit", _write(tmp_path / "list.json", edits), "--export", out)
    assert [r["method"] for r in got["edits"]][1:] == ["retime", "channel", "handle"]
    lib = PoseEditor(m, keys, "hermite")
    lib.apply_all(parse_capture_edits(edits, m).edits)
    assert out.read_bytes() == _bvh_bytes(tmp_path / "lib.bvh", lib.motion())
    assert not np.array_equal(read_bvh(out).values, m.values)
    # the project's capture object: the same pose edits, then per-channel key edits over them
    price = 0.02
    ck = per_channel_keys(channel_features(m), price, interp="hermite", relative=True).keys
    arm = "mixamorig:RightForeArm"
    col = int(m._starts[m.joint_names.index(arm)]) + m.channels[m.joint_names.index(arm)].index("Xrotation")
    own = ck[col]
    k = int(np.argmax(np.minimum(np.diff(own)[:-1], np.diff(own)[1:]))) + 1
    f0 = int(own[k])
    channel_edits = [
        {"frame": f0, "joint": arm, "channel": "Xrotation", "to": f0 + 1},
        {"frame": f0 + 1, "joint": arm, "channel": "Xrotation", "value": float(m.values[f0, col]) - 9.0},
        {"frame": int(own[k - 1]), "joint": arm, "channel": "Xrotation", "slope": -0.8},
    ]
    project = {
        "bvh": "(not read)",
        "source": str(src),
        "chain": 2,
        "edits": edits,
        "channel_edits": channel_edits,
    }
    path = _write(tmp_path / "project.json", project)
    got = _keys(capsys, *argv, "--edit", path, "--export", out, "--channel-price", price)
    assert len(got["edits"]) == 7
    layer = ChannelEditor(lib.motion(), ck, "hermite")
    layer.apply_all(parse_capture_edits(project, m).channel_edits)
    assert out.read_bytes() == _bvh_bytes(tmp_path / "lib2.bvh", layer.motion())
    assert not np.array_equal(layer.motion().values, lib.motion().values)
    # the printed lines say what each edit did
    assert (
        main(
            [
                "keys",
                *map(str, argv),
                "--edit",
                str(path),
                "--export",
                str(out),
                "--channel-price",
                str(price),
            ]
        )
        == 0
    )
    text = capsys.readouterr().out
    assert "key move at frame" in text and "Xrotation key value" in text and "handle" in text


def test_edits_of_no_kind_or_in_the_wrong_list_are_refused_naming_the_entry(motion_dir, tmp_path, capsys):
    src = motion_dir / "freebvh.bvh"
    m = read_bvh(src)
    keys = _keys(capsys, src, "--keys", 10, "--interp", "hermite")["keys"]
    edits = _studio_kinds(m, keys)
    out = tmp_path / "out.bvh"
    base = [src, "--keys", 10, "--interp", "hermite", "--export", out, "--edit"]
    path = tmp_path / "edits.json"
    move = {"frame": keys[2], "joint": "mixamorig:LeftForeArm", "channel": "Yrotation", "to": keys[2] + 1}
    cases = [
        ([edits[0], {"frame": keys[2], "scale": 2}], "edit 2 {'frame': "),
        ([edits[0], {"frame": keys[2], "scale": 2}], "is no edit the studio keeps"),
        ([edits[1], "retime"], "edit 2 retime is no edit"),
        ([edits[0], move], "edit 2: edit={'frame'"),  # a channel's own key: not a pose key
        ([edits[0], move], "an edit of the pose keys"),
        ({"edits": edits, "channel_edits": [edits[1]]}, "channel edit 1 is a pose key's move in time"),
        ({"edits": edits, "keys": [0, 1]}, "unknown fields keys"),
        ({"edits": {"frame": 1}}, '"edits" is not a list'),
        ({"edits": [], "channel_edits": [{**move, "channel": "Qrotation"}]}, "channel edit 1: 'Qrotation'"),
        (
            [edits[1], {**edits[1], "frame": edits[1]["frame"]}],
            f"edit 2: frame {edits[1]['frame']} is not a key",
        ),
    ]
    for data, words in cases:
        _write(path, data)
        _refused(capsys, tmp_path, [*base, path], words)
    # the moved key is named by its new frame afterwards: a value there replays
    _write(path, edits[1:3])
    assert main(["keys", *map(str, [*base, path])]) == 0
    capsys.readouterr()
    out.unlink()
    # per-channel keys take a list of their own edits or a project's channel_edits alone
    per = [src, "--per-channel", "--penalty", 0.01, "--bvh-features", "channels", "--export", out, "--edit"]
    _write(path, {"edits": edits, "channel_edits": []})
    _refused(capsys, tmp_path, [*per, path], "replay them without --per-channel")
    _write(path, [edits[1]])
    _refused(capsys, tmp_path, [*per, path], "an edit of per-channel keys")


def test_an_ik_pose_on_per_channel_keys_replays_at_a_pose_key_no_channel_keys(motion_dir, tmp_path, capsys):
    """A joint the studio dragged with per-channel keys on is a pose in the project's
    ``channel_edits``: replayed on each channel's own keys over the pose-edited capture, at a pose
    key even where no channel has a key (each channel it turns gets one there), the effector on
    its target; a frame that is neither is refused naming the frames it may be."""
    from hairtool.errors import ParameterError
    from hairtool.mocap.channel_edit import ChannelEditor
    from hairtool.mocap.edit_file import channel_keys
    from hairtool.mocap.pose_edit import PoseEdit, PoseEditor

    src = motion_dir / "mocapbank_walk.bvh"
    m = read_bvh(src)
    h = ik.figure_height(m)
    argv = [src, "--keys", 12, "--interp", "hermite"]
    keys = np.asarray(_keys(capsys, *argv)["keys"])
    price = 0.01
    ck = channel_keys(m, "hermite", price)
    union = np.unique(np.concatenate(ck))
    f = int(next(k for k in keys[1:-1] if k not in union))  # a pose key no channel keys
    hand = m.joint_names.index("LeftWrist")
    target = m.joint_positions()[f, hand] + [0.03 * h, 0.08 * h, 0.0]
    pose = {"frame": f, "joint": "LeftWrist", "target": target.tolist(), "chain": 2}
    project = {"edits": [], "channel_edits": [pose]}
    out = tmp_path / "cli.bvh"
    path = _write(tmp_path / "project.json", project)
    got = _keys(capsys, *argv, "--edit", path, "--export", out, "--channel-price", price)
    assert got["edits"][0]["miss_share"] < 1e-4
    edited = read_bvh(out)
    assert np.linalg.norm(edited.joint_positions()[f, hand] - target) < 1e-4 * h
    assert np.array_equal(edited.offsets, m.offsets)
    # the library's layer, byte for byte; the turned channels change only between their own keys
    edit = PoseEdit(f, "LeftWrist", tuple(target), 2)
    layer = ChannelEditor(PoseEditor(m, keys, "hermite").motion(), ck, "hermite", pose_keys=keys)
    layer.apply(edit)
    assert out.read_bytes() == _bvh_bytes(tmp_path / "lib.bvh", layer.motion())
    changed = np.flatnonzero(np.any(layer.motion().values != m.values, axis=0))
    turned = {c for j in ik.ancestors(m, hand, 2) for c in ik.rotation_columns(m, j)[0]}
    assert changed.size and set(changed.tolist()) <= turned
    for c in changed:
        own = ck[c]
        a = int(np.searchsorted(own, f))
        rows = np.flatnonzero(layer.motion().values[:, c] != m.values[:, c])
        assert own[a - 1] < rows.min() and rows.max() < own[a]  # f was no key of c: one added there
        assert f in layer.keys(c)
    # without the pose keys the layer takes only its channels' keys
    with pytest.raises(ParameterError, match="a key of some channel: "):
        ChannelEditor(m, ck, "hermite").apply(edit)
    # a frame that is neither a pose key nor any channel's key
    off = int(next(g for g in range(1, m.n_frames - 1) if g not in union and g not in keys))
    _write(path, {"edits": [], "channel_edits": [{**pose, "frame": off}]})
    words = f"channel edit 1: frame {off} is not a key of any channel or a pose key"
    _refused(capsys, tmp_path, [*argv, "--edit", path, "--export", out, "--channel-price", price], words)
