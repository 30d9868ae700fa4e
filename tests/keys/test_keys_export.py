"""Keys export: JSON record round trip, CSV key sheet, USD with exactly the key poses as samples."""

from __future__ import annotations

import csv
import json

import numpy as np
import pytest

from hairtool import samples
from hairtool.errors import FormatError, ParameterError
from hairtool.keys.costs import cost_table
from hairtool.keys.dp import select_keys
from hairtool.keys.export import (
    export_keys,
    keys_record,
    read_keys_json,
    record_keys,
    sheet_rows,
    write_key_poses,
)
from hairtool.keys.features import frame_features
from hairtool.simulate.sway import sway_animation


@pytest.fixture(scope="module")
def solved():
    anim = sway_animation(samples.scalp(12, 6, seed=1), 30, flick_frame=19)
    sel = select_keys(cost_table(frame_features(anim), "linear", 0.0, "total"), keys=6)
    result = {"frames": anim.n_frames, "fps": anim.fps, **sel.to_dict()}
    return anim, sel, keys_record(result, "sway.npz")


def test_json_record_reads_back_with_frames_times_params_and_costs(tmp_path, solved):
    anim, sel, record = solved
    path = tmp_path / "keys.json"
    export_keys(path, record)
    back = read_keys_json(path)
    assert back == json.loads(json.dumps(record))
    assert record_keys(back).tolist() == sel.keys.tolist()
    assert [k["time"] for k in back["keys"]] == pytest.approx((sel.keys / anim.fps).tolist())
    assert back["cost"] == sel.cost and back["uniform"]["cost"] == sel.uniform_cost
    assert back["params"]["keys"] == 6 and back["frames"] == 30 and "curve" not in back


def test_usd_holds_exactly_the_key_frames_as_time_samples(tmp_path, solved):
    from pxr import Usd, UsdGeom

    anim, sel, record = solved
    path = tmp_path / "keys.usda"
    export_keys(path, record, anim)
    stage = Usd.Stage.Open(str(path))
    curves = next(UsdGeom.BasisCurves(p) for p in stage.Traverse() if p.IsA(UsdGeom.BasisCurves))
    attr = curves.GetPointsAttr()
    assert attr.GetTimeSamples() == [float(k) for k in sel.keys]
    for k in sel.keys:
        np.testing.assert_array_equal(np.asarray(attr.Get(float(k))), anim.frames[k])
    a, b = int(sel.keys[1]), int(sel.keys[2])
    mid = (a + b) / 2  # a USD reader interpolates linearly: the linear reconstruction
    expect = anim.frames[a] + (anim.frames[b] - anim.frames[a]) * ((mid - a) / (b - a))
    np.testing.assert_allclose(np.asarray(attr.Get(mid)), expect, atol=1e-5)
    assert stage.GetTimeCodesPerSecond() == anim.fps


def test_csv_sheet_has_one_row_per_frame_with_weights(tmp_path, solved):
    anim, sel, record = solved
    path = tmp_path / "keys.csv"
    export_keys(path, record)
    with open(path, newline="", encoding="utf-8") as f:
        rows = list(csv.DictReader(f))
    assert len(rows) == anim.n_frames
    assert [int(r["frame"]) for r in rows if r["key"] == "1"] == sel.keys.tolist()
    assert [int(r["frame"]) for r in rows if r["uniform_key"] == "1"] == sel.uniform_keys.tolist()
    a, b = int(sel.keys[0]), int(sel.keys[1])
    row = rows[a + 1]
    assert (int(row["previous_key"]), int(row["next_key"])) == (a, b)
    assert float(row["weight"]) == pytest.approx(1 / (b - a))


def test_sheet_rows_outside_the_keys_hold_the_nearest_key():
    rows = sheet_rows(6, 24.0, [1, 3])
    assert rows[1][4:7] == [1, 1, "0.0"] and rows[6][4:7] == [3, 3, "0.0"]
    assert rows[3][4:7] == [1, 3, "0.5"]


