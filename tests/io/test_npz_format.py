"""hairtool's .npz cache: lossless grooms and animations, every member validated before use."""

from __future__ import annotations

import io
import json
import os
import zipfile
from pathlib import Path

import numpy as np
import pytest

from hairtool.errors import FormatError
from hairtool.groom import Animation, Groom
from hairtool.io import npz, read, write


def test_groom_round_trip_keeps_everything(tmp_path, groom):
    p = tmp_path / "g.npz"
    write(p, groom)
    back = read(p)
    assert isinstance(back, Groom)
    assert back.points.tobytes() == groom.points.tobytes()
    np.testing.assert_array_equal(back.counts, groom.counts)
    for name in ("thickness", "transparency", "colors"):
        assert getattr(back, name).tobytes() == getattr(groom, name).tobytes()
    with np.load(p, allow_pickle=False) as z:
        assert int(z["format_version"]) == npz.FORMAT_VERSION and str(z["kind"]) == "groom"


def test_animation_round_trip_keeps_frames_and_fps(tmp_path, animation):
    p = tmp_path / "a.npz"
    write(p, animation)
    back = read(p)
    assert isinstance(back, Animation)
    assert back.frames.tobytes() == animation.frames.tobytes()
    assert back.fps == animation.fps
    assert back.colors.tobytes() == animation.colors.tobytes()
    assert back.transparency is None


def _write_members(path, **arrays):
    with open(path, "wb") as f:
        np.savez(f, **arrays)


def _prims(*prims: tuple[str, int, str]) -> str:
    fixed = {"basis": "linear", "wrap": "nonperiodic"}
    return json.dumps([{"path": p, "strands": n, **fixed, "purpose": u} for p, n, u in prims])


def _valid(**changes):
    base = {
        "format_version": np.array(1),
        "kind": np.array("groom"),
        "counts": np.array([2, 3]),
        "points": np.zeros((5, 3), np.float32),
    }
    base.update(changes)
    return {k: v for k, v in base.items() if v is not None}


@pytest.mark.parametrize(
    ("members", "reason"),
    [
        (_valid(format_version=np.array(99)), "version 99"),
        (_valid(format_version=None), "missing 'format_version'"),
        (_valid(kind=np.array("mesh")), "kind is 'mesh'"),
        (_valid(kind=np.array(3)), "'kind' must be"),
        (_valid(counts=np.array([2, 1])), "at least 2"),
        (_valid(counts=np.array([2.0, 3.0])), "'counts' must be"),
        (_valid(points=np.zeros((4, 3), np.float32)), "'points' has shape"),
        (_valid(points=np.full((5, 3), np.nan, np.float32)), "non-finite"),
        (_valid(thickness=np.ones(4, np.float32)), "'thickness' has shape"),
        (_valid(colors=np.ones((5, 3), complex)), "'colors' must be"),
        (_valid(extra=np.ones(3)), "unexpected member"),
        (_valid(kind=np.array("animation"), frames=np.zeros((2, 5, 3), np.float32)), "missing 'fps'"),
        (
            _valid(kind=np.array("animation"), frames=np.zeros((2, 5, 3), np.float32), fps=np.array(-1.0)),
            "fps is -1",
        ),
        (
            _valid(kind=np.array("animation"), frames=np.zeros((0, 5, 3), np.float32), fps=np.array(24.0)),
            "F>=1",
        ),
        (_valid(curves=np.array("[{")), "'curves' is not"),
        (_valid(curves=np.array('[{"path": "/A", "strands": 2}]')), "exactly"),
        (_valid(curves=np.array(_prims(("/A", 1, "guide")))), "hold 1 strands, not 2"),
        (_valid(curves=np.array(_prims(("/A", 1, "hat"), ("/B", 1, "default")))), "purpose"),
        (_valid(curves=np.array(3)), "'curves' must be"),
    ],
)
def test_invalid_members_raise_format_error(tmp_path, members, reason):
    p = tmp_path / "bad.npz"
    _write_members(p, **members)
    with pytest.raises(FormatError, match=reason):
        read(p)


def _npy_header(shape: tuple[int, ...]) -> bytes:
    """A hand-made .npy 1.0 header for a float32 array of ``shape`` (no data follows)."""
    text = f"{{'descr': '<f4', 'fortran_order': False, 'shape': {shape}, }}"
    pad = 64 - (10 + len(text) + 1) % 64
    body = (text + " " * pad + "\n").encode("latin-1")
    return b"\x93NUMPY\x01\x00" + len(body).to_bytes(2, "little") + body


