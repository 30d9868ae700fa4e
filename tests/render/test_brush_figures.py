"""The manual's brush pictures are made by a script that strokes the portrait with every brush."""

from __future__ import annotations

import imageio.v3 as iio
import numpy as np
import pytest

from app.figures import brushes
from app.figures.sheet import GAP, LABEL_HEIGHT
from hairtool.frozen.brushes import BRUSHES


@pytest.mark.slow(seconds=15)  # warm about 2 s; a fresh clone compiles the brushes and the raster
def test_every_brush_gets_a_before_and_after_picture_that_differ(tmp_path, capsys):
    size = 64
    brushes.make([str(tmp_path), "--size", str(size)])
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(f"figure-brush-{b}.png" for b in BRUSHES)
    for name in BRUSHES:
        sheet = iio.imread(tmp_path / f"figure-brush-{name}.png")
        assert sheet.shape[:2] == (size + LABEL_HEIGHT + 2 * GAP, 2 * size + 3 * GAP), name
        before = sheet[GAP : GAP + size, GAP : GAP + size, :3]
        after = sheet[GAP : GAP + size, 2 * GAP + size : 2 * GAP + 2 * size, :3]
        assert np.count_nonzero(np.any(before != after, axis=-1)) > 20, f"{name}: the stroke shows"


def test_every_brush_has_a_stroke_and_the_head_is_a_closed_ring():
    from hairtool import samples

    strokes = brushes.strokes_for(samples.portrait(strands=90, vertices=20, seed=0))
    assert set(strokes) == set(BRUSHES)
    for name, (entries, caption) in strokes.items():
        assert name in [e["brush"] for e in entries] and all(e["samples"] for e in entries) and caption
    entries, caption = brushes.default_stroke("comb")  # a brush added later gets this one
    assert entries[0]["brush"] == "comb" and len(entries[0]["samples"]) > 1 and caption
    mesh = brushes.head_mesh()
    radial = np.linalg.norm(mesh.vertices[:, :2], axis=1)
    assert np.allclose(radial, samples.HEAD_RADIUS, atol=1e-6)
    assert np.allclose(np.einsum("ij,ij->i", mesh.normals[:, :2], mesh.vertices[:, :2]), radial, atol=1e-5)
    assert np.unique(mesh.faces).size == len(mesh.vertices)  # every vertex on a face: no gaps
