"""Frames made from a static source (``simulate``, ``anime``) start at the source's own start
time code: a Blender stage whose range starts at 1 gets its simulation at 1…N, one without a
range at 0…N−1."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from hairtool.cli import main

BLENDER = Path(__file__).resolve().parents[1] / "data" / "interop" / "b.usda"  # static, no start authored


def _stage_with_start(tmp_path: Path, start: int | None, ends: str = "both") -> Path:
    """Blender's groom with ``startTimeCode`` ``start`` and an end 23 later (``ends``: "both",
    as Blender writes a range; "start" or "end": that one alone)."""
    text = BLENDER.read_text()
    if start is not None:
        authored = '    upAxis = "Z"\n'
        authored += f"    startTimeCode = {start}\n" if ends != "end" else ""
        authored += f"    endTimeCode = {start + 23}\n" if ends != "start" else ""
        text = text.replace('    upAxis = "Z"\n', authored, 1)
    path = tmp_path / f"hair_{start}_{ends}.usda"
    path.write_text(text)
    return path


@pytest.mark.parametrize("command", [["simulate", "--motion", "nod"], ["anime"]], ids=lambda c: c[0])
@pytest.mark.parametrize("start", [None, 1, 101])
def test_output_time_codes_start_where_the_source_did(tmp_path, command, start):
    from pxr import Usd, UsdGeom

    src, out = _stage_with_start(tmp_path, start), tmp_path / "out.usda"
    assert main([command[0], str(src), str(out), "--frames", "4", *command[1:]]) == 0
    stage = Usd.Stage.Open(str(out))
    curves = next(UsdGeom.BasisCurves(p) for p in stage.Traverse() if p.IsA(UsdGeom.BasisCurves))
    first = 0 if start is None else start
    assert curves.GetPointsAttr().GetTimeSamples() == [float(first + f) for f in range(4)]
    assert stage.GetStartTimeCode() == first and stage.GetEndTimeCode() == first + 3


@pytest.mark.parametrize("ends", ["start", "end"])
def test_one_end_authored_alone_is_read_as_usd_reads_it(tmp_path, ends, capsys):
    """usd-core (and Blender's importer, which takes ``GetStartTimeCode`` as its first frame)
    starts a stage with ``startTimeCode = 101`` and no end at 101, and one with only an end at
    its fallback 0: the frames made from it start there too, and ``convert`` writes the end it
    authored, alone."""
    from pxr import Usd, UsdGeom

    src = _stage_with_start(tmp_path, 101, ends)
    first = Usd.Stage.Open(str(src)).GetStartTimeCode()
    assert first == (101.0 if ends == "start" else 0.0)
    out = tmp_path / "sim.usda"
    assert main(["anime", str(src), str(out), "--frames", "3"]) == 0
    stage = Usd.Stage.Open(str(out))
    curves = next(UsdGeom.BasisCurves(p) for p in stage.Traverse() if p.IsA(UsdGeom.BasisCurves))
    assert curves.GetPointsAttr().GetTimeSamples() == [first + f for f in range(3)]
    assert main(["convert", str(src), str(tmp_path / "c.usda")]) == 0
    written = Usd.Stage.Open(str(tmp_path / "c.usda"))  # (held: a freed stage's layer is invalid)
    layer = written.GetRootLayer()
    assert (layer.HasStartTimeCode(), layer.HasEndTimeCode()) == (ends == "start", ends == "end")
    kept = layer.startTimeCode if ends == "start" else layer.endTimeCode
    assert kept == (101.0 if ends == "start" else 124.0)
    capsys.readouterr()
    assert main(["info", str(src), "--json"]) == 0  # the end not authored is null
    shown = json.loads(capsys.readouterr().out)["usd"]["time_code_range"]
    assert shown == ([101.0, None] if ends == "start" else [None, 124.0])
