"""hairtool.io.usda_check (curve arrays against their points, before usd-core parses the text)
and usd-core's diagnostics kept off stderr (through its trap, or through fd 2)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from hairtool.errors import FormatError
from hairtool.groom import Animation, Groom
from hairtool.io import read, usd, usda_check

from . import hostile

INTEROP = Path(__file__).resolve().parents[1] / "data" / "interop"


@pytest.fixture
def scan_everything(monkeypatch):
    """Scan small files too, and refuse any array over its points: the rules without their margins."""
    monkeypatch.setattr(usda_check, "MIN_SCAN_BYTES", 0)
    monkeypatch.setattr(usda_check, "FLOOR", 0)


def test_real_and_written_files_pass(tmp_path, scan_everything):
    for p in INTEROP.glob("*.usda"):  # Blender's: a head mesh beside the curves
        usda_check.check(p)
    rng = np.random.default_rng(1)
    counts = rng.integers(2, 9, 300)
    v = int(counts.sum())
    widths, colors = rng.uniform(0.1, 1, v), rng.uniform(0, 1, (v, 3))
    g = Groom(rng.standard_normal((v, 3)), counts, thickness=widths, colors=colors)
    usd.write(tmp_path / "g.usda", g)
    a = Animation(np.stack([g.points, g.points + 1]), g.topology, 24.0, thickness=widths)
    usd.write(tmp_path / "a.usda", a)
    for name in ("g.usda", "a.usda"):
        usda_check.check(tmp_path / name)
        read(tmp_path / name)
    usda_check.check(hostile.write_usda(tmp_path / "h.usda"))


@pytest.mark.parametrize(
    ("old", "new", "words"),
    [
        ("[0.1, 0.2]", "[" + "1, " * 8 + "1]", "line 16: widths holds 9 values for curves of at most 7"),
        ("= [4, 3]", "= [" + "2," * 9 + "2]", "curveVertexCounts holds 10"),
        ("widths = [0.1, 0.2]", "widths.timeSamples = {1: [1, 1], 2: [" + "1," * 9 + "1]}", "widths hold"),
        ('float[] widths = [0.1, 0.2] (interpolation = "uniform")',
         "color3f[] primvars:displayColor = [" + "(1, 0, 0), " * 8 + "(1, 0, 0)]", "displayColor holds 9"),
        ("}\n}\n", '}\n}\nover "Head" {\n over "Hair" {\n  float[] widths = [' + "1," * 9 + "1]\n }\n}\n",
         "widths holds 10 values for curves of at most 7 points"),
    ],
    ids=["widths", "counts", "time-samples", "colour", "over"],
)  # fmt: skip
def test_an_array_beyond_its_points(tmp_path, scan_everything, old, new, words):
    path = hostile.write_usda(tmp_path / "h.usda", old, new)
    with pytest.raises(FormatError, match=words):
        usda_check.check(path)


def test_a_file_of_too_many_braces_is_one_block(tmp_path, scan_everything, monkeypatch):
    monkeypatch.setattr(usda_check, "MAX_BRACES", 4)
    wide = hostile.write_usda(tmp_path / "w.usda", "[0.1, 0.2]", "[" + "1," * 7 + "1]")
    with pytest.raises(FormatError, match="line 16: widths holds 8 values for curves of at most 7 points"):
        usda_check.check(wide)  # against the file's largest points array
    usda_check.check(hostile.write_usda(tmp_path / "ok.usda"))


def test_strings_comments_and_composed_points(tmp_path, scan_everything):
    many = "[" + "1," * 99 + "1]"
    quoted = f'"Hair" (doc = "widths = {many} # }}")\n# widths = {many}\n'
    path = hostile.write_usda(tmp_path / "s.usda", '"Hair"', quoted)
    usda_check.check(path)  # the arrays in a string and a comment are not the prim's
    sublayer = "metersPerUnit = 1\n    subLayers = [@base.usda@]"
    other = hostile.write_usda(tmp_path / "o.usda", "metersPerUnit = 1", sublayer)
    text = other.read_text().replace("point3f[] points = [", "#")  # points from the sublayer
    other.write_text(text.replace("[0.1, 0.2]", many))
    usda_check.check(other)  # may be the sublayer's points: not judged here


@pytest.mark.parametrize("trap", [True, False], ids=["DiagnosticTrap", "fd-2"])
def test_usd_core_diagnostics_kept_off_stderr(tmp_path, capfd, monkeypatch, trap):
    from pxr import Tf

    if not trap:
        monkeypatch.delattr(Tf, "DiagnosticTrap", raising=False)  # a usd-core without one
    reads = hostile.write_usda(tmp_path / "r.usda", "{1: 0, 2: 30}", "{1: 0, 99999999999999999999999: 30}")
    refused = hostile.write_usda(tmp_path / "f.usda", "[4, 3]", "[4, " + "9" * 30 + "]")
    capfd.readouterr()
    assert read(reads).n_frames == 2
    with pytest.raises(FormatError, match=r"usd-core warned: Integer literal '9+' on line 14"):
        read(refused)
    assert capfd.readouterr().err == ""
