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
