"""BVH reading: the real captures, hand-worked forward kinematics, malformed files, round trips."""

from __future__ import annotations

import numpy as np
import pytest

from hairtool.errors import FormatError
from hairtool.mocap.bvh import bvh_from_bytes, bvh_text, read_bvh, write_bvh

from .conftest import CHAIN

REAL = [
    ("mocapbank_walk.bvh", 455, 30, 19, 60, 5),
    ("freebvh.bvh", 69, 30, 55, 168, 15),
    ("pymo_walk.bvh", 1064, 120, 23, 72, 7),
]


@pytest.mark.parametrize(("name", "frames", "fps", "joints", "channels", "ends"), REAL)
def test_real_captures_load_with_their_published_counts(
    motion_dir, name, frames, fps, joints, channels, ends
):
    m = read_bvh(motion_dir / name)
    assert (m.n_frames, m.n_joints, m.n_channels) == (frames, joints, channels)
    assert m.fps == fps
    assert len(m.end_parents) == ends
    assert m.parents[0] == -1 and np.all(m.parents[1:] < np.arange(1, joints))
    assert m.local_rotations().shape == (frames, joints, 4)
    assert m.joint_positions().shape == (frames, joints, 3)
    assert m.joint_positions(end_sites=True).shape == (frames, joints + ends, 3)
    np.testing.assert_allclose(np.linalg.norm(m.local_rotations(), axis=-1), 1.0, atol=1e-12)
    # Bones keep their lengths in every frame: FK is rigid.
    p = m.joint_positions()
    child = np.arange(1, joints)
    bone = np.linalg.norm(p[:, child] - p[:, m.parents[child]], axis=-1)
    np.testing.assert_allclose(
        bone, np.broadcast_to(np.linalg.norm(m.offsets[child], axis=1), bone.shape), atol=1e-6
    )


def test_two_joint_chain_by_hand(chain_bvh):
    m = read_bvh(chain_bvh)
    assert m.joint_names == ["hips", "knee"]
    assert m.channels[0][3:] == ["Zrotation", "Xrotation", "Yrotation"]
    np.testing.assert_array_equal(m.depths(), [0, 1])
    p = m.joint_positions(end_sites=True)
    # Frame 0: rest. hips at origin, knee at (0,2,0), end at (0,3,0).
    np.testing.assert_allclose(p[0], [[0, 0, 0], [0, 2, 0], [0, 3, 0]], atol=1e-12)
    # Frame 1: the position channels replace the offset; 90° about z turns +y into −x.
    np.testing.assert_allclose(p[1], [[1, 2, 3], [-1, 2, 3], [-2, 2, 3]], atol=1e-12)
    # Frame 2: the knee adds −90° about z: the end site points back along +y from the knee.
    np.testing.assert_allclose(p[2], [[0, 0, 0], [-2, 0, 0], [-2, 1, 0]], atol=1e-12)
    np.testing.assert_allclose(m.root_translation()[1], [1, 2, 3])


def test_channel_order_is_applied_intrinsically(tmp_path):
    # One joint rotated Z 90 then X 90 (R = Rz·Rx): its child offset (0,1,0) → Rx: (0,0,1) → Rz: (0,0,1).
    # The other order (R = Rx·Rz): (0,1,0) → Rz: (−1,0,0) → Rx: (−1,0,0).
    def make(order):
        return (
            "HIERARCHY\nROOT a\n{\n OFFSET 0 0 0\n CHANNELS 2 " + order + "\n"
            " End Site\n {\n  OFFSET 0 1 0\n }\n}\nMOTION\nFrames: 1\nFrame Time: 0.1\n90 90\n"
        )

    (tmp_path / "zx.bvh").write_text(make("Zrotation Xrotation"))
    (tmp_path / "xz.bvh").write_text(make("Xrotation Zrotation"))
    zx = read_bvh(tmp_path / "zx.bvh").joint_positions(end_sites=True)[0, 1]
    xz = read_bvh(tmp_path / "xz.bvh").joint_positions(end_sites=True)[0, 1]
    np.testing.assert_allclose(zx, [0, 0, 1], atol=1e-12)
    np.testing.assert_allclose(xz, [-1, 0, 0], atol=1e-12)


