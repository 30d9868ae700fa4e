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


def test_csv_sheet_marks_the_pinned_keys(tmp_path):
    from hairtool.keys.constraints import KeyConstraints

    x = np.cumsum(np.random.default_rng(2).normal(size=(30, 3)), axis=0)
    sel = select_keys(cost_table(x, "linear"), keys=6, constraints=KeyConstraints((7, 20), (10, 11)))
    record = keys_record({"frames": 30, "fps": 24.0, **sel.to_dict()})
    export_keys(tmp_path / "k.csv", record)
    with open(tmp_path / "k.csv", newline="", encoding="utf-8") as f:
        rows = list(csv.DictReader(f))
    assert {r["pinned"] for r in rows if r["key"] == "0"} == {""}
    assert {int(r["frame"]): int(r["pinned"]) for r in rows if r["key"] == "1"} == {
        k: int(k in (7, 20)) for k in sel.keys.tolist()
    }
    free = keys_record({"frames": 30, "fps": 24.0, **select_keys(cost_table(x, "linear"), keys=6).to_dict()})
    assert [r[8] for r in sheet_rows(30, 24.0, record_keys(free))[1:] if r[3]] == [0] * 6
    with pytest.raises(ParameterError, match="pins"):
        export_keys(tmp_path / "bad.csv", {**record, "params": {"pins": ["7"]}})


def test_sheet_rows_outside_the_keys_hold_the_nearest_key():
    rows = sheet_rows(6, 24.0, [1, 3])
    assert rows[1][5:8] == [1, 1, "0.0"] and rows[6][5:8] == [3, 3, "0.0"]
    assert rows[3][5:8] == [1, 3, "0.5"]


@pytest.mark.parametrize(
    "text,needle",
    [
        ("{", "not valid JSON"),
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
        ("[" * 100_000 + "]" * 100_000, "nested 100000 levels deep"),
        ('{"frames": 5, "fps": 24, "keys": [], "x": ' + "[" * 100_000 + "]" * 100_000 + "}", "nested"),
        ('{"frames": ' + "9" * 5000 + ', "fps": 24, "keys": []}', "a number of 5000 digits"),
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
    with pytest.raises(FormatError, match="nested 901 levels deep"):
        read_keys_json(path)
    path.write_text(base + "[" * (MAX_NESTING - 1) + "]" * (MAX_NESTING - 1) + "}", encoding="utf-8")
    write_keys_json(tmp_path / "again.json", read_keys_json(path))
    assert read_keys_json(tmp_path / "again.json")["x"] == read_keys_json(path)["x"]


def _curve_from_sheet(path):
    """Every frame of every channel rebuilt from the CSV alone, by the formula sheet_rows documents."""
    with open(path, newline="", encoding="utf-8") as f:
        rows = list(csv.DictReader(f))
    names = [c for c in rows[0] if f"{c}:in" in rows[0]]
    keyed = {int(r["frame"]): r for r in rows if r["key"] == "1"}

    def at(frame, name, what=""):
        return float(keyed[frame][name + what])

    out = np.empty((len(rows), len(names)))
    for r in rows:
        f, a, b = int(r["frame"]), int(r["previous_key"]), int(r["next_key"])
        for c, name in enumerate(names):
            if a == b:
                out[f, c] = at(a, name)
                continue
            s, el = (f - a) / (b - a), b - a
            h00, h10 = 2 * s**3 - 3 * s**2 + 1, s**3 - 2 * s**2 + s
            h01, h11 = -2 * s**3 + 3 * s**2, s**3 - s**2
            start = h00 * at(a, name) + h10 * el * at(a, name, ":out")
            out[f, c] = start + h01 * at(b, name) + h11 * el * at(b, name, ":in")
    return names, keyed, out


@pytest.mark.parametrize("interp", ["hermite", "hermite-fit"])
def test_csv_sheet_carries_the_tangents_and_rebuilds_the_json_curve(tmp_path, capsys, interp, motion_dir):
    from hairtool.cli import main
    from hairtool.keys.reconstruct import interpolate_keys, key_poses
    from hairtool.mocap.bvh import read_bvh

    bvh = motion_dir / "freebvh.bvh"
    sheet, record = tmp_path / "k.csv", tmp_path / "k.json"
    argv = ["keys", str(bvh), "--keys", "7", "--interp", interp, "--export", str(sheet), "--out", str(record)]
    assert main(argv) == 0
    capsys.readouterr()
    back = read_keys_json(record)
    keys = record_keys(back)
    names, keyed, curve = _curve_from_sheet(sheet)
    motion = read_bvh(bvh)
    assert names == back["tangents"]["channels"] and len(names) == motion.values.shape[1]
    assert names[0] == "mixamorig:Hips.Xposition"
    for a, key in enumerate(keys.tolist()):  # the CSV holds the JSON's numbers to the bit
        for what, field in (("", "values"), (":in", "in"), (":out", "out")):
            got = [float(keyed[key][n + what]) for n in names]
            assert got == back["tangents"][field][a]
    kp = key_poses(motion.values, keys, interp)
    np.testing.assert_allclose(curve, interpolate_keys(kp), rtol=1e-12, atol=1e-9)
    if interp == "hermite":  # seed 003's data tangents: one per key
        assert back["tangents"]["in"] == back["tangents"]["out"]


def test_feature_arrays_export_json_and_csv_but_not_key_poses(tmp_path, capsys):
    from hairtool.cli import main

    x = np.cumsum(np.random.default_rng(4).normal(size=(40, 3)), axis=0)
    np.savez(tmp_path / "x.npz", X=x)
    base = ["keys", str(tmp_path / "x.npz"), "--keys", "5", "--interp", "hermite-fit", "--export"]
    assert main([*base, str(tmp_path / "k.csv")]) == 0
    assert main([*base, str(tmp_path / "k.json")]) == 0
    capsys.readouterr()
    names, _, curve = _curve_from_sheet(tmp_path / "k.csv")
    assert names == ["x0", "x1", "x2"]
    keys = record_keys(read_keys_json(tmp_path / "k.json"))
    from hairtool.keys.reconstruct import interpolate_keys, key_poses

    rebuilt = interpolate_keys(key_poses(x, keys, "hermite-fit"))
    np.testing.assert_allclose(curve, rebuilt, rtol=1e-12, atol=1e-12)
    assert main([*base, str(tmp_path / "k.usda")]) == 2
    assert "export" in capsys.readouterr().err


def test_sheet_refuses_curves_that_do_not_match_the_keys():
    curves = {"channels": ["a"], "values": [[0.0], [1.0]], "out": [[0.0], [1.0]], "in": [[0.0]]}
    with pytest.raises(ParameterError, match="tangents"):
        sheet_rows(5, 24.0, [0, 4], curves=curves)
    with pytest.raises(ParameterError, match="tangents"):
        sheet_rows(5, 24.0, [0, 4], curves={"channels": ["a"]})
    good = {**curves, "in": [[0.5], [2.0]]}
    rows = sheet_rows(5, 24.0, [0, 4], curves=good)
    assert rows[0][-3:] == ["a", "a:in", "a:out"]
    assert rows[1][-3:] == ["0.0", "0.5", "0.0"] and rows[2][-3:] == ["", "", ""]
