"""The density brush: under the brush no two roots end closer than the spacing and no point is
farther than twice it from a root, thinning a dense comb and filling a sparse one on a plane
and on Sintel's head; masked strands stay; the kernels equal their twins; replays are exact."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from hairtool import io, samples
from hairtool.cli import main
from hairtool.frozen.brushes import BrushSample, falloff_lut
from hairtool.frozen.density import accept, accept_reference, thin, thin_reference
from hairtool.frozen.pipeline import FrozenParams, FrozenPipeline
from hairtool.frozen.strokes import strokes_from_log, write_strokes
from hairtool.guides.planting import HeadSurface
from hairtool.io.obj import read_mesh

DATA = Path(__file__).resolve().parents[1] / "data" / "grooms"
PLAIN = FrozenParams(freeze=False, clump=False)
LUT = tuple(falloff_lut("smooth").tolist())


def density(cursor, radius, spacing, seed=0):
    c = tuple(map(float, cursor))
    return BrushSample("density", c, (0.0, 0.0, 0.0), radius, 1.0, LUT, spacing=spacing, seed=seed)


def check_spacing(g, surface, centre, radius, spacing):
    q, _ = surface.project(np.asarray(centre, np.float64).reshape(1, 3))
    roots = g.roots.astype(np.float64)
    inside = np.linalg.norm(roots - q[0], axis=1) < radius
    d = np.linalg.norm(roots[inside][:, None] - roots[None], axis=-1)
    d[d == 0] = np.inf
    assert d.min() >= spacing * (1 - 1e-6)  # no two roots closer than the spacing
    rng = np.random.default_rng(0)
    t, r = rng.uniform(0, 2 * np.pi, 1500), 0.95 * radius * np.sqrt(rng.random(1500))
    n = surface.project(q)[1][0]
    u = np.cross(n, np.eye(3)[int(np.argmin(np.abs(n)))])
    u /= np.linalg.norm(u)
    v = np.cross(n, u)
    probe, _ = surface.project(q[0] + r[:, None] * (np.cos(t)[:, None] * u + np.sin(t)[:, None] * v))
    gap = np.min(np.linalg.norm(probe[:, None] - roots[None], axis=-1), axis=1).max()
    assert gap <= 2.0 * spacing  # no gap larger than twice it
    return inside.sum()


@pytest.mark.parametrize("spacing", [0.12, 0.03])
def test_on_a_plane_the_comb_is_thinned_or_filled_to_the_spacing(plane, spacing):
    comb = samples.comb(100, 8)  # roots 0.05 apart
    surface = HeadSurface(plane)
    pipe = FrozenPipeline(comb, PLAIN, surface)
    c, r = (0.225, 0.0, 0.225), 0.15
    pipe.brush(density((0.225, -0.1, 0.225), 0.15, spacing))
    out = pipe.result
    assert (out.strand_count < 100) if spacing > 0.05 else (out.strand_count > 100)
    check_spacing(out, surface, c, r, spacing)
    far = np.linalg.norm(comb.roots - np.array(c), axis=1) >= r + spacing  # beyond reach: untouched
    assert np.isin(np.flatnonzero(far), pipe.origin).all()


def test_masked_strands_stay_and_sintel_reaches_the_spacing(tmp_path):
    groom = io.read_groom(DATA / "sintel_hair.tfx")
    surface = HeadSurface(read_mesh(DATA / "sintel_head.obj"))
    pipe = FrozenPipeline(groom, PLAIN, surface)
    c = groom.roots[40].astype(np.float64)
    pipe.brush(BrushSample("mask", tuple(c), (0, 0, 0), 0.5, 1.0, LUT))
    masked = np.flatnonzero(pipe.locked)
    pipe.brush(density(c, 3.0, 0.6, seed=2))
    assert np.isin(masked, pipe.origin).all()
    assert check_spacing(pipe.result, surface, c, 3.0, 0.6) >= 3
    io.write(tmp_path / "g.npz", groom)
    write_strokes(tmp_path / "s.json", strokes_from_log(pipe.strokes))
    args = ["freeze", str(tmp_path / "g.npz"), str(tmp_path / "o.npz"), "--no-freeze", "--no-clump"]
    args += ["--strokes", str(tmp_path / "s.json"), "--scalp", str(DATA / "sintel_head.obj")]
    assert main(args) == 0
    np.testing.assert_array_equal(io.read(tmp_path / "o.npz").points, pipe.result.points)


def test_the_kernels_match_their_twins():
    rng = np.random.default_rng(3)
    roots = rng.random((300, 3))
    fixed = rng.random(300) < 0.2
    np.testing.assert_array_equal(thin(roots, fixed, 0.1), thin_reference(roots, fixed, 0.1))
    cands = rng.random((400, 3))
    np.testing.assert_array_equal(accept(cands, roots[:50], 0.08), accept_reference(cands, roots[:50], 0.08))
    assert 0 < accept(cands, roots[:50], 0.08).sum() < 400
