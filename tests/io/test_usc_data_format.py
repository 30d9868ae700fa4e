"""USC-HairSalon ``.data``: the layout byte for byte, generated grooms written and read back the
same, and hostile files (cut anywhere, huge or negative counts, non-finite points, nothing but bald
scalp samples) refused with one clear error, through the library and the CLI. Bald scalp samples
(strands of one point) among hair are dropped with one warning line."""

from __future__ import annotations

import struct
import subprocess
import sys
import warnings

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from hairtool import io as hairtool_io
from hairtool.errors import FormatError, ReaderNote
from hairtool.groom import Groom

from .conftest import make_groom


def data_bytes(strands: list[np.ndarray]) -> bytes:
    """The format written out by hand: count, then each strand's count and its points."""
    out = struct.pack("<i", len(strands))
    for p in strands:
        out += struct.pack("<i", len(p)) + np.asarray(p, "<f4").tobytes()
    return out


@st.composite
def grooms(draw) -> Groom:
    counts = draw(st.lists(st.integers(2, 12), min_size=1, max_size=20))
    v = sum(counts)
    finite = st.floats(-(2.0**127), 2.0**127, allow_nan=False, allow_infinity=False, width=32)
    pts = np.array(draw(st.lists(finite, min_size=3 * v, max_size=3 * v)), np.float32).reshape(v, 3)
    return Groom(pts, np.array(counts))


def test_the_layout_is_the_databases(tmp_path):
    a = np.array([[0, 1, 2], [3, 4, 5]], np.float32)
    b = np.array([[6, 7, 8], [9, 10, 11], [12, 13, 14]], np.float32)
    path = tmp_path / "h.data"
    path.write_bytes(data_bytes([a, b]))
    g = hairtool_io.read_groom(path)
    assert g.counts.tolist() == [2, 3]
    assert np.array_equal(g.points, np.vstack([a, b]))
    hairtool_io.write(tmp_path / "out.data", g)
    assert (tmp_path / "out.data").read_bytes() == path.read_bytes()


@settings(max_examples=60, deadline=None)
@given(groom=grooms())
def test_a_groom_written_reads_back_to_the_bytes(tmp_path_factory, groom):
    path = tmp_path_factory.mktemp("rt") / "g.data"
    hairtool_io.write(path, groom)
    back = hairtool_io.read_groom(path)
    assert np.array_equal(back.counts, groom.counts)
    assert back.points.tobytes() == groom.points.astype("<f4").tobytes()
    assert path.stat().st_size == 4 + 4 * groom.strand_count + 12 * groom.vertex_count


def test_attributes_the_format_lacks_are_not_written_and_the_points_stay(tmp_path):
    g = make_groom(3)  # thickness, transparency, colours: .data has no room for them
    hairtool_io.write(tmp_path / "g.data", g)
    back = hairtool_io.read_groom(tmp_path / "g.data")
    assert np.array_equal(back.points, g.points) and back.colors is None


@settings(max_examples=80, deadline=None)
@given(groom=grooms(), cut=st.floats(0.0, 1.0, exclude_max=True))
def test_a_file_cut_anywhere_is_refused(tmp_path_factory, groom, cut):
    path = tmp_path_factory.mktemp("cut") / "g.data"
    hairtool_io.write(path, groom)
    data = path.read_bytes()
    path.write_bytes(data[: int(cut * len(data))])
    with pytest.raises(FormatError) as e:
        hairtool_io.read_groom(path)
    assert str(path) in str(e.value)


@settings(max_examples=60, deadline=None)
@given(
    groom=grooms(),
    which=st.integers(0, 10**6),
    bad=st.sampled_from([np.nan, np.inf, -np.inf]),
    axis=st.integers(0, 2),
)
def test_a_non_finite_point_is_refused_naming_it(tmp_path_factory, groom, which, bad, axis):
    pts = groom.points.copy()
    i = which % len(pts)
    pts[i, axis] = bad
    ends = np.cumsum(groom.counts)
    path = tmp_path_factory.mktemp("nf") / "g.data"
    path.write_bytes(data_bytes(np.split(pts, ends[:-1])))
    with pytest.raises(FormatError, match=f"non-finite value at index {i}"):
        hairtool_io.read_groom(path)


@pytest.mark.parametrize(
    ("body", "words"),
    [
        (struct.pack("<i", 2**31 - 1) + struct.pack("<i", 2) + b"\0" * 24, "2147483647 strands need"),
        (struct.pack("<i", 0), "strand count is 0"),
        (struct.pack("<i", -5), "strand count is -5"),
        (struct.pack("<ii", 1, 2**31 - 1) + b"\0" * 24, "claims 2147483647 points"),
        (struct.pack("<ii", 1, -3) + b"\0" * 24, "strand 0 has -3 points"),
        (struct.pack("<ii", 1, 1) + b"\0" * 12, "bald scalp sample"),
        (data_bytes([np.zeros((2, 3))]) + b"\0\0", "2 unexpected bytes"),
        (b"\1\0", "too short"),
        (b"", "empty"),
    ],
)
def test_hostile_counts_are_one_line_and_exit_2_in_the_cli(tmp_path, body, words):
    path = tmp_path / "bad.data"
    path.write_bytes(body)
    with pytest.raises(FormatError, match=words):
        hairtool_io.read_groom(path)
    run = subprocess.run(
        [sys.executable, "-m", "hairtool", "info", str(path)], capture_output=True, text=True, timeout=120
    )
    assert run.returncode == 2
    lines = run.stderr.strip().splitlines()
    assert len(lines) == 1 and str(path) in lines[0] and words in lines[0], lines


@settings(max_examples=60, deadline=None)
@given(groom=grooms(), bald=st.lists(st.integers(0, 10**6), min_size=1, max_size=8))
def test_bald_scalp_samples_are_dropped_with_a_note(tmp_path_factory, groom, bald):
    """One-point strands put anywhere among the hair: the hair reads as written, and one note
    counts what was dropped."""
    strands = np.split(groom.points, np.cumsum(groom.counts)[:-1])
    for b in bald:
        strands.insert(b % (len(strands) + 1), np.full((1, 3), 7.0, np.float32))
    path = tmp_path_factory.mktemp("bald") / "g.data"
    path.write_bytes(data_bytes(strands))
    with warnings.catch_warnings(record=True) as notes:
        warnings.simplefilter("always")
        back = hairtool_io.read_groom(path)
    assert np.array_equal(back.counts, groom.counts)
    assert back.points.tobytes() == groom.points.astype("<f4").tobytes()
    assert [str(n.message) for n in notes if n.category is ReaderNote] == [
        f"{path}: dropped {len(bald)} of {len(strands)} strands of one point (bald scalp samples)"
    ]


def test_the_cli_says_what_it_dropped_in_one_line(tmp_path):
    path = tmp_path / "bald.data"
    path.write_bytes(data_bytes([np.zeros((1, 3)), np.zeros((3, 3)), np.ones((1, 3)), np.ones((2, 3))]))
    run = subprocess.run(
        [sys.executable, "-m", "hairtool", "info", str(path)], capture_output=True, text=True, timeout=120
    )
    assert run.returncode == 0, run.stderr
    assert run.stderr.splitlines() == [
        f"hairtool info: warning: {path}: dropped 2 of 4 strands of one point (bald scalp samples)"
    ]