@pytest.mark.parametrize(
    "text,needle",
    [
        ("{", "not JSON"),
        ("[1, 2]", "JSON object"),
        ('{"format": "other"}', "format"),
        ('{"version": 9, "frames": 3, "fps": 24, "keys": []}', "version 9"),
        ('{"frames": 0, "fps": 24, "keys": []}', "frames"),
        ('{"frames": 5, "fps": -1, "keys": []}', "fps"),
        ('{"frames": 5, "fps": 24, "keys": [{"frame": 1.5}]}', "keys"),
        ('{"frames": 5, "fps": 24, "keys": [{"frame": 3}, {"frame": 2}]}', "increasing"),
        ('{"frames": 5, "fps": 24, "keys": [{"frame": 7}]}', "keys"),
    ],
)
def test_bad_json_is_one_error_naming_the_file(tmp_path, text, needle):
    path = tmp_path / "bad.json"
    path.write_text(text, encoding="utf-8")
    with pytest.raises(FormatError, match=needle) as e:
        read_keys_json(path)
    assert "bad.json" in str(e.value)


def test_bad_exports_are_refused(tmp_path, solved):
    anim, _sel, record = solved
    with pytest.raises(FormatError, match="animation"):
        export_keys(tmp_path / "k.usda", record)
    with pytest.raises(FormatError, match="frames"):
        export_keys(tmp_path / "k.usda", record, anim.with_frames(anim.frames[:10]))
    with pytest.raises(FormatError, match=r"\.json"):
        export_keys(tmp_path / "k.txt", record)
    with pytest.raises(FormatError, match="USD"):
        write_key_poses(tmp_path / "k.npz", anim, [0, 5])
    with pytest.raises(ParameterError, match="keys"):
        keys_record({"frames": 5, "fps": 24.0, "keys": [0, 9]})
    assert not list(tmp_path.iterdir())


@pytest.mark.parametrize(
    ("text", "needle"),
    [
        ("[" * 100_000 + "]" * 100_000, "nested too deeply"),
        ('{"frames": 5, "fps": 24, "keys": [], "x": ' + "[" * 100_000 + "]" * 100_000 + "}", "nested"),
        ('{"frames": ' + "9" * 5000 + ', "fps": 24, "keys": []}', "digits long"),
        ('{"frames": 10, "fps": 24, "keys": [{"frame": ' + "9" * 30 + "}]}", "whole frame numbers"),
        ('{"frames": 10, "fps": 1e400, "keys": [{"frame": 1}]}', "fps"),
    ],
)
def test_hostile_json_is_one_error_naming_the_file(tmp_path, text, needle):
    """Deep nesting, integers past Python's digit limit or past int64: no RecursionError,
    ValueError or TypeError escapes (issue 17)."""
    path = tmp_path / "hostile.json"
    path.write_text(text, encoding="utf-8")
    with pytest.raises(FormatError, match=needle) as e:
        read_keys_json(path)
    assert e.value.path == str(path)


def test_a_record_read_back_can_always_be_written_again(tmp_path):
    """A record nested 900 levels parses, but writing it again would recurse past Python's limit:
    the reader refuses anything deeper than MAX_NESTING."""
    from hairtool.keys.export import MAX_NESTING, write_keys_json

    base = '{"frames": 5, "fps": 24, "keys": [{"frame": 1}], "x": '
    path = tmp_path / "deep.json"
    path.write_text(base + "[" * 900 + "]" * 900 + "}", encoding="utf-8")
    with pytest.raises(FormatError, match="nests deeper"):
        read_keys_json(path)
    path.write_text(base + "[" * (MAX_NESTING - 1) + "]" * (MAX_NESTING - 1) + "}", encoding="utf-8")
    write_keys_json(tmp_path / "again.json", read_keys_json(path))
    assert read_keys_json(tmp_path / "again.json")["x"] == read_keys_json(path)["x"]
