"""``hairtool bench io``: one row per groom and format, sizes and rates that make sense."""

from __future__ import annotations

import pytest

from hairtool.cli import main

TIMES = ("write_ms", "write_mb_s", "read_ms", "read_mb_s", "read_over_npy", "file_mb")


def test_quick_rows_cover_every_format(quick_bench, grooms_dir):
    rows = quick_bench("io", times=TIMES)
    by_groom: dict[str, list[str]] = {}
    for r in rows:
        by_groom.setdefault(r["groom"], []).append(r["format"])
    assert by_groom == {
        "ponytail_tail": ["npy", "tfx", "hair", "npz", "usda", "obj"],
        "scalp 200x8": ["npy", "hair", "npz", "usda", "obj"],
    }
    for r in rows:
        assert r["vertices"] == (474 * 16 if r["groom"] == "ponytail_tail" else 1600)
        assert (r["write_ms"] is None) == (r["format"] == "tfx")
        assert r["read_ms"] is not None
        assert r["read_mb_s"] == pytest.approx(r["file_mb"] / r["read_ms"] * 1e3)
        if r["format"] == "npy":
            assert r["read_over_npy"] == 1.0
        if r["format"] in ("npy", "hair"):  # uncompressed float32 points, and a little more
            assert r["vertices"] * 12 < r["file_mb"] * 1e6 < r["vertices"] * 12 + r["strands"] * 8 + 1024


def test_formats_grooms_and_folder_options(quick_bench, tmp_path):
    rows = quick_bench(
        "io", "--grooms", "30x4", "sample:comb:5:3", "--formats", "usdc", "--dir", str(tmp_path)
    )
    assert [(r["groom"], r["format"]) for r in rows] == [
        ("scalp 30x4", "npy"),
        ("scalp 30x4", "usdc"),
        ("sample:comb:5:3", "npy"),
        ("sample:comb:5:3", "usdc"),
    ]
    assert list(tmp_path.iterdir()) == []  # the temporary folder is gone


def test_bad_groom_exits_2(capsys):
    assert main(["bench", "io", "--grooms", "sample:braid"]) == 2
    assert main(["bench", "io", "--repeat", "0"]) == 2
