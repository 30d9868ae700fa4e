"""Stroke logs: written, read back and replayed through ``hairtool freeze --strokes``, they give
the bytes of the pipeline that recorded them; older and newer logs stay readable; a bad log is
one line naming the file and the entry."""

from __future__ import annotations

import json

import numpy as np
import pytest

from hairtool import io, samples
from hairtool.cli import main
from hairtool.errors import FormatError, ParameterError
from hairtool.frozen.brushes import BrushSample, falloff_lut
from hairtool.frozen.pipeline import AlignSample, FrozenParams, FrozenPipeline
from hairtool.frozen.strokes import (
    Stroke,
    StrokeSample,
    read_strokes,
    stroke_from_dict,
    strokes_from_log,
    write_strokes,
)


def studio_session(groom):
    """A pipeline an artist worked in: align, a comb with a custom curve, a mask, smooth, length."""
    pipe = FrozenPipeline(groom, FrozenParams(seed=4))
    tips = groom.points[groom.topology.tip_indices].astype(np.float64)
    c, r = tips[len(tips) // 2], 0.5 * float(np.ptp(groom.points, axis=0).max())
    curve = tuple(falloff_lut([[0, 1], [0.3, 0.9], [1, 0]]).tolist())
    pipe.align(c + np.array([0.2, 0.3, 0.0]), r, 0.7)
    for k in range(3):
        pipe.brush(BrushSample("comb", tuple(c + k * 0.05), (0.05, 0.02, 0.0), r, 0.9, curve))
    constant = tuple(falloff_lut("constant").tolist())
    pipe.brush(BrushSample("mask", tuple(tips[3]), (0, 0, 0), 0.3 * r, 1.0, constant))
    pipe.brush(BrushSample("smooth", tuple(c), (0, 0, 0), r, 0.6, tuple(falloff_lut("linear").tolist())))
    pipe.brush(BrushSample("length", tuple(c), (0, 0, 0), r, -0.2, tuple(falloff_lut("smooth").tolist())))
    pipe.settle()  # the mouse released: the whole groom clumped (brush-local moves before)
    return pipe


def test_an_exported_log_replays_to_the_studios_bytes(tmp_path):
    groom = samples.scalp(150, 12, seed=2)
    io.write(tmp_path / "groom.npz", groom)
    pipe = studio_session(groom)
    strokes = strokes_from_log(pipe.strokes)
    assert [s.brush for s in strokes] == ["align", "comb", "mask", "smooth", "length"]
    write_strokes(tmp_path / "strokes.json", strokes)
    raw = json.loads((tmp_path / "strokes.json").read_text())
    assert isinstance(raw, list) and raw[1]["brush"] == "comb" and len(raw[1]["samples"]) == 3
    assert raw[3]["falloff"] == "linear"
    out = tmp_path / "replayed.npz"
    assert main(["freeze", str(tmp_path / "groom.npz"), str(out), "--seed", "4", "--strokes",
                 str(tmp_path / "strokes.json")]) == 0
    np.testing.assert_array_equal(io.read(out).points, pipe.result.points)


def test_symmetry_and_defaults_in_a_hand_written_log(tmp_path):
    log = [
        {
            "brush": "puff",
            "symmetry": "x",
            "samples": [{"cursor": [0.3, 0.2, 0.1], "radius": 2.0, "strength": 0.5}],
        },
        {"brush": "comb", "future_field": 7, "samples": [
            {"cursor": [0.0, 0.5, 0.0], "direction": [0.1, 0, 0], "radius": 1.0, "strength": 0.4}]},
    ]
    (tmp_path / "s.json").write_text(json.dumps(log))
    strokes = read_strokes(tmp_path / "s.json")
    assert strokes[0].falloff == "smooth" and strokes[0].samples[0].direction == (0.0, 0.0, 0.0)
    samples_ = strokes[0].pipeline_samples(default_mirror_x=1.0)
    assert len(samples_) == 2 and samples_[1].cursor == (1.7, 0.2, 0.1)  # mirrored across x = 1


@pytest.mark.parametrize(
    ("log", "words"),
    [
        ("{", "not a readable stroke log"),
        ('{"brush": "comb"}', "a JSON list of strokes"),
        ('[{"brush": "frizz", "samples": []}]', "strokes[0].brush"),
        ('[{"brush": "comb", "samples": [{"cursor": [0, 0], "radius": 1, "strength": 0.5}]}]', "cursor"),
        ('[{"brush": "comb", "samples": [{"cursor": [0, 0, 0], "radius": 1, "strength": 5}]}]', "strength"),
        ('[{"brush": "comb", "falloff": "bumpy", "samples": []}]', "falloff"),
        ('[{"brush": "comb", "symmetry": "y", "samples": []}]', "symmetry"),
        ('[{"brush": "comb", "samples": [{"cursor": [0, 0, 0], "radius": 1, "strength": 0.5, '
         '"pressure": 1.5}]}]', "strokes[0].samples[0].pressure"),
        ('[{"brush": "align", "samples": [{"cursor": [0, 0, 0], "radius": 1, "strength": 0.5, '
         '"pressure": "hard"}]}]', "strokes[0].samples[0].pressure"),
    ],
)
def test_bad_logs_are_one_line(tmp_path, capsys, log, words):
    (tmp_path / "bad.json").write_text(log)
    io.write(tmp_path / "g.npz", samples.comb(strands=4, vertices=4))
    with pytest.raises(FormatError, match=r"bad\.json"):
        for s in read_strokes(tmp_path / "bad.json"):
            s.pipeline_samples(0.0)
    argv = ["freeze", str(tmp_path / "g.npz"), str(tmp_path / "o.npz")]
    argv += ["--strokes", str(tmp_path / "bad.json")]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and words in err and not (tmp_path / "o.npz").exists()


def test_brush_strokes_survive_a_project_round_trip(tmp_path):
    from hairtool import project as pf

    groom = samples.scalp(60, 10, seed=1)
    pipe = studio_session(groom)
    pf.save(tmp_path / "p.hairproj", pf.Project.from_pipeline(pipe))
    back = pf.load(tmp_path / "p.hairproj")
    assert back.strokes == pipe.strokes
    again = back.pipeline()
    np.testing.assert_array_equal(again.result.points, pipe.result.points)
    np.testing.assert_array_equal(again.locked, pipe.locked)


def test_stroke_sample_type():
    s = Stroke("length", (StrokeSample((0.0, 0.0, 0.0), 1.0, -0.5),))
    assert s.pipeline_samples(0.0)[0].strength == -0.5


def painted_session(groom):
    """Front-facing samples (a camera on +z) and clump strokes painting clumping off and on."""
    pipe = FrozenPipeline(groom, FrozenParams(seed=6))
    tips = groom.points[groom.topology.tip_indices].astype(np.float64)
    c, r = tips[len(tips) // 2], 0.5 * float(np.ptp(groom.points, axis=0).max())
    smooth, linear = tuple(falloff_lut("smooth").tolist()), tuple(falloff_lut("linear").tolist())
    view = (0.0, -0.2, -1.0)
    pipe.align(c + np.array([0.2, 0.3, 0.0]), r, 0.7)
    pipe.apply_samples([AlignSample(tuple(c), r, 0.5, "paper", view)])
    pipe.brush(BrushSample("comb", tuple(c), (0.05, 0.02, 0.0), r, 0.9, smooth, view))
    pipe.brush(BrushSample("clump", tuple(c), (0, 0, 0), r, -0.8, linear, view))
    pipe.brush(BrushSample("clump", tuple(tips[5]), (0, 0, 0), 0.5 * r, 0.6, smooth))
    pipe.settle()  # the mouse released
    return pipe


def test_views_and_clump_strokes_round_trip_through_json_and_the_cli(tmp_path):
    groom = samples.scalp(150, 12, seed=2)
    io.write(tmp_path / "groom.npz", groom)
    pipe = painted_session(groom)
    strength = pipe.clump_strength
    assert strength.min() < 0.9 and np.all((strength >= 0) & (strength <= 1))
    strokes = strokes_from_log(pipe.strokes)
    assert [s.brush for s in strokes] == ["align", "comb", "clump", "clump"]
    assert strokes[0].samples[0].view is None and strokes[0].samples[1].view == (0.0, -0.2, -1.0)
    write_strokes(tmp_path / "strokes.json", strokes)
    raw = json.loads((tmp_path / "strokes.json").read_text())
    assert raw[2]["samples"][0]["view"] == [0.0, -0.2, -1.0] and raw[3]["samples"][0]["view"] is None
    back = read_strokes(tmp_path / "strokes.json")
    assert back == strokes
    replay = FrozenPipeline(groom, FrozenParams(seed=6))
    for s in back:
        replay.apply_samples(s.pipeline_samples(float(replay.scalp_centre[0])))
    assert replay.strokes == pipe.strokes
    np.testing.assert_array_equal(replay.clump_strength, strength)
    out = tmp_path / "replayed.npz"
    argv = ["freeze", str(tmp_path / "groom.npz"), str(out), "--seed", "6"]
    assert main([*argv, "--strokes", str(tmp_path / "strokes.json")]) == 0
    np.testing.assert_array_equal(io.read(out).points, pipe.result.points)


def test_an_older_log_without_views_reads_as_none(tmp_path):
    comb = {"cursor": [0.1, 0.2, 0.3], "direction": [0.1, 0, 0], "radius": 1.0, "strength": 0.4}
    log = [
        {"brush": "comb", "falloff": "linear", "symmetry": "x", "mirror_x": 0.5, "samples": [comb]},
        {"brush": "align", "samples": [{"cursor": [0, 1, 0], "radius": 1.0, "strength": 0.3, "view": None}]},
    ]
    (tmp_path / "old.json").write_text(json.dumps(log))
    comb, align = read_strokes(tmp_path / "old.json")
    first, mirrored = comb.pipeline_samples(0.0)
    assert first.view is None and mirrored.view is None and align.pipeline_samples(0.0)[0].view is None


def test_a_symmetric_stroke_mirrors_its_view():
    s = Stroke("puff", (StrokeSample((0.3, 0.0, 0.0), 1.0, 0.5, view=(0.6, 0.0, -0.8)),), symmetry="x")
    first, mirrored = s.pipeline_samples(1.0)
    assert first.view == (0.6, 0.0, -0.8) and mirrored.view == (-0.6, 0.0, -0.8)
    a = Stroke("align", (StrokeSample((0.3, 0.0, 0.0), 1.0, 0.5, view=(0.6, 0.0, -0.8)),), symmetry="x")
    assert a.pipeline_samples(1.0)[1].view == (-0.6, 0.0, -0.8)


def test_views_and_clump_strokes_survive_a_project_round_trip(tmp_path):
    from hairtool import project as pf

    groom = samples.scalp(60, 10, seed=1)
    pipe = painted_session(groom)
    pf.save(tmp_path / "p.hairproj", pf.Project.from_pipeline(pipe))
    back = pf.load(tmp_path / "p.hairproj")
    assert back.strokes == pipe.strokes
    again = back.pipeline()
    np.testing.assert_array_equal(again.result.points, pipe.result.points)
    np.testing.assert_array_equal(again.clump_strength, pipe.clump_strength)


@pytest.mark.parametrize("big", [10**400, -(10**5000)], ids=["10^400", "-10^5000"])
def test_an_integer_beyond_float64_is_refused_before_float(big):
    """Through the API too (a file's numbers are bounded earlier, by their digits)."""
    stroke = {"brush": "comb", "samples": [{"cursor": [0, 0, 0], "radius": big, "strength": 0.5}]}
    with pytest.raises(ParameterError, match=r"radius='an integer of about \d+ digits'"):
        stroke_from_dict(stroke)
    stroke["samples"][0]["radius"] = 10**300  # within float64: a radius, just a large one
    assert stroke_from_dict(stroke).samples[0].radius == 1e300


def pen_session(groom):
    """Samples drawn with a pen: radius and strength already scaled by its pressure (the
    studio's), align and brush samples, one at full pressure."""
    pipe = FrozenPipeline(groom, FrozenParams(seed=3))
    tips = groom.points[groom.topology.tip_indices].astype(np.float64)
    c, r = tips[len(tips) // 2], 0.5 * float(np.ptp(groom.points, axis=0).max())
    smooth = tuple(falloff_lut("smooth").tolist())
    pipe.apply_samples([AlignSample(tuple(c), r * 0.4, 0.7 * 0.4, "paper", pressure=0.4)])
    for k, p in enumerate((0.8, 0.3, 1.0)):
        pipe.brush(BrushSample("comb", tuple(c + k * 0.05), (0.05, 0.0, 0.0), r, 0.9 * p, smooth, pressure=p))
    return pipe


def test_a_pens_pressure_is_kept_in_the_log_and_replays_to_the_bytes(tmp_path):
    groom = samples.scalp(150, 12, seed=2)
    io.write(tmp_path / "groom.npz", groom)
    pipe = pen_session(groom)
    strokes = strokes_from_log(pipe.strokes)
    write_strokes(tmp_path / "strokes.json", strokes)
    raw = json.loads((tmp_path / "strokes.json").read_text())
    assert [x["pressure"] for st in raw for x in st["samples"]] == [0.4, 0.8, 0.3, 1.0]
    back = read_strokes(tmp_path / "strokes.json")
    assert back == strokes
    replay = FrozenPipeline(groom, FrozenParams(seed=3))
    for st in back:
        replay.apply_samples(st.pipeline_samples(0.0))
    assert replay.strokes == pipe.strokes
    out = tmp_path / "replayed.npz"
    argv = ["freeze", str(tmp_path / "groom.npz"), str(out), "--seed", "3"]
    assert main([*argv, "--strokes", str(tmp_path / "strokes.json")]) == 0
    np.testing.assert_array_equal(io.read(out).points, pipe.result.points)


def test_an_older_log_without_pressure_reads_as_full_pressure(tmp_path):
    comb = {"cursor": [0.1, 0.2, 0.3], "direction": [0.1, 0, 0], "radius": 1.0, "strength": 0.4}
    log = [
        {"brush": "comb", "symmetry": "x", "samples": [comb]},
        {"brush": "align", "samples": [{"cursor": [0, 1, 0], "radius": 1.0, "strength": 0.3}]},
    ]
    (tmp_path / "old.json").write_text(json.dumps(log))
    comb, align = read_strokes(tmp_path / "old.json")
    assert [x.pressure for x in comb.pipeline_samples(0.0) + align.pipeline_samples(0.0)] == [1.0] * 3


def test_a_pens_pressure_survives_a_project_round_trip(tmp_path):
    from hairtool import project as pf

    groom = samples.scalp(60, 10, seed=1)
    pipe = pen_session(groom)
    pf.save(tmp_path / "p.hairproj", pf.Project.from_pipeline(pipe))
    back = pf.load(tmp_path / "p.hairproj")
    assert back.strokes == pipe.strokes and back.strokes[1].pressure == 0.8
    np.testing.assert_array_equal(back.pipeline().result.points, pipe.result.points)


def test_a_pressure_outside_0_1_is_refused():
    from hairtool.frozen.brushes import check_sample

    smooth = tuple(falloff_lut("smooth").tolist())
    sample = BrushSample("comb", (0.0, 0.0, 0.0), (1.0, 0.0, 0.0), 1.0, 0.5, smooth)

    for bad in (-0.1, 1.01, float("nan"), True):
        with pytest.raises(ParameterError, match="pressure"):
            check_sample(BrushSample(**{**sample.__dict__, "pressure": bad}))
