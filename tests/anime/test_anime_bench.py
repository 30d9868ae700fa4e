"""``hairtool bench anime``: cycle time per frame and the numba pose against its numpy twin."""

from __future__ import annotations

import pytest

from hairtool.cli import main

TIMES = ("cycle_ms", "ms_per_frame", "pose_ms", "pose_numpy_ms", "numpy_over_numba")


def test_quick_rows(quick_bench):
    rows = quick_bench("anime", times=TIMES)
    assert [(r["groom"], r["vertices"]) for r in rows] == [
        ("scalp 100x8", 800),
        ("sample:portrait:20:10", 200),
    ]
    for r in rows:
        assert (r["frames"], r["pictures"]) == (11, 6)  # the paper's T = 0.45 s at 24 fps on twos
        assert r["ms_per_frame"] == pytest.approx(r["cycle_ms"] / 11)
        assert r["numpy_over_numba"] == pytest.approx(r["pose_numpy_ms"] / r["pose_ms"])


def test_timing_options(quick_bench):
    (row,) = quick_bench("anime", "--grooms", "10x4", "--fps", "30", "--hold", "3", times=TIMES)
    assert row["frames"] == 14 and row["pictures"] == 5  # round(0.45 × 30) = 13.5 → 14 frames


def test_bad_schedule_exits_2(capsys):
    assert main(["bench", "anime", "--grooms", "10x4", "--hold", "0"]) == 2
