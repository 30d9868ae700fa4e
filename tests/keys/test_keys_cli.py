"""``hairtool keys``: inputs (animation, raw X, BVH), modes, --json, --out, --export, bad input."""

from __future__ import annotations

import csv
import itertools
import json
from pathlib import Path

import numpy as np
import pytest

from hairtool import samples
from hairtool.cli import main
from hairtool.io import write
from hairtool.simulate.sway import sway_animation


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    d = tmp_path_factory.mktemp("keys")
    anim = sway_animation(samples.scalp(40, 10, seed=0), 36, flick_frame=25)
    write(d / "anim.npz", anim)
    x = np.cumsum(np.random.default_rng(0).normal(size=(30, 3)), axis=0)
    np.savez(d / "x.npz", X=x)
    one = anim.with_frames(anim.frames[:1])
    write(d / "one.npz", one)
    bad = x.copy()
    bad[4, 1] = np.nan
    np.savez(d / "nan.npz", X=bad)
    return d, x


def run_json(capsys, *argv):
    assert main(["keys", *map(str, argv), "--json"]) == 0
    return json.loads(capsys.readouterr().out)


def test_raw_x_cost_is_the_sum_of_squared_errors(files, capsys):
    d, x = files
    out = run_json(capsys, d / "x.npz", "--keys", 6)
    keys = out["keys"]
    assert len(keys) == 6 and keys[0] == 0 and keys[-1] == 29
    sse = 0.0
    for a, b in itertools.pairwise(keys):
        for k in range(a + 1, b):
            s = (k - a) / (b - a)
            sse += np.sum((x[k] - (1 - s) * x[a] - s * x[b]) ** 2)
    assert out["cost"] == pytest.approx(sse, rel=1e-9)
    assert len(out["uniform"]["keys"]) == 6 and out["uniform"]["cost"] >= out["cost"]
    assert out["curve"][0][0] == 2 and [k for k, _ in out["curve"]] == list(range(2, 31))
    assert dict(out["curve"])[6] == pytest.approx(out["cost"])


@pytest.mark.parametrize(
    "argv",
    [
        ["--penalty", "2"],
        ["--budget", "10"],
        ["--max-error", "1"],
        ["--keys", "5", "--objective", "worst", "--interp", "hermite"],
        ["--keys", "5", "--curvature", "0.5"],
    ],
)
def test_every_mode_runs_on_raw_features(files, capsys, argv):
    d, _ = files
    out = run_json(capsys, d / "x.npz", *argv)
    assert out["keys"][0] == 0 and out["keys"][-1] == 29


def test_animation_with_out_and_usd_export(files, capsys):
    d, _ = files
    out = run_json(
        capsys,
        d / "anim.npz",
        "--keys",
        7,
        "--samples",
        8,
        "--tip-weight",
        3,
        "--out",
        d / "keys.json",
        "--export",
        d / "keys.usda",
    )
    assert out["params"]["features"]["samples"] == 8 and out["params"]["features"]["tip_weight"] == 3.0
    assert set(out["position_errors"]) == {"keys", "uniform"}
    record = json.loads((d / "keys.json").read_text())
    assert [k["frame"] for k in record["keys"]] == out["keys"]
    assert record["keys"][1]["time"] == pytest.approx(out["keys"][1] / 24.0)
    assert record["params"]["interp"] == "linear"  # the keys USD plays as they are
    from pxr import Usd, UsdGeom

    stage = Usd.Stage.Open(str(d / "keys.usda"))
    curves = next(UsdGeom.BasisCurves(p) for p in stage.Traverse() if p.IsA(UsdGeom.BasisCurves))
    assert [int(t) for t in curves.GetPointsAttr().GetTimeSamples()] == out["keys"]


def test_per_channel(files, capsys):
    d, _ = files
    out = run_json(capsys, d / "x.npz", "--per-channel", "--penalty", "1")
    assert len(out["channels"]) == 3 and all(c[0] == 0 and c[-1] == 29 for c in out["channels"])


