"""Frames made from a static source (``simulate``, ``anime``) start at the source's own start
time code: a Blender stage whose range starts at 1 gets its simulation at 1…N, one without a
range at 0…N−1."""

from __future__ import annotations

from pathlib import Path

import pytest

from hairtool.cli import main

BLENDER = Path(__file__).resolve().parents[1] / "data" / "interop" / "b.usda"  # static, no start authored


def _stage_with_start(tmp_path: Path, start: int | None) -> Path:
    text = BLENDER.read_text()
    if start is not None:
        authored = f'    upAxis = "Z"\n    startTimeCode = {start}\n    endTimeCode = {start + 23}\n'
        text = text.replace('    upAxis = "Z"\n', authored, 1)  # as Blender writes a range: both ends
    path = tmp_path / f"hair_{start}.usda"
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
