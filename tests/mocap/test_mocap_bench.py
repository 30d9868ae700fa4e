"""``hairtool bench mocap``: BVH read, features, the quaternion table and the DP, with the twins."""

from __future__ import annotations

from hairtool.cli import main

TIMES = (
    "read_ms",
    "features_ms",
    "quat_features_ms",
    "table_ms",
    "select_ms",
    "select_numpy_ms",
    "positions_keys_ms",
    "head_table_ms",
    "head_reference_ms",
    "reference_over_table",
)


def test_quick_row_on_a_real_capture(quick_bench, motion_dir):
    (row,) = quick_bench("mocap", times=TIMES)
    assert (row["capture"], row["frames"], row["joints"]) == ("freebvh", 69, 55)
    assert row["keys"] == 6 and row["reference_frames"] == 20


def test_given_captures_and_reference_frames(quick_bench, chain_bvh):
    rows = quick_bench("mocap", str(chain_bvh), str(chain_bvh), "--reference-frames", "50", times=TIMES)
    assert [(r["capture"], r["frames"], r["joints"], r["keys"]) for r in rows] == [("chain", 3, 2, 2)] * 2
    assert rows[0]["reference_frames"] == 3  # never more than the take


def test_bad_input_exits_2(capsys, tmp_path):
    (tmp_path / "bad.bvh").write_text("HIERARCHY\n")
    assert main(["bench", "mocap", str(tmp_path / "bad.bvh")]) == 2
