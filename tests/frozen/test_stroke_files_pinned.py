"""Stroke logs and projects written before the sample schema (main at fd8bb20, committed under
tests/data/strokes) read back to the same samples and are written again byte for byte."""

from __future__ import annotations

import io
import zipfile
from pathlib import Path

import numpy as np
import pytest

from hairtool import project as pf
from hairtool.frozen.strokes import read_strokes, strokes_from_log, write_strokes

DATA = Path(__file__).resolve().parent.parent / "data" / "strokes"
LOGS = ("align", "brushes", "mixed", "symmetry")
PROJECTS = ("align", "brushes", "mixed")


@pytest.mark.parametrize("name", LOGS)
def test_a_stroke_log_is_written_again_byte_for_byte(tmp_path, name):
    src = DATA / f"{name}.json"
    write_strokes(tmp_path / "again.json", read_strokes(src))
    assert (tmp_path / "again.json").read_bytes() == src.read_bytes()


def _npy(array: np.ndarray) -> bytes:
    buf = io.BytesIO()
    np.lib.format.write_array(buf, np.ascontiguousarray(array), allow_pickle=False)
    return buf.getvalue()


@pytest.mark.parametrize("name", PROJECTS)
def test_a_project_is_written_again_byte_for_byte(tmp_path, name):
    src = DATA / f"{name}.hairproj"
    back = pf.load(src)
    manifest, arrays = pf.manifest_and_arrays(back)
    with zipfile.ZipFile(src) as zf:
        import json

        old = json.loads(zf.read(pf.MANIFEST))
        members = {n: zf.read(n) for n in zf.namelist() if n != pf.MANIFEST}
    assert manifest["strokes"] == old["strokes"] and manifest["version"] == old["version"]
    assert manifest["arrays"] == old["arrays"]
    assert {n: _npy(a) for n, a in arrays.items()} == members


@pytest.mark.parametrize("name", PROJECTS)
def test_a_project_and_its_stroke_log_hold_the_same_samples(tmp_path, name):
    """Both files were written from one log: the project's samples, as a stroke log, are the
    log's bytes, and the log's strokes replay to the project's samples."""
    log = pf.load(DATA / f"{name}.hairproj").strokes
    write_strokes(tmp_path / "from_project.json", strokes_from_log(log))
    assert (tmp_path / "from_project.json").read_bytes() == (DATA / f"{name}.json").read_bytes()
    replayed = [s for stroke in read_strokes(DATA / f"{name}.json") for s in stroke.pipeline_samples(0.0)]
    assert tuple(replayed) == log
