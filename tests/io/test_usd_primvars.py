"""Curve primvars of every interpolation and basis, and colour as DCCs write it."""

from __future__ import annotations

import numpy as np
import pytest

from hairtool.errors import FormatError
from hairtool.io import read, usd_basis
from hairtool.metadata import CurvesPrim

CASES = [
    ("linear", "nonperiodic", [2, 5, 3]),
    ("bezier", "nonperiodic", [4, 7, 10]),
    ("bezier", "periodic", [3, 6, 9]),
    ("bspline", "nonperiodic", [4, 5, 9]),
    ("catmullRom", "pinned", [2, 6, 12]),
    ("catmullRom", "periodic", [3, 4, 8]),
]


@pytest.mark.parametrize(("basis", "wrap", "counts"), CASES)
@pytest.mark.parametrize("interpolation", ["constant", "uniform", "varying", "vertex"])
@pytest.mark.parametrize("width", [1, 3])
def test_per_vertex_matches_the_curve_by_curve_twin(basis, wrap, counts, interpolation, width):
    counts = np.array(counts)
    assert usd_basis.fits(counts, basis, wrap)
    n = usd_basis.expected_count(interpolation, counts, basis, wrap)
    values = np.random.default_rng(1).uniform(0, 1, (n, width) if width > 1 else n)
    got = usd_basis.per_vertex(values, interpolation, counts, basis, wrap)
    want = usd_basis.per_vertex_reference(values, interpolation, counts, basis, wrap)
    assert got.shape == want.shape == ((int(counts.sum()), width) if width > 1 else (int(counts.sum()),))
    np.testing.assert_allclose(got, want, rtol=0, atol=1e-12)


def test_varying_counts_follow_the_schema():
    # One value per segment end: n for linear, (n−1)/3 + 1 for bezier, n − 2 for B-spline, n pinned.
    assert usd_basis.expected_count("varying", np.array([5]), "linear", "nonperiodic") == 5
    assert usd_basis.expected_count("varying", np.array([7]), "bezier", "nonperiodic") == 3
    assert usd_basis.expected_count("varying", np.array([6]), "bspline", "nonperiodic") == 4
    assert usd_basis.expected_count("varying", np.array([6]), "catmullRom", "pinned") == 6
    # Bezier varying values sit on control points 0, 3, 6 and are interpolated between them.
    v = usd_basis.per_vertex(np.array([0.0, 3.0, 9.0]), "varying", np.array([7]), "bezier", "nonperiodic")
    np.testing.assert_allclose(v, [0, 1, 2, 3, 5, 7, 9])
    # B-spline ones on control points 1 … n−2, held at the ends.
    v = usd_basis.per_vertex(np.array([1.0, 2.0]), "varying", np.array([4]), "bspline", "nonperiodic")
    np.testing.assert_allclose(v, [1, 1, 2, 2])


def test_fits():
    assert usd_basis.fits(np.array([4, 7]), "bezier", "nonperiodic")
    assert not usd_basis.fits(np.array([4, 5]), "bezier", "nonperiodic")
    assert not usd_basis.fits(np.array([3]), "bspline", "nonperiodic")
    assert usd_basis.fits(np.array([2]), "bspline", "pinned")


def _stage(path, body: str) -> None:
    path.write_text(f'#usda 1.0\n(\n    upAxis = "Z"\n)\ndef BasisCurves "C" {{\n{body}\n}}\n')


POINTS = "point3f[] points = [(0,0,0),(0,0,1),(0,0,2),(0,0,3),(1,0,0),(1,0,1),(1,0,2),(1,0,3)]"


@pytest.mark.parametrize(
    ("widths", "expect"),
    [
        ('float[] widths = [0.5] (interpolation = "constant")', [0.5] * 8),
        ('float[] widths = [0.1, 0.2] (interpolation = "uniform")', [0.1] * 4 + [0.2] * 4),
        ('float[] widths = [1, 2, 3, 4, 5, 6, 7, 8] (interpolation = "vertex")', list(range(1, 9))),
        ('float[] widths = [1, 3, 5, 7] (interpolation = "varying")', [1, 1, 3, 3, 5, 5, 7, 7]),
    ],
)
def test_widths_of_every_interpolation_on_bspline_curves(tmp_path, widths, expect):
    p = tmp_path / "w.usda"
    body = 'uniform token type = "cubic"\nuniform token basis = "bspline"\nint[] curveVertexCounts = [4, 4]\n'
    _stage(p, body + POINTS + "\n" + widths)
    g = read(p)
    np.testing.assert_allclose(g.thickness, expect, rtol=1e-6)
    assert g.metadata.curves == (CurvesPrim("/C", 2, "bspline", "nonperiodic"),)


def test_widths_that_do_not_fit_their_interpolation_are_refused(tmp_path):
    p = tmp_path / "w.usda"
    _stage(
        p,
        "int[] curveVertexCounts = [4, 4]\n"
        + POINTS
        + '\nfloat[] widths = [1, 2, 3] (interpolation = "uniform")',
    )
    with pytest.raises(FormatError, match="widths has 3 values; uniform interpolation needs 2"):
        read(p)


def test_colour_from_primvars_color3f_and_color4f_alpha_as_opacity(tmp_path):
    p = tmp_path / "c3.usda"
    counts = 'uniform token type = "linear"\nint[] curveVertexCounts = [4, 4]\n'
    _stage(
        p, counts + POINTS + '\ncolor3f[] primvars:color = [(1, 0, 0), (0, 1, 0)] (interpolation = "uniform")'
    )
    g = read(p)
    np.testing.assert_array_equal(g.colors, [[1, 0, 0]] * 4 + [[0, 1, 0]] * 4)
    assert g.transparency is None and g.metadata.color_primvar == "color"
    p = tmp_path / "c4.usda"
    _stage(
        p,
        counts + POINTS + '\ncolor4f[] primvars:color = [(0.2, 0.4, 0.6, 0.25)] (interpolation = "constant")',
    )
    g = read(p)
    np.testing.assert_allclose(g.colors, [[0.2, 0.4, 0.6]] * 8, rtol=1e-6)
    np.testing.assert_allclose(g.transparency, [0.75] * 8)
    # displayColor wins over a second colour primvar.
    p = tmp_path / "both.usda"
    both = '\ncolor3f[] primvars:color = [(1, 0, 0)] (interpolation = "constant")'
    both += '\ncolor3f[] primvars:displayColor = [(0, 0, 1)] (interpolation = "constant")'
    _stage(p, counts + POINTS + both)
    g = read(p)
    np.testing.assert_array_equal(g.colors, [[0, 0, 1]] * 8)
    assert g.metadata.color_primvar == "displayColor"


def test_a_cubic_basis_the_counts_cannot_draw_reads_as_linear(tmp_path):
    p = tmp_path / "b.usda"
    _stage(
        p,
        'uniform token type = "cubic"\nuniform token basis = "bezier"\nint[] curveVertexCounts = [3, 5]\n'
        + POINTS,
    )
    assert read(p).metadata.curves == (CurvesPrim("/C", 2, "linear", "nonperiodic"),)