@pytest.mark.slow(seconds=13)
def test_bvh_input(motion_dir, capsys):
    out = run_json(capsys, motion_dir / "freebvh.bvh", "--keys", 10)
    assert len(out["keys"]) == 10 and out["frames"] == 69
    assert out["position_errors"]["keys"]["mean"] <= out["position_errors"]["uniform"]["mean"] * 1.5
    q = run_json(capsys, motion_dir / "freebvh.bvh", "--keys", 10, "--bvh-features", "quaternion")
    assert len(q["keys"]) == 10


@pytest.mark.parametrize(
    "name,argv,needle",
    [
        ("x.npz", ["--keys", "1"], "keys=1"),
        ("x.npz", ["--keys", "31"], "keys=31"),
        ("x.npz", ["--penalty", "-1"], "penalty"),
        ("one.npz", ["--keys", "2"], "frame"),
        ("nan.npz", ["--keys", "3"], "non-finite"),
        ("missing.npz", [], "no such file"),
        ("x.npz", ["--per-channel", "--keys", "3"], "penalty"),
        ("x.npz", ["--export", "out.usda"], "export"),
    ],
)
def test_bad_input_exits_2_with_one_line(files, capsys, name, argv, needle):
    d, _ = files
    assert main(["keys", str(d / name), *argv]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and needle in err


@pytest.mark.parametrize(
    "mode", [["--keys", "6"], ["--penalty", "2"], ["--budget", "60"], ["--max-error", "30"]]
)
def test_pinned_and_excluded_frames_steer_every_mode(files, capsys, mode):
    d, _ = files
    out = run_json(capsys, d / "x.npz", *mode, "--pin", "7,20", "--exclude", "10-13")
    keys = set(out["keys"])
    assert {7, 20} <= keys and not keys & {10, 11, 12, 13}
    assert out["params"]["pins"] == [7, 20] and out["params"]["excludes"] == [10, 11, 12, 13]
    assert out["uniform"]["ignores"] == {"pins": 2, "excludes": 4}
    assert out["uniform"]["note"] == "the DP keys honour 2 pins and 4 exclusions, the uniform keys do not"
    free = run_json(capsys, d / "x.npz", *mode)
    assert "pins" not in free["params"] and set(free["uniform"]) == {"keys", "cost"}


def test_the_csv_sheet_marks_the_pinned_keys(files, tmp_path, capsys):
    d, _ = files
    out = tmp_path / "k.csv"
    assert main(["keys", str(d / "x.npz"), "--keys", "6", "--pin", "7,20", "--export", str(out)]) == 0
    with open(out, newline="", encoding="utf-8") as f:
        keyed = {int(r["frame"]): r["pinned"] for r in csv.DictReader(f) if r["key"] == "1"}
    assert len(keyed) == 6 and {f for f, pinned in keyed.items() if pinned == "1"} == {7, 20}
    assert set(keyed.values()) == {"0", "1"}


def test_the_printed_line_says_the_uniform_keys_ignore_the_pins(motion_dir, capsys):
    assert main(["keys", str(motion_dir / "pymo_walk.bvh"), "--keys", "10", "--pin", "10,55"]) == 0
    line = capsys.readouterr().out.strip()
    assert "(uniform " in line
    assert "; the DP keys honour 2 pins and 0 exclusions, the uniform keys do not)" in line


@pytest.mark.parametrize(
    ("argv", "words"),
    [
        (["--keys", "3", "--pin", "5,9"], "keys=3"),
        (["--exclude", "0"], "first (0)"),
        (["--exclude", "29"], "last (29)"),
        (["--pin", "4", "--exclude", "4"], "pin"),
        (["--pin", "x"], "pin"),
        (["--keys", "5", "--pin", "1-28"], "at least one frame left"),
    ],
)
def test_impossible_constraints_are_one_line(files, capsys, argv, words):
    d, _ = files
    assert main(["keys", str(d / "x.npz"), *argv]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and words in err


@pytest.mark.parametrize(
    "mode", [[], ["--keys", "2"], ["--penalty", "0.01"], ["--budget", "1e9"], ["--max-error", "1e9"]]
)
def test_excluding_every_inner_frame_gives_the_two_ends(files, capsys, mode):
    d, _ = files
    out = run_json(capsys, d / "x.npz", "--exclude", "1-28", *mode)
    assert out["keys"] == [0, 29] and out["params"]["excludes"] == list(range(1, 29))


def test_a_count_the_exclusions_cannot_meet_names_keys(files, capsys):
    d, _ = files
    assert main(["keys", str(d / "x.npz"), "--exclude", "1-28", "--keys", "3"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "keys=3 is invalid: expected 2, the only count with these pins" in err


def test_penalty_is_a_share_of_the_two_key_error_and_the_absolute_form_is_seed_003s(files, capsys):
    d, x = files
    two_key = run_json(capsys, d / "x.npz", "--keys", 2)["cost"]
    rel = run_json(capsys, d / "x.npz", "--penalty", 0.02)
    absolute = run_json(capsys, d / "x.npz", "--penalty-abs", 0.02 * two_key)
    assert rel["keys"] == absolute["keys"] and 2 < len(rel["keys"]) < 30
    assert rel["params"]["penalty"] == pytest.approx(0.02 * two_key)
    assert rel["params"]["penalty_share"] == 0.02 and "penalty_share" not in absolute["params"]
    # the same share means the same on data a thousand times larger (squared units 10⁶ larger)
    np.savez(d / "x1000.npz", X=x * 1000.0)
    assert run_json(capsys, d / "x1000.npz", "--penalty", 0.02)["keys"] == rel["keys"]


@pytest.mark.parametrize("flag", ["--penalty", "--penalty-abs"])
def test_a_price_per_key_with_the_worst_frame_objective_quotes_what_was_typed(files, capsys, flag):
    d, _ = files
    assert main(["keys", str(d / "x.npz"), flag, "0.5", "--objective", "worst"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and f"{flag[2:]}=0.5 is invalid" in err and "not worst" in err
    assert ("absolute" in err) == (flag == "--penalty")


def test_the_extremes_are_explained(files, capsys):
    d, _ = files
    every = run_json(capsys, d / "x.npz", "--penalty-abs", 0)
    assert len(every["keys"]) == 30 and every["note"].startswith("a key on every frame")
    two = run_json(capsys, d / "x.npz", "--penalty", 5)
    assert two["keys"] == [0, 29] and two["note"].startswith("two keys: no key saves more than its price")
    loose = run_json(capsys, d / "x.npz", "--budget", 1e9)
    assert loose["keys"] == [0, 29] and "already meet the error budget" in loose["note"]
    assert "note" not in run_json(capsys, d / "x.npz", "--keys", 5)
    assert main(["keys", str(d / "x.npz"), "--penalty-abs", "0"]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert len(lines) == 2 and lines[1].startswith("a key on every frame")


def test_the_default_count_is_the_knee(files, capsys):
    from hairtool.keys.session import knee_count

    d, _ = files
    out = run_json(capsys, d / "x.npz")
    assert out["params"]["count_rule"] == "knee"
    assert len(out["keys"]) == knee_count(np.array(out["curve"]))


def test_the_default_count_is_the_unconstrained_knee_and_holds_under_pins(motion_dir, capsys):
    walk = motion_dir / "mocapbank_walk.bvh"
    free = run_json(capsys, walk)
    keys = free["keys"]
    assert free["params"]["knee"] == len(keys) > 4
    pinned = run_json(capsys, walk, "--pin", f"{keys[3]},{keys[4]}")  # frames that are keys already
    assert pinned["keys"] == keys and pinned["cost"] == free["cost"] and "note" not in pinned
    old, new = keys[2], keys[2] + 5  # a move: pin the new frame, exclude the old one
    moved = run_json(capsys, walk, "--pin", new, "--exclude", old)
    assert len(moved["keys"]) == len(keys) and new in moved["keys"] and old not in moved["keys"]
    many = run_json(capsys, walk, "--pin", ",".join(str(f) for f in range(10, 400, 40)))
    assert len(many["keys"]) == 12
    assert many["note"] == f"12 keys, not the knee's {len(keys)}: the fewest these pins allow"


def test_a_progress_bar_on_a_terminal_only(files, capsys):
    import io as text_io

    from hairtool.cli._progress import ProgressBar

    stream = text_io.StringIO()
    bar = ProgressBar(enabled=True, stream=stream)
    bar(0.5, "cost table")
    bar(1.0, "done")
    bar.close()
    shown = stream.getvalue()
    assert "cost table" in shown and "[" + "#" * 14 + "-" * 14 + "]" in shown and shown.endswith("\r")
    quiet = text_io.StringIO()
    ProgressBar(stream=quiet)(0.5, "table")  # not a terminal: nothing
    assert quiet.getvalue() == ""
    d, _ = files
    assert main(["keys", str(d / "anim.npz"), "--keys", "5"]) == 0
    assert capsys.readouterr().err == ""  # piped stderr stays clean


def test_the_bar_moves_through_the_dp_and_is_gone_before_the_result(files, capsys, monkeypatch):
    import hairtool.cli.keys as keys_cli
    from hairtool.cli._progress import ProgressBar

    seen = []

    class Recording(ProgressBar):
        def __init__(self, enabled=None, stream=None):
            super().__init__(enabled=enabled is None, stream=stream)

        def __call__(self, fraction=None, stage=""):
            seen.append((fraction, stage))
            super().__call__(fraction, stage)

    monkeypatch.setattr(keys_cli, "ProgressBar", Recording)
    d, _ = files
    assert main(["keys", str(d / "anim.npz"), "--keys", "5", "--curve-keys", "60"]) == 0
    fractions = [f for f, _ in seen]
    assert fractions == sorted(fractions) and fractions[-1] == 1.0
    assert sum(stage == "keys" for _, stage in seen) >= 4  # the DP's blocks of layers
    err = capsys.readouterr().err
    assert err.endswith("\r") and "5 keys" not in err  # cleared; the result went to stdout


def test_storage_is_the_bytes_of_the_key_poses_in_the_inputs_own_format(files, tmp_path, capsys, monkeypatch):
    """Measured on a real file in the system's temp dir, deleted after; the --out record is the
    same with or without it."""
    import tempfile

    from hairtool.io import read

    scratch = tmp_path / "scratch"
    scratch.mkdir()
    monkeypatch.setattr(tempfile, "tempdir", str(scratch))
    d, _ = files
    write(tmp_path / "anim.usdc", read(d / "anim.npz"))
    for src in (d / "anim.npz", tmp_path / "anim.usdc"):
        out = run_json(capsys, src, "--keys", 5, "--storage", "--out", tmp_path / "with.json")
        anim, k = read(src), out["keys"]
        by_hand = tmp_path / f"by_hand{src.suffix}"
        write(by_hand, anim.with_frames(anim.frames[k], time_codes=anim.time_codes[k]))
        size, full = by_hand.stat().st_size, src.stat().st_size
        assert out["storage"] == {
            "format": src.suffix,
            "keys_only_bytes": size,
            "input_bytes": full,
            "ratio": size / full,
        }
        assert 0 < out["storage"]["ratio"] < 1 and list(scratch.iterdir()) == []
        run_json(capsys, src, "--keys", 5, "--out", tmp_path / "without.json")
        assert (tmp_path / "with.json").read_text() == (tmp_path / "without.json").read_text()
    assert main(["keys", str(src), "--keys", "5", "--storage"]) == 0
    assert f"keys only: {size} bytes as .usdc, " in capsys.readouterr().out
    assert run_json(capsys, d / "x.npz", "--keys", 5, "--storage")["storage"] is None  # raw features


def test_the_keys_record_keeps_the_sources_time_codes(tmp_path):
    # Blender's time codes 1…48
    src = Path(__file__).resolve().parents[1] / "data" / "interop" / "b_gnanim.usdc"
    assert main(["keys", str(src), "--keys", "5", "--out", str(tmp_path / "k.json")]) == 0
    record = json.loads((tmp_path / "k.json").read_text())
    codes = [k["time_code"] for k in record["keys"]]
    assert codes[0] == 1 and codes[-1] == 48 and len(codes) == 5
    assert record["keys"][0]["frame"] == 0


def test_more_frames_than_a_table_can_hold_are_one_line(tmp_path, capsys):
    from hairtool.groom import Animation

    g = samples.comb(strands=2, vertices=2)  # a small file of 50,000 still frames: 55.9 GiB of tables
    still = np.zeros((50_000, g.vertex_count, 3), np.float32)
    write(tmp_path / "long.npz", Animation(still, g.topology, 24.0))
    assert main(["keys", str(tmp_path / "long.npz"), "--keys", "4"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "at most 6688 frames" in err and "55.9 GiB" in err