def test_member_claiming_a_huge_shape_is_refused_before_allocating(tmp_path):
    p = tmp_path / "huge.npz"
    with zipfile.ZipFile(p, "w", compression=zipfile.ZIP_DEFLATED) as z:
        z.writestr("format_version.npy", _npy(np.array(1)))
        z.writestr("kind.npy", _npy(np.array("groom")))
        z.writestr("counts.npy", _npy(np.array([2_000_000_000])))
        z.writestr("points.npy", _npy_header((2_000_000_000, 3)) + b"\0" * 60)
    with pytest.raises(FormatError, match="does not match its stored size"):
        read(p)


def _npy(a) -> bytes:
    buf = io.BytesIO()
    np.lib.format.write_array(buf, a)
    return buf.getvalue()


def test_pickled_members_are_refused(tmp_path):
    p = tmp_path / "pickle.npz"
    _write_members(p, **_valid(kind=np.array([{"a": 1}], dtype=object)))
    with pytest.raises(FormatError, match="Python objects"):
        read(p)


@pytest.mark.parametrize("data", [b"", b"PK\x03\x04garbage", b"\x93NUMPY" + b"\0" * 20, b"not a zip at all"])
def test_non_npz_bytes_raise_format_error(tmp_path, data):
    p = tmp_path / "junk.npz"
    p.write_bytes(data)
    with pytest.raises(FormatError):
        read(p)


# -- issue 17's hostile classes ------------------------------------------------------------------
def _cache(tmp_path, **arrays):
    p = tmp_path / "hostile.npz"
    np.savez(p, format_version=np.array(1, dtype=np.int64), **arrays)
    return p


def test_counts_whose_sum_wraps_around_are_refused(tmp_path):
    counts = np.array([2**62, 2**62, 2**62, 2**62, 10], dtype=np.int64)  # int64 sum: 10
    p = _cache(tmp_path, kind=np.array("groom"), counts=counts, points=np.zeros((10, 3), np.float32))
    with pytest.raises(FormatError, match="strand 0 claims 4611686018427387904 points"):
        read(p)
    huge = np.array([2**64 - 1, 12], dtype=np.uint64)  # checked as uint64: as int64 it would be −1
    p = _cache(tmp_path, kind=np.array("groom"), counts=huge, points=np.zeros((11, 3), np.float32))
    with pytest.raises(FormatError, match="strand 0"):
        read(p)


@pytest.mark.parametrize("member", ["points", "frames", "thickness", "colors"])
def test_float64_beyond_float32_is_refused_after_the_cast(tmp_path, member):
    counts = np.array([2, 3], dtype=np.int64)
    arrays = {"counts": counts, "thickness": np.ones(5), "colors": np.ones((5, 3))}
    if member == "frames":
        arrays.update(kind=np.array("animation"), frames=np.zeros((2, 5, 3)), fps=np.array(24.0))
    else:
        arrays.update(kind=np.array("groom"), points=np.zeros((5, 3)))
    arrays[member].reshape(-1)[-1] = 1e39
    with pytest.raises(FormatError, match=f"{member} has a value at index \\d+ beyond float32"):
        read(_cache(tmp_path, **arrays))


def _features(tmp_path, name="x.npz", **arrays):
    p = tmp_path / name
    np.savez(p, **arrays)
    return p


def test_feature_array_reads_as_float64_frames(tmp_path):
    x = np.arange(12, dtype=np.float32).reshape(6, 2)
    p = _features(tmp_path, X=x, labels=np.arange(6))
    assert npz.holds_feature_array(p)
    out = npz.read_feature_array(p)
    assert out.dtype == np.float64 and out.flags.c_contiguous
    np.testing.assert_array_equal(out, x)
    column = npz.read_feature_array(_features(tmp_path, "one.npz", X=np.arange(4)))
    np.testing.assert_array_equal(column, [[0], [1], [2], [3]])
    write(tmp_path / "cache.npz", Groom(np.zeros((2, 3)), [2]))
    assert not npz.holds_feature_array(tmp_path / "cache.npz")
    (tmp_path / "plain.npz").write_bytes(b"not a zip")
    assert not npz.holds_feature_array(tmp_path / "plain.npz")


@pytest.mark.parametrize(
    ("arrays", "reason"),
    [
        ({"Y": np.zeros((3, 2))}, "no array 'X'"),
        ({"X": np.zeros((1, 2))}, "1 frame"),
        ({"X": np.zeros((3, 0))}, "no dimensions"),
        ({"X": np.zeros((3, 2, 2))}, "shape"),
        ({"X": np.array([["a", "b"], ["c", "d"]])}, "numbers"),
        ({"X": np.array([[0.0, 1.0], [np.nan, 2.0]])}, "non-finite value in frame 1"),
        ({"X": np.array([[0.0, 1.0], [1e200, 2.0]])}, "beyond"),
        ({"X": np.array([[0.0], [1.0]], dtype=np.longdouble) * np.longdouble(1e308) * 1e10}, "non-finite"),
    ],
)
def test_bad_feature_arrays_are_one_format_error(tmp_path, arrays, reason):
    with pytest.raises(FormatError, match=reason) as e:
        npz.read_feature_array(_features(tmp_path, **arrays))
    assert e.value.path.endswith("x.npz")


