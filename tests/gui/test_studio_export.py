"""Stills and groom export from the window: PNG and SVG match the view; the edited groom round-trips."""

from __future__ import annotations

import re
import xml.etree.ElementTree as ET

import imageio.v3 as iio
import numpy as np
import pytest

from hairtool import io, samples

pytestmark = pytest.mark.gui


def test_png_export_matches_the_view(ui, make_window, tmp_path):
    w = make_window()
    ui.leave(w.viewport)
    view = ui.grab(w.viewport)
    path = tmp_path / "still.png"
    assert w.export_still(path), w.errors
    image = iio.imread(path)
    assert image.shape[:2] == view.shape[:2]
    a, b = ui.hair_mask(view), ui.hair_mask(image)
    iou = (a & b).sum() / (a | b).sum()
    assert iou > 0.8, iou
    mean_diff = np.abs(image[..., :3][a & b].astype(float) - view[a & b]).mean()
    assert mean_diff < 25, mean_diff

    big = tmp_path / "big.png"
    assert w.export_still(big, size=(320, 200), transparent=True)
    rgba = iio.imread(big)
    assert rgba.shape == (200, 320, 4)
    assert rgba[0, 0, 3] == 0 and rgba[..., 3].max() == 255


def test_svg_export_matches_the_view(make_window, tmp_path):
    w = make_window(groom=samples.portrait(strands=25, vertices=10))
    path = tmp_path / "still.svg"
    assert w.export_still(path), w.errors
    root = ET.parse(path).getroot()
    width, height = w.viewport_pixel_size()
    assert (root.get("width"), root.get("height")) == (str(width), str(height))
    lines = [e for e in root.iter() if e.tag.endswith("polyline")]
    assert len(lines) == 25
    expected = w.viewport.project(w.scene.result.points)
    for line in lines:
        s = int(line.get("data-strand"))
        xy = np.array(
            [[float(v) for v in p.split(",")] for p in re.split(r"\s+", line.get("points").strip())]
        )
        a, b = w.scene.result.offsets[s : s + 2]
        np.testing.assert_allclose(xy, expected[a:b], atol=0.05)


def test_svg_refused_for_3d_and_groom_export_round_trips(ui, make_window, tmp_path):
    w = make_window(groom=samples.scalp(strands=40, vertices=8))
    assert not w.export_still(tmp_path / "x.svg")
    assert "2-D" in w.errors[-1][1]
    v = w.viewport
    start = v.project(w.scene.result.tips[3:4])[0]
    ui.drag(v, start, start + np.array([50.0, 30.0]))
    out = tmp_path / "edited.usda"
    assert w.export_groom(out), w.errors
    np.testing.assert_allclose(io.read_groom(out).points, w.scene.result.points, atol=1e-6)
    assert w.scene.path is None  # exporting does not change the current file
