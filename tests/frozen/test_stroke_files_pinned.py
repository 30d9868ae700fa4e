"""Stroke logs and projects written before the sample schema (main at fd8bb20, committed under
tests/data/strokes) read back to the same samples and are written again byte for byte."""

from __future__ import annotations

import io
import zipfile
from pathlib import Path

import numpy as np
import pytest

from hairtool import project as pf
from hairtool.errors import FormatError
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


def _rewrite(src, dst, manifest_edit=None, member=None, array=None):
    """``src`` copied to ``dst`` with its manifest's strokes section edited or one member replaced."""
    import json

    with zipfile.ZipFile(src) as zin, zipfile.ZipFile(dst, "w") as zout:
        for name in zin.namelist():
            data = zin.read(name)
            if name == pf.MANIFEST and manifest_edit is not None:
                manifest = json.loads(data)
                manifest_edit(manifest["strokes"])
                data = json.dumps(manifest).encode()
            if name == member:
                data = _npy(array)
            zout.writestr(name, data)


@pytest.mark.parametrize(
    "edit, member, array, needle",
    [
        (lambda s: s.update(brushes=True), None, None, "unknown brush"),
        (lambda s: s.update(selection=["all", "lasso"]), None, None, "unknown selection"),
        (None, "strokes/pressure.npy", np.full(13, 1.5), "pressure"),
        (None, "strokes/mode.npy", np.full(13, 7), "mode"),
        (None, "strokes/box.npy", np.full((13, 21), 0.5), "box"),
        (None, "strokes/radius.npy", np.zeros(12), "radius"),
        (None, "strokes/view.npy", np.full((13, 3), np.nan), "view"),
    ],
)
def test_damaged_stroke_columns_are_one_error_naming_the_file(tmp_path, edit, member, array, needle):
    bad = tmp_path / "bad.hairproj"
    _rewrite(DATA / "mixed.hairproj", bad, edit, member, array)
    with pytest.raises(FormatError, match=needle) as e:
        pf.load(bad)
    assert "bad.hairproj" in str(e.value)