def test_feature_array_header_is_checked_before_numpy_allocates(tmp_path):
    from .hostile import npy_header

    p = tmp_path / "x.npz"
    with zipfile.ZipFile(p, "w") as zf:  # a header claiming 10^12 values over 80 bytes of data
        zf.writestr("X.npy", npy_header((10**6, 10**6)) + bytes(80))
    with pytest.raises(FormatError, match="does not match its stored size"):
        npz.read_feature_array(p)


def _npz_with_member(path, name: str, member: bytes):
    with zipfile.ZipFile(path, "w") as zf:
        zf.writestr(name, member)
    return path


def test_corrupt_npy_header_is_a_format_error_not_a_token_error(tmp_path):
    """numpy's fallback parse of a header with an unbalanced bracket let tokenize.TokenError escape."""
    header = b"{'descr': '<f8', 'fortran_order': False, 'shape': (3, \x0f}"
    member = b"\x93NUMPY\x01\x00" + len(header).to_bytes(2, "little") + header + bytes(24)
    p = _npz_with_member(tmp_path / "x.npz", "X.npy", member)
    with pytest.raises(FormatError, match=r"corrupt \.npy header"):
        npz.read_feature_array(p)
    p = _npz_with_member(tmp_path / "g.npz", "points.npy", member)
    with pytest.raises(FormatError, match=r"corrupt \.npy header"):
        read(p)


def test_a_lone_npy_is_refused_before_numpy_reads_it(tmp_path):
    from .hostile import npy_header

    p = tmp_path / "single.npz"  # a .npy under an .npz name, claiming 10^12 values
    p.write_bytes(npy_header((10**6, 10**6)) + bytes(80))
    with pytest.raises(FormatError, match=r"a single \.npy array"):
        read(p)
    with pytest.raises(FormatError, match=r"a single \.npy array"):
        npz.read_feature_array(p)
    assert not npz.holds_feature_array(p)


@pytest.mark.skipif(not Path("/proc/self/fd").is_dir(), reason="counts open files in /proc")
def test_a_corrupt_zip_leaves_no_file_open(tmp_path):
    """np.load given a path kept its file open when the zip was corrupt (held by the traceback)."""
    p = tmp_path / "broken.npz"
    p.write_bytes(b"PK\x03\x04" + bytes(60))
    for reader in (read, npz.read_feature_array):
        before = len(os.listdir("/proc/self/fd"))
        with pytest.raises(FormatError) as e:
            reader(p)
        assert len(os.listdir("/proc/self/fd")) == before, e.value


def test_render_hair_and_its_guides_stay_apart_through_a_cache(tmp_path):
    from hairtool import samples
    from hairtool.guides.binding import bind_roots
    from hairtool.guides.files import split_guides, with_guides

    guides = samples.scalp(12, 6, seed=1)
    both = with_guides(bind_roots(guides, count=40, seed=2).build(guides), guides)
    p = tmp_path / "both.npz"
    write(p, both)
    back = read(p)
    assert back.metadata.curves == both.metadata.curves
    hair, g = split_guides(back)
    assert (hair.strand_count, g.strand_count) == (40, 12)
    anim = Animation(np.stack([both.points, both.points + 1]), both.counts, 24.0, metadata=both.metadata)
    write(p, anim)
    assert read(p).metadata.curves == both.metadata.curves


def test_a_header_met_again_reads_as_the_first_time_and_a_corrupt_one_is_refused_each_time():
    """read_npy_header parses each distinct header once: the second member with the same
    header gets the same shape, order and dtype, left at its first data byte; a corrupt one
    (a Python 2 header, a truncated one) is refused however often it comes."""
    from hairtool.io.npz import read_npy_header

    good = io.BytesIO()
    np.lib.format.write_array(good, np.arange(12, dtype=np.float32).reshape(3, 4))
    data = good.getvalue()
    starts = []
    for _ in range(2):
        f = io.BytesIO(data)
        assert read_npy_header("x.npz", f, "a") == ((3, 4), False, np.dtype("<f4"))
        starts.append(f.tell())
    assert starts[0] == starts[1] == len(data) - 48
    corrupt = data.replace(b"'descr'", b"u'descr", 1)
    for _ in range(2):
        with pytest.raises(FormatError, match=r"corrupt \.npy header"):
            read_npy_header("x.npz", io.BytesIO(corrupt), "a")
    for _ in range(2):
        with pytest.raises(ValueError, match="EOF"):
            read_npy_header("x.npz", io.BytesIO(data[:10] + b"{}"), "a")  # cut short
