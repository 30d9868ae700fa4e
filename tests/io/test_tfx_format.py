"""AMD TressFX 3 and 4: the real models load with their published sizes; bad headers fail cleanly."""

from __future__ import annotations

import struct

import numpy as np
import pytest

from hairtool.errors import FormatError
from hairtool.io import read, write

REAL = {
    "ratboy_mohawk.tfx": (2226, 32),
    "sintel_hair.tfx": (228, 32),
    "ponytail_back.tfx": (517, 16),
    "ponytail_front_top.tfx": (876, 16),
    "ponytail_tail.tfx": (474, 16),
    "bear.tfx": (48113, 4),
}


@pytest.mark.parametrize(("name", "size"), REAL.items())
def test_real_models_load_with_their_published_sizes(grooms_dir, name, size):
    g = read(grooms_dir / name)
    strands, per_strand = size
    assert g.strand_count == strands
    assert np.all(g.counts == per_strand)
    assert np.all(np.isfinite(g.points))
    assert np.all(g.strand_lengths > 0)
    # A wrong stride or offset would scatter vertices: real segments are short against the groom.
    lo, hi = g.bounds
    assert g.segment_lengths.max() < 0.25 * np.linalg.norm(hi - lo)


def _v4(strands, per, xyzw, thickness=None, colors=None) -> bytes:
    pos = 160
    body = np.asarray(xyzw, "<f4").tobytes()
    off_t = off_c = 0
    if thickness is not None:
        off_t = pos + len(body)
        body += np.asarray(thickness, "<f4").tobytes()
    if colors is not None:
        off_c = pos + len(body)
        body += np.asarray(colors, "<f4").tobytes()
    head = struct.pack("<f7I", 4.0, strands, per, pos, 0, 0, off_t, off_c) + b"\0" * 128
    return head + body


def _v3(strands, per, xyz, offset=296) -> bytes:
    head = struct.pack("<f3Ii", 3.0, strands, per, 0, 0) + b"\0" * 124 + struct.pack("<I", offset)
    head = head.ljust(offset, b"\0")
    return head + np.asarray(xyz, "<f4").tobytes()


def test_v4_reads_positions_thickness_and_colours(tmp_path):
    xyzw = np.arange(2 * 4 * 4, dtype=np.float32).reshape(8, 4)
    colors = np.linspace(0, 1, 32, dtype=np.float32).reshape(8, 4)
    p = tmp_path / "t4.tfx"
    p.write_bytes(_v4(2, 4, xyzw, thickness=[0.5, 0.25], colors=colors))
    g = read(p)
    np.testing.assert_array_equal(g.points, xyzw[:, :3])
    np.testing.assert_array_equal(g.thickness, [0.5] * 4 + [0.25] * 4)
    np.testing.assert_array_equal(g.colors, colors[:, :3])


def test_v4_ignores_optional_arrays_out_of_range(tmp_path):
    data = bytearray(_v4(1, 2, np.zeros((2, 4))))
    struct.pack_into("<2I", data, 20, 10_000_000, 10_000_000)  # thickness and colour offsets
    p = tmp_path / "t4.tfx"
    p.write_bytes(bytes(data))
    g = read(p)
    assert g.thickness is None and g.colors is None


def test_v3_reads_float3_positions(tmp_path):
    xyz = np.arange(3 * 4 * 3, dtype=np.float32).reshape(12, 3)
    p = tmp_path / "t3.tfx"
    p.write_bytes(_v3(3, 4, xyz))
    g = read(p)
    assert g.strand_count == 3
    np.testing.assert_array_equal(g.points, xyz)


@pytest.mark.parametrize(
    ("data", "reason"),
    [
        (b"", "empty"),
        (b"\0\0\x40\x40", "too short"),
        (struct.pack("<f", 7.0) + b"\0" * 200, "not a TressFX"),
        (struct.pack("<f", float("nan")) + b"\0" * 200, "not a TressFX"),
        (_v4(2**31, 32, np.zeros((4, 4))), "truncated"),
        (_v4(1, 4, np.zeros((2, 4))), "truncated"),
        (_v4(1, 1, np.zeros((1, 4))), "vertices per strand"),
        (_v4(1, 128, np.zeros((128, 4))), "vertices per strand"),
        (_v4(0, 4, np.zeros((0, 4))), "no strands"),
        (_v4(1, 2, [[0, 0, 0, 0], [np.inf, 0, 0, 1]]), "non-finite"),
        (_v4(1, 2, np.zeros((2, 4)))[:100], "too short"),
        (_v3(2**30, 64, np.zeros((4, 3))), "truncated"),
        (_v3(1, 2, np.zeros((2, 3)), offset=148)[:-1], "truncated"),
    ],
)
def test_bad_files_raise_format_error(tmp_path, data, reason):
    p = tmp_path / "bad.tfx"
    p.write_bytes(data)
    with pytest.raises(FormatError, match=reason):
        read(p)


def test_tfx_is_read_only(tmp_path, groom):
    with pytest.raises(FormatError, match="cannot write"):
        write(tmp_path / "x.tfx", groom)