@pytest.mark.parametrize(
    ("edit", "reason"),
    [
        (lambda t: t.replace("0 0 0 90 0 0 -90 0 0\n", ""), "truncated"),
        (lambda t: t.replace("1 2 3 90 0 0 0 0 0", "1 2 3 90 0 0 0 0"), "has 8 values"),
        (lambda t: t.replace("1 2 3 90 0 0 0 0 0", "1 2 3 90 0 0 0 0 x"), "not a number"),
        (lambda t: t.replace("1 2 3 90 0 0 0 0 0", "1 2 3 90 nan 0 0 0 0"), "non-finite"),
        (lambda t: t.replace("Frames: 3", "Frames: 99999999999"), "too large"),
        (lambda t: t.replace("Frames: 3", "Frames: -1"), "positive whole"),
        (lambda t: t.replace("Frame Time: 0.04", "Frame Time: 0"), "Frame Time"),
        (lambda t: t.replace("CHANNELS 3 Zrotation", "CHANNELS 3 Wrotation"), "unknown channel"),
        (lambda t: t.replace("CHANNELS 3", "CHANNELS 9"), "channel count"),
        (lambda t: t.replace("OFFSET 0 2 0", "OFFSET 0 two 0"), "not a number"),
        (lambda t: t.split("MOTION")[0], "no MOTION"),
        (lambda t: t.replace("HIERARCHY", "HELLO"), "not a BVH"),
        (lambda t: t[: t.index("End Site")] + "MOTION\n", "file ends"),
        (lambda t: t.replace("Frames: 3\n", ""), "Frames:"),
    ],
)
def test_malformed_files_raise_format_error_naming_the_file(tmp_path, edit, reason):
    p = tmp_path / "bad.bvh"
    p.write_text(edit(CHAIN))
    with pytest.raises(FormatError, match=reason) as e:
        read_bvh(p)
    assert e.value.path == str(p)


def test_missing_file_and_binary_garbage(tmp_path):
    with pytest.raises(FormatError, match="cannot read"):
        read_bvh(tmp_path / "nope.bvh")
    p = tmp_path / "noise.bvh"
    p.write_bytes(np.random.default_rng(0).bytes(300))
    with pytest.raises(FormatError):
        read_bvh(p)


def test_crlf_and_tabs_are_read(tmp_path, chain_bvh):
    p = tmp_path / "crlf.bvh"
    p.write_bytes(CHAIN.replace("\n", "\r\n").replace("  ", "\t").encode())
    np.testing.assert_array_equal(read_bvh(p).values, read_bvh(chain_bvh).values)


@pytest.mark.parametrize("name", ["mocapbank_walk.bvh", "freebvh.bvh"])
def test_write_read_round_trip(tmp_path, motion_dir, name):
    m = read_bvh(motion_dir / name)
    out = tmp_path / "copy.bvh"
    write_bvh(out, m)
    back = read_bvh(out)
    assert back.joint_names == m.joint_names and back.channels == m.channels
    np.testing.assert_array_equal(back.parents, m.parents)
    np.testing.assert_allclose(back.values, m.values, atol=1e-6)
    np.testing.assert_allclose(back.offsets, m.offsets, atol=1e-6)
    np.testing.assert_allclose(back.end_offsets, m.end_offsets, atol=1e-6)
    np.testing.assert_array_equal(back.end_parents, m.end_parents)
    assert back.frame_time == pytest.approx(m.frame_time, rel=1e-6)


