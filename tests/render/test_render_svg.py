"""SVG export: one polyline per strand at the pixel coordinates Camera.project gives."""

from __future__ import annotations

import xml.etree.ElementTree as ET

import numpy as np
import pytest

from app.render.camera import Camera
from app.render.ramps import RAMPS, per_strand_random_colors, strand_to_vertex_colors
from app.render.svg import groom_svg, save_svg
from hairtool import samples
from hairtool.errors import ParameterError

NS = {"svg": "http://www.w3.org/2000/svg"}
SIZE = (300, 200)


def _polylines(text: str) -> list[ET.Element]:
    return ET.fromstring(text).findall(".//svg:polyline", NS)


def _points(line: ET.Element) -> np.ndarray:
    return np.array([[float(v) for v in pair.split(",")] for pair in line.get("points").split()])


@pytest.mark.parametrize("make", [samples.portrait, samples.scalp], ids=["portrait", "scalp"])
def test_one_polyline_per_strand_at_projected_coordinates(make):
    g = make(strands=25, vertices=7)
    cam = Camera.for_groom(g, aspect=SIZE[0] / SIZE[1])
    text = groom_svg(g, cam, SIZE)
    root = ET.fromstring(text)
    assert root.get("width") == "300" and root.get("height") == "200"
    lines = _polylines(text)
    assert len(lines) == g.strand_count
    assert sorted(int(ln.get("data-strand")) for ln in lines) == list(range(g.strand_count))
    px = cam.project(g.points, *SIZE)
    for ln in lines:
        s = int(ln.get("data-strand"))
        np.testing.assert_allclose(_points(ln), px[g.offsets[s] : g.offsets[s + 1]], atol=0.006)


def test_root_to_tip_gradient_uses_the_ramp():
    g = samples.portrait(strands=3, vertices=6)
    cam = Camera.for_groom(g)
    root = ET.fromstring(groom_svg(g, cam, SIZE, ramp="root-tip"))
    gradients = root.findall(".//svg:linearGradient", NS)
    assert len(gradients) == 3
    first = _polylines(ET.tostring(root, encoding="unicode"))[0]
    gid = first.get("stroke")[len("url(#") : -1]
    grad = next(gr for gr in gradients if gr.get("id") == gid)
    stops = grad.findall("svg:stop", NS)
    offsets = [float(st.get("offset")) for st in stops]
    assert offsets[0] == 0.0 and offsets[-1] == 1.0 and offsets == sorted(offsets)
    hexes = [st.get("stop-color") for st in stops]
    expected = [
        "#{:02x}{:02x}{:02x}".format(*np.round(RAMPS["root-tip"][i] * 255).astype(int)) for i in (0, -1)
    ]
    assert [hexes[0], hexes[-1]] == expected
    # The gradient axis runs from the strand's root pixel to its tip pixel.
    pts = _points(first)
    np.testing.assert_allclose([float(grad.get("x1")), float(grad.get("y1"))], pts[0], atol=0.006)
    np.testing.assert_allclose([float(grad.get("x2")), float(grad.get("y2"))], pts[-1], atol=0.006)


def test_per_strand_colours_give_plain_strokes_and_background():
    g = samples.comb(strands=4, vertices=5)
    colors = strand_to_vertex_colors(per_strand_random_colors(4, seed=1), g.topology)
    text = groom_svg(g, Camera.for_groom(g), SIZE, colors=colors, background=(1, 1, 1), line_width=3)
    assert "linearGradient" not in text and 'fill="#ffffff"' in text and 'stroke-width="3"' in text
    strokes = {int(ln.get("data-strand")): ln.get("stroke") for ln in _polylines(text)}
    for s in range(4):
        want = "#{:02x}{:02x}{:02x}".format(*np.round(colors[g.offsets[s]] * 255).astype(int))
        assert strokes[s] == want


def test_3d_strands_are_painted_back_to_front():
    g = samples.comb(strands=9, vertices=4)
    cam = Camera.for_groom(g)
    order = [int(ln.get("data-strand")) for ln in _polylines(groom_svg(g, cam, SIZE))]
    depth = [cam.depth(g.strand(s)).mean() for s in order]
    assert depth == sorted(depth, reverse=True)


def test_save_svg_writes_the_file(tmp_path):
    g = samples.portrait(strands=5, vertices=4)
    path = tmp_path / "hair.svg"
    save_svg(path, g, Camera.for_groom(g), SIZE)
    assert len(_polylines(path.read_text())) == 5
    with pytest.raises(ParameterError, match="size"):
        groom_svg(g, Camera(), (0, 10))
    with pytest.raises(ParameterError, match="colors"):
        groom_svg(g, Camera(), SIZE, colors=np.zeros((3, 3)))
