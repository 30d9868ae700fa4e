"""Rendered pictures against small stored references, with a tolerance for rasteriser drift.

The references were made on Mesa llvmpipe (EGL), with the strands drawn by GL (multisampled) and
by the CPU rasterizer (``*_cpu.png``, which auto picks on llvmpipe). After an intended change to
the look,
regenerate them with::

    HAIRTOOL_REGEN_REFERENCES=1 python -m pytest tests/render/test_render_reference_images.py

and look at the new PNGs in tests/render/reference/ before committing them. On a failure the
actual picture, the reference and an amplified difference are saved in tests/render/_failures/.
"""

from __future__ import annotations

import os
from pathlib import Path
from types import SimpleNamespace

import imageio.v3 as iio
import numpy as np
import pytest

from app.render.offscreen import render_image, save_png
from hairtool import samples

HERE = Path(__file__).resolve().parent
REFERENCES = HERE / "reference"
FAILURES = HERE / "_failures"
SIZE = (160, 160)
MEAN_ABS_TOLERANCE = 2.0  # per channel, of 255
DIFFERING_PIXEL = 48  # a pixel "differs" when some channel is off by more than this
MAX_DIFFERING_FRACTION = 0.01


def uv_sphere(radius: float = 1.0, rings: int = 16, segments: int = 24) -> SimpleNamespace:
    """A head stand-in: ``vertices``/``faces``/``normals`` like hairtool.io.obj's Mesh."""
    theta = np.linspace(0.0, np.pi, rings + 1)
    phi = np.linspace(0.0, 2.0 * np.pi, segments + 1)
    t, p = np.meshgrid(theta, phi, indexing="ij")
    normals = np.stack([np.sin(t) * np.cos(p), np.cos(t), np.sin(t) * np.sin(p)], axis=-1).reshape(-1, 3)
    faces = []
    for i in range(rings):
        for j in range(segments):
            a, b = i * (segments + 1) + j, (i + 1) * (segments + 1) + j
            faces += [[a, b, a + 1], [a + 1, b, b + 1]]
    return SimpleNamespace(
        vertices=(normals * radius).astype(np.float32),
        faces=np.array(faces, dtype=np.int32),
        normals=normals.astype(np.float32),
    )


def _compare(name: str, actual: np.ndarray) -> None:
    path = REFERENCES / f"{name}.png"
    if os.environ.get("HAIRTOOL_REGEN_REFERENCES") == "1":
        REFERENCES.mkdir(exist_ok=True)
        save_png(path, actual)
        pytest.skip(f"regenerated {path}")
    assert path.is_file(), f"missing reference {path}; set HAIRTOOL_REGEN_REFERENCES=1 to make it"
    expected = iio.imread(path)
    assert expected.shape == actual.shape
    diff = np.abs(actual.astype(np.int16) - expected.astype(np.int16))
    mean_abs = float(diff.mean())
    differing = float((diff.max(axis=2) > DIFFERING_PIXEL).mean())
    if mean_abs > MEAN_ABS_TOLERANCE or differing > MAX_DIFFERING_FRACTION:
        FAILURES.mkdir(exist_ok=True)
        save_png(FAILURES / f"{name}.actual.png", actual)
        save_png(FAILURES / f"{name}.expected.png", expected)
        amplified = np.clip(diff[..., :3] * 4, 0, 255).astype(np.uint8)
        save_png(FAILURES / f"{name}.diff.png", amplified)
        pytest.fail(
            f"{name}: mean abs diff {mean_abs:.2f} (limit {MEAN_ABS_TOLERANCE}), "
            f"{differing:.2%} pixels differ (limit {MAX_DIFFERING_FRACTION:.0%}); see {FAILURES}"
        )


@pytest.mark.parametrize("raster", ["gl", "cpu"])
def test_portrait_root_tip_matches_reference(raster):
    g = samples.portrait(strands=40, vertices=12, seed=0)
    img = render_image(g, size=SIZE, line_width=2.0, strand_raster=raster)
    _compare("portrait_root_tip" + ("_cpu" if raster == "cpu" else ""), img)


@pytest.mark.parametrize("raster", ["gl", "cpu"])
def test_scalp_with_head_mesh_matches_reference(raster):
    g = samples.scalp(strands=300, vertices=10, seed=0)
    img = render_image(g, size=SIZE, line_width=1.5, mesh=uv_sphere(0.98), strand_raster=raster)
    _compare("scalp_head_mesh" + ("_cpu" if raster == "cpu" else ""), img)


def test_comparison_catches_a_different_picture(monkeypatch, tmp_path):
    # The tolerance is loose enough for drift but not for a wrong picture: another seed fails.
    monkeypatch.delenv("HAIRTOOL_REGEN_REFERENCES", raising=False)
    monkeypatch.setattr(f"{__name__}.FAILURES", tmp_path)
    g = samples.portrait(strands=40, vertices=12, seed=5)
    with pytest.raises(pytest.fail.Exception, match="portrait_root_tip"):
        _compare("portrait_root_tip", render_image(g, size=SIZE, line_width=2.0, strand_raster="gl"))
    assert (tmp_path / "portrait_root_tip.diff.png").is_file()