@pytest.mark.parametrize("name", ["mocapbank_walk.bvh", "freebvh.bvh"])
def test_the_text_in_memory_is_the_files_and_its_bytes_read_as_the_file(tmp_path, motion_dir, name):
    """A project keeps its capture as text: bvh_text is write_bvh's bytes, bvh_from_bytes is
    read_bvh's motion, and a refusal names the place given (never a temporary file)."""
    m = read_bvh(motion_dir / name)
    out = tmp_path / "copy.bvh"
    write_bvh(out, m)
    assert bvh_text(m).encode("utf-8") == out.read_bytes()
    back, again = read_bvh(out), bvh_from_bytes(out.read_bytes(), "kept")
    assert again.joint_names == back.joint_names and again.channels == back.channels
    for field in ("parents", "offsets", "values", "end_parents", "end_offsets"):
        np.testing.assert_array_equal(getattr(again, field), getattr(back, field))
    assert again.frame_time == back.frame_time
    with pytest.raises(FormatError, match="no MOTION") as e:
        bvh_from_bytes(out.read_bytes().split(b"MOTION")[0], "a project's capture")
    assert e.value.path == "a project's capture"


def test_fps_snaps_only_printed_whole_rates(tmp_path):
    ntsc = CHAIN.replace("Frame Time: 0.04", "Frame Time: 0.0417083")
    (tmp_path / "ntsc.bvh").write_text(ntsc)
    assert read_bvh(tmp_path / "ntsc.bvh").fps == pytest.approx(23.976, abs=1e-3)
    (tmp_path / "thirty.bvh").write_text(CHAIN.replace("Frame Time: 0.04", "Frame Time: 0.033333"))
    assert read_bvh(tmp_path / "thirty.bvh").fps == 30.0


def test_motion_checks_its_skeleton():
    from hairtool.errors import ParameterError
    from hairtool.mocap.bvh import Motion

    chans = [["Xrotation"], ["Xrotation"]]
    with pytest.raises(ParameterError, match="parents"):
        Motion(["a", "b"], [-1, 1], np.zeros((2, 3)), chans, np.zeros((1, 2)), 0.1)
    with pytest.raises(ParameterError, match="values"):
        Motion(["a", "b"], [-1, 0], np.zeros((2, 3)), chans, np.zeros((1, 3)), 0.1)
    with pytest.raises(ParameterError, match="frame_time"):
        Motion(["a", "b"], [-1, 0], np.zeros((2, 3)), chans, np.zeros((1, 2)), 0.0)


@pytest.mark.parametrize("frames", ["nan", "NaN", "1e400", "inf", "-inf", "0", "2.5", "0x10"])
def test_frames_field_that_is_no_count_is_one_format_error(tmp_path, frames):
    p = tmp_path / "frames.bvh"
    p.write_text(CHAIN.replace("Frames: 3", f"Frames: {frames}"))
    with pytest.raises(FormatError, match="Frames") as e:
        read_bvh(p)
    assert e.value.path == str(p)


def test_frames_field_with_more_frames_than_the_file_can_hold(tmp_path):
    """Checked against the file's size, not only against a fixed cap, before anything is allocated."""
    p = tmp_path / "claim.bvh"
    p.write_text(CHAIN.replace("Frames: 3", "Frames: 50000000"))  # 450 M values: under the cap
    with pytest.raises(FormatError, match="truncated: 'Frames:' says 50000000 frames"):
        read_bvh(p)
    p.write_text(CHAIN.replace("Frames: 3", "Frames: 3.0"))  # a whole number written as a float
    assert read_bvh(p).n_frames == 3


@pytest.mark.parametrize(
    ("edit", "reason"),
    [
        (lambda t: t.replace("Frame Time: 0.04", "Frame Time: 5e-324"), "Frame Time"),
        (lambda t: t.replace("Frame Time: 0.04", "Frame Time: nan"), "Frame Time"),
        (lambda t: t.replace("OFFSET 0 2 0", "OFFSET 0 1e300 0"), "beyond"),
        (lambda t: t.replace("1 2 3 90 0 0 0 0 0", "1 2e39 3 90 0 0 0 0 0"), "beyond"),
    ],
)
def test_values_that_would_overflow_later_are_refused(tmp_path, edit, reason):
    p = tmp_path / "big.bvh"
    p.write_text(edit(CHAIN))
    with pytest.raises(FormatError, match=reason):
        read_bvh(p)


