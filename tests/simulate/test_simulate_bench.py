"""``hairtool bench simulate``: frames per second of the solver and of its numpy twin."""

from __future__ import annotations

import pytest

from hairtool.cli import main

TIMES = ("sim_ms", "ms_per_frame", "sim_fps", "reference_fps", "speedup")


def test_quick_row(quick_bench):
    (row,) = quick_bench("simulate", times=TIMES)
    assert (row["strands"], row["vertices"], row["frames"], row["substeps"]) == (100, 800, 6, 8)
    assert row["reference_fps"] is not None and row["threads"] >= 1
    assert row["sim_fps"] == pytest.approx(5 / (row["sim_ms"] / 1e3))
    assert row["speedup"] == pytest.approx(row["sim_fps"] / row["reference_fps"])


def test_options_and_reference_skipped_above_the_limit(quick_bench):
    argv = [
        "--grooms",
        "20x4",
        "sample:comb:5:3",
        "--frames",
        "4",
        "--substeps",
        "2",
        "--reference-limit",
        "50",
    ]
    rows = quick_bench("simulate", *argv, times=TIMES)
    assert [(r["groom"], r["frames"], r["substeps"]) for r in rows] == [
        ("scalp 20x4", 4, 2),
        ("sample:comb:5:3", 4, 2),
    ]
    assert rows[0]["reference_fps"] is None and rows[0]["speedup"] is None
    assert rows[1]["reference_fps"] is not None


def test_bad_frames_exit_2(capsys):
    assert main(["bench", "simulate", "--grooms", "20x4", "--frames", "1"]) == 2
