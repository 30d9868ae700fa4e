"""Key exports agree on time: the CSV sheet's time_code and time, the JSON record's, and USD
key poses only where USD plays them as the keys' curve (linear), else every frame (--bake)."""

from __future__ import annotations

import csv
import json
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from hairtool import samples
from hairtool.cli import main
from hairtool.errors import FormatError, ParameterError
from hairtool.keys.export import export_keys, keys_record, sheet_rows, sheet_time_codes
from hairtool.simulate.sway import sway_animation

GN = Path(__file__).resolve().parents[1] / "data" / "interop" / "b_gnanim.usdc"  # time codes 1…48


def _sheet(path) -> list[dict]:
    with open(path, newline="", encoding="utf-8") as f:
        return list(csv.DictReader(f))


def test_the_sheet_json_and_frames_agree_on_a_source_starting_at_one(tmp_path):
    out, sheet = str(tmp_path / "k.json"), str(tmp_path / "k.csv")
    assert main(["keys", str(GN), "--keys", "5", "--out", out, "--export", sheet]) == 0
    record = json.loads((tmp_path / "k.json").read_text())
    rows = _sheet(tmp_path / "k.csv")
    assert [float(r["time_code"]) for r in rows] == [float(f + 1) for f in range(48)]
    assert [int(r["frame"]) for r in rows] == list(range(48))
    fps = record["fps"]
    for r in rows:
        assert float(r["time"]) == pytest.approx(float(r["time_code"]) / fps, abs=1e-9)
    for key in record["keys"]:
        row = rows[key["frame"]]
        assert row["key"] == "1"
        assert float(row["time_code"]) == key["time_code"]
        assert float(row["time"]) == pytest.approx(key["time"], abs=1e-9)


def test_hermite_key_poses_are_refused_naming_bake_and_baked_with_it(tmp_path, capsys):
    from pxr import Usd, UsdGeom

    out = tmp_path / "k.usda"
    assert main(["keys", str(GN), "--keys", "5", "--interp", "hermite", "--export", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--bake" in err and "k.usda" in err and not out.exists()
    assert list(tmp_path.iterdir()) == []
    argv = ["keys", str(GN), "--keys", "5", "--interp", "hermite", "--export", str(out), "--bake"]
    assert main(argv) == 0
    stage = Usd.Stage.Open(str(out))
    curves = next(UsdGeom.BasisCurves(p) for p in stage.Traverse() if p.IsA(UsdGeom.BasisCurves))
    assert curves.GetPointsAttr().GetTimeSamples() == [float(c) for c in range(1, 49)]
    # linear keys are what USD plays: their poses alone are the export
    assert main(["keys", str(GN), "--keys", "5", "--export", str(tmp_path / "lin.usda")]) == 0


def test_the_library_refuses_hermite_key_poses(tmp_path):
    anim = sway_animation(samples.scalp(6, 5, seed=3), 12, flick_frame=7)
    result = {"frames": 12, "fps": anim.fps, "keys": [0, 5, 11], "params": {"interp": "hermite-fit"}}
    with pytest.raises(FormatError, match=r"linearly.*hermite-fit"):
        export_keys(tmp_path / "k.usdc", keys_record(result), anim)
    assert list(tmp_path.iterdir()) == []


@st.composite
def timed_keys(draw):
    n = draw(st.integers(2, 40))
    start = draw(st.integers(-100, 100)) / draw(st.sampled_from([1, 2, 4]))
    keys = sorted(draw(st.sets(st.integers(0, n - 1), min_size=1, max_size=n)))
    fps = draw(st.sampled_from([12.0, 24.0, 25.0, 30.0, 29.97]))
    return n, start, keys, fps


@settings(max_examples=60, deadline=None)
@given(timed_keys())
def test_generated_sheets_agree_with_their_records(case):
    n, start, keys, fps = case
    codes = start + np.arange(n, dtype=np.float64)
    record = keys_record({"frames": n, "fps": fps, "keys": keys}, time_codes=codes)
    # the record alone gives the sheet every frame's time code
    np.testing.assert_array_equal(sheet_time_codes(record), codes)
    rows = sheet_rows(n, fps, keys, time_codes=sheet_time_codes(record))
    header, body = rows[0], rows[1:]
    assert header[:4] == ["frame", "time_code", "time", "key"]
    by_frame = {k["frame"]: k for k in record["keys"]}
    for f, row in enumerate(body):
        assert row[0] == f and float(row[1]) == codes[f]
        assert float(row[2]) == pytest.approx(codes[f] / fps, abs=1e-9)
        assert row[3] == int(f in by_frame)
        if f in by_frame:
            assert float(row[1]) == by_frame[f]["time_code"]
            assert float(row[2]) == pytest.approx(by_frame[f]["time"], abs=1e-9)
    if len(keys) >= 1:  # time codes that contradict the record's keys are refused
        wrong = codes + 0.5
        with pytest.raises(ParameterError, match="time_codes"):
            sheet_time_codes(record, wrong)


def test_a_record_with_uneven_time_codes_needs_them_all(tmp_path):
    codes = np.array([0.0, 1.0, 3.0, 4.0])
    record = keys_record({"frames": 4, "fps": 24.0, "keys": [0, 2]}, time_codes=codes)
    with pytest.raises(ParameterError, match="time_codes"):
        export_keys(tmp_path / "k.csv", record)
    export_keys(tmp_path / "k.csv", record, time_codes=codes)
    assert [float(r["time_code"]) for r in _sheet(tmp_path / "k.csv")] == codes.tolist()