@pytest.mark.parametrize("depth", [1200, 5000])
def test_deep_chains_read_and_write_without_recursion(tmp_path, depth):
    """Joints nested deeper than Python's recursion limit (1,000): read, FK and written back."""
    lines = ["HIERARCHY"]
    for j in range(depth):
        lines += [f"{'ROOT' if j == 0 else 'JOINT'} j{j}", "{", "OFFSET 0 1 0", "CHANNELS 1 Zrotation"]
    lines += ["End Site", "{", "OFFSET 0 1 0", "}", *["}"] * depth, "MOTION", "Frames: 3", "Frame Time: 0.04"]
    lines += [" ".join(str((f * 7 + j) % 30) for j in range(depth)) for f in range(3)]
    p = tmp_path / "deep.bvh"
    p.write_text("\n".join(lines) + "\n")
    m = read_bvh(p)
    assert m.n_joints == depth and len(m.end_parents) == 1
    np.testing.assert_array_equal(m.parents, np.arange(-1, depth - 1))
    np.testing.assert_array_equal(m.depths(), np.arange(depth))
    assert np.all(np.isfinite(m.joint_positions(end_sites=True)))
    write_bvh(tmp_path / "copy.bvh", m)
    back = read_bvh(tmp_path / "copy.bvh")
    np.testing.assert_array_equal(back.parents, m.parents)
    np.testing.assert_array_equal(back.values, m.values)
    assert back.joint_names == m.joint_names


def test_writer_keeps_children_before_end_sites_in_file_order(tmp_path):
    """The iterative writer emits the same text as the hierarchy it read (a branching skeleton)."""
    text = (
        "HIERARCHY\nROOT a\n{\n\tOFFSET 0 0 0\n\tCHANNELS 1 Zrotation\n"
        "\tJOINT b\n\t{\n\t\tOFFSET 1 0 0\n\t\tEnd Site\n\t\t{\n\t\t\tOFFSET 1 0 0\n\t\t}\n\t}\n"
        "\tJOINT c\n\t{\n\t\tOFFSET 0 1 0\n\t\tJOINT d\n\t\t{\n\t\t\tOFFSET 0 1 0\n\t\t}\n\t}\n"
        "\tEnd Site\n\t{\n\t\tOFFSET 0 0 1\n\t}\n}\n"
        "MOTION\nFrames: 2\nFrame Time: 0.04\n0\n45\n"
    )
    (tmp_path / "tree.bvh").write_text(text)
    write_bvh(tmp_path / "out.bvh", read_bvh(tmp_path / "tree.bvh"))
    assert (tmp_path / "out.bvh").read_text() == text


def test_frames_times_joints_is_bounded_by_the_file(tmp_path):
    """Joints without channels take no bytes per frame, yet every frame poses them all."""
    lines = ["HIERARCHY", "ROOT r", "{", "OFFSET 0 0 0", "CHANNELS 1 Zrotation"]
    lines += [s for j in range(1, 3000) for s in (f"JOINT j{j}", "{", "OFFSET 0 1 0", "}")]
    head = "\n".join([*lines, "}", "MOTION"])
    p = tmp_path / "wide.bvh"
    p.write_text(head + "\nFrames: 600\nFrame Time: 0.04\n" + "0\n" * 600)  # 1.8 M poses, 70 KB
    with pytest.raises(FormatError, match="600 frames of 3000 joints"):
        read_bvh(p)
    p.write_text(head + "\nFrames: 300\nFrame Time: 0.04\n" + "0\n" * 300)  # 0.9 M: under the floor
    assert read_bvh(p).joint_positions().shape == (300, 3000, 3)
