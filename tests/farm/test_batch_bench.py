"""``hairtool bench batch`` reports its rows (what it measures, never how fast)."""

from __future__ import annotations

import math

import pytest

pytest.importorskip("distributed", reason="the farm extra (dask[distributed]) is not installed")


def test_the_batch_bench_reports_speedup_and_overhead(quick_bench):
    rows = quick_bench(
        "batch", "--jobs", "4", times=("wall_s", "serial_s", "speedup", "split_s", "split_speedup", "start_s")
    )
    assert len(rows) == 1
    row = rows[0]
    assert (row["data"], row["jobs"], row["workers"]) == ("synthetic", 4, 2)
    assert row["speedup"] == pytest.approx(row["serial_s"] / row["wall_s"])
    assert row["split_speedup"] == pytest.approx(row["serial_s"] / row["split_s"])
    assert math.isfinite(row["overhead_ms"]) and row["serial_threads"] >= 1
