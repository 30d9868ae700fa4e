"""``hairtool anime``: the schedule as text and JSON, the exposure sheet, posing, writing, comparing."""

from __future__ import annotations

import csv
import json

import numpy as np
import pytest

from hairtool.cli import main
from hairtool.cli.anime import parse_ids


def run_json(capsys, *argv):
    assert main(["anime", *argv, "--json"]) == 0
    return json.loads(capsys.readouterr().out)


def test_schedule_only_json(capsys):
    r = run_json(capsys)
    assert r["n_frames"] == 11 and r["n_pictures"] == 6
    assert r["holds"] == [2, 2, 2, 2, 2, 1] and r["dt"] == 0.075
    assert r["exposure"] == [0, 0, 1, 1, 2, 2, 3, 3, 4, 4, 5]
    assert "strands" not in r


def test_schedule_options_and_shot_length(capsys):
    r = run_json(capsys, "--period", "1", "--fps", "24", "--hold", "3", "--cycles", "2")
    assert (r["n_frames"], r["n_pictures"], r["k"]) == (24, 8, 0)
    assert r["shot_frames"] == 48 and r["exposure"][24:27] == [0, 0, 0]
    r = run_json(capsys, "--frames", "13")
    assert r["exposure"] == [0, 0, 1, 1, 2, 2, 3, 3, 4, 4, 5, 0, 0]


def test_text_output(capsys):
    assert main(["anime"]) == 0
    out = capsys.readouterr().out
    assert "11 frames" in out and "6 pictures" in out and "holds: 2 2 2 2 2 1" in out


@pytest.mark.parametrize(
    "argv",
    [
        ["--period", "0.01"],
        ["--period", "0.05", "--hold", "3"],
        ["--gravity", "0"],
        ["--wavelength", "-1"],
        ["--hold", "0"],
        ["--cycles", "0"],
        ["--frames", "0"],
        ["--fps", "nan"],
        ["sample:bogus"],
        ["sample:portrait:x"],
        ["sample:portrait", "--guides", "a-b"],
        ["sample:portrait", "--guides", "999"],
        ["sample:portrait", "--sway", "1,2"],
        ["sample:portrait", "--phase-spread", "2"],
        ["sample:portrait", "out.xyz"],
        ["--compare", "ref.npz"],
        ["/no/such/groom.tfx"],
    ],
)
def test_bad_input_exits_2_with_one_line(capsys, argv):
    assert main(["anime", *argv]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("hairtool anime: error:") and "\n" not in err


def test_help_exits_0(capsys):
    with pytest.raises(SystemExit) as e:
        main(["anime", "--help"])
    assert e.value.code == 0
    out = capsys.readouterr().out
    assert "sample:NAME" in out and "--export-sheet" in out


def test_export_sheet(tmp_path, capsys):
    sheet = tmp_path / "sheet.csv"
    r = run_json(capsys, "--cycles", "2", "--export-sheet", str(sheet))
    with open(sheet, newline="") as f:
        rows = list(csv.reader(f))
    assert rows[0] == ["frame", "picture", "time"] and len(rows) == 23
    assert [int(x[1]) for x in rows[1:]] == r["exposure"]
    assert float(rows[-1][2]) == pytest.approx(21 / 24)


def test_pose_sample_write_and_compare(tmp_path, capsys):
    from hairtool.io import read

    out = tmp_path / "cycle.npz"
    r = run_json(capsys, "sample:portrait:20:10", str(out), "--cycles", "2", "--seed", "3")
    assert r["strands"] == 20 and r["vertices"] == 200 and r["output_frames"] == 22
    anim = read(out)
    assert anim.n_frames == 22 and anim.fps == 24.0
    assert not np.any(anim.frames[..., 2])
    # the same command compared with its own output: zero error; a different seed: some error
    r = run_json(capsys, "sample:portrait:20:10", "--seed", "3", "--compare", str(out))
    assert r["compare"]["angular_error_deg"] == pytest.approx(0.0, abs=1e-3)
    assert r["compare"]["frames_compared"] == 11
    r = run_json(capsys, "sample:portrait:20:10", "--seed", "4", "--compare", str(out))
    assert r["compare"]["angular_error_deg"] > 0.1


def test_guides_and_sway_on_a_real_groom(grooms_dir, capsys):
    r = run_json(
        capsys,
        str(grooms_dir / "sintel_hair.tfx"),
        "--guides",
        "0,10-20,100",
        "--sway",
        "1,0,0",
        "--hold",
        "3",
    )
    assert r["strands"] == 228 and r["n_pictures"] == 4


def test_parse_ids():
    assert parse_ids("0,5,10-13") == [0, 5, 10, 11, 12, 13]
    assert parse_ids(" 7 ") == [7]
