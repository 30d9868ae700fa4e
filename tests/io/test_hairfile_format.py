"""Cem Yuksel's HAIR format: every array and flag, header defaults, info string, bad headers."""

from __future__ import annotations

import struct

import numpy as np
import pytest

from hairtool.errors import FormatError
from hairtool.groom import Groom
from hairtool.io import hairfile, read, write


def _header(hair_count, point_count, arrays, default_segments=0, info=b"") -> bytes:
    return (
        b"HAIR"
        + struct.pack("<4I", hair_count, point_count, arrays, default_segments)
        + struct.pack("<5f", 0.5, 0.25, 0.1, 0.2, 0.3)
        + info.ljust(88, b"\0")
    )


def test_round_trip_is_bit_exact_with_every_attribute(tmp_path, groom):
    p = tmp_path / "g.hair"
    write(p, groom)
    back = read(p)
    assert isinstance(back, Groom)
    np.testing.assert_array_equal(back.counts, groom.counts)
    assert back.points.tobytes() == groom.points.tobytes()
    for name in ("thickness", "transparency", "colors"):
        assert getattr(back, name).tobytes() == getattr(groom, name).tobytes()
    h = hairfile.read_header(p)
    assert h.arrays == 31  # segments (uneven strands), points, thickness, transparency, colours
    assert p.stat().st_size == 128 + 2 * groom.strand_count + (12 + 4 + 4 + 12) * groom.vertex_count


def test_equal_strands_use_default_segments_and_no_attribute_arrays(tmp_path):
    g = Groom(np.arange(60, dtype=np.float32).reshape(20, 3), [5, 5, 5, 5])
    p = tmp_path / "even.hair"
    write(p, g)
    h = hairfile.read_header(p)
    assert h.arrays == hairfile.HAS_POINTS and h.default_segments == 4
    assert p.stat().st_size == 128 + 12 * 20
    back = read(p)
    np.testing.assert_array_equal(back.counts, [5, 5, 5, 5])
    assert back.thickness is None and back.transparency is None and back.colors is None


def test_hand_written_file_with_segments_and_defaults(tmp_path):
    pts = np.arange(15, dtype="<f4")
    data = _header(
        2, 5, hairfile.HAS_SEGMENTS | hairfile.HAS_POINTS | hairfile.HAS_COLORS, 7, b"made by hand"
    )
    data += np.array([1, 2], "<u2").tobytes() + pts.tobytes() + (pts / 100).astype("<f4").tobytes()
    p = tmp_path / "hand.hair"
    p.write_bytes(data)
    g = read(p)
    np.testing.assert_array_equal(g.counts, [2, 3])
    np.testing.assert_array_equal(g.points.ravel(), pts)
    np.testing.assert_array_equal(g.colors.ravel(), (pts / 100).astype(np.float32))
    assert g.thickness is None  # header defaults are not materialised
    h = hairfile.read_header(p)
    assert h.info == "made by hand"
    assert h.defaults.thickness == 0.5 and h.defaults.transparency == 0.25
    assert h.defaults.color == pytest.approx((0.1, 0.2, 0.3))


def test_info_string_and_defaults_are_written(tmp_path, groom):
    p = tmp_path / "info.hair"
    hairfile.write(p, groom, info="é" * 60, defaults=hairfile.HairDefaults(2.0, 0.5, (0.1, 0.2, 0.3)))
    h = hairfile.read_header(p)
    assert h.info == "é" * 43  # 87 bytes at most, never a half character
    assert h.defaults.thickness == 2.0 and h.defaults.transparency == 0.5
    write(p, groom)
    assert hairfile.read_header(p).info == hairfile.DEFAULT_INFO


@pytest.mark.parametrize(
    ("data", "reason"),
    [
        (b"", "empty"),
        (b"HAIR" + b"\0" * 20, "too short"),
        (_header(1, 2, 2, 1).replace(b"HAIR", b"RIAH"), "not a HAIR file"),
        (_header(1, 2, 2, 1), "truncated"),
        (_header(1, 2, 2, 1) + b"\0" * 28, "unexpected bytes"),
        (_header(2**31, 2**32 - 2, 2, 1) + b"\0" * 24, "truncated"),
        (_header(1, 2, 1 | 4, 1) + b"\0" * 10, "no points"),
        (_header(1, 2, 2 | 64, 1) + b"\0" * 24, "unknown array flags"),
        (_header(0, 0, 2, 1), "no strands"),
        (_header(1, 1, 2, 0) + b"\0" * 12, "default_segments"),
        (_header(2, 5, 3) + np.array([1, 1], "<u2").tobytes() + b"\0" * 60, "add up to"),
        (_header(1, 1, 3) + np.array([0], "<u2").tobytes() + b"\0" * 12, "at least 2"),
        (_header(1, 2, 2, 1) + np.array([0, 0, 0, np.nan, 0, 0], "<f4").tobytes(), "non-finite"),
        (_header(1, 2, 6, 1) + np.array([0] * 6 + [1, np.inf], "<f4").tobytes(), "non-finite"),
    ],
)
def test_bad_files_raise_format_error(tmp_path, data, reason):
    p = tmp_path / "bad.hair"
    p.write_bytes(data)
    with pytest.raises(FormatError, match=reason) as e:
        read(p)
    assert str(p) in str(e.value)


def test_strands_longer_than_u16_segments_are_refused(tmp_path):
    g = Groom(np.zeros((70_000, 3), np.float32), [70_000])
    with pytest.raises(FormatError, match="65536"):
        write(tmp_path / "long.hair", g)
    assert not (tmp_path / "long.hair").exists()
