"""A guide prim's custom primvars reach its children's render prim: floats blended from the
guides with the binding's weights (per vertex and per curve), ints from the nearest guide,
constants copied, on a static and an animated stage of two prims."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from hairtool import io
from hairtool.cli import main
from hairtool.guides.attributes import blend_reference
from hairtool.guides.binding import bind_roots
from hairtool.prims import shares, split

from .test_animated_interpolate import two_prims
from .usd_scenes import write_stage


def add_primvars(path) -> None:
    from pxr import Sdf, Usd, UsdGeom, Vt

    stage = Usd.Stage.Open(str(path))
    pv = UsdGeom.PrimvarsAPI(stage.GetPrimAtPath("/Root0_0/Hair0"))
    pv.CreatePrimvar("strand_id", Sdf.ValueTypeNames.IntArray, "uniform").Set(
        Vt.IntArray([7, 8, 9, 10, 11, 12])
    )
    pv.CreatePrimvar("stiff", Sdf.ValueTypeNames.FloatArray, "uniform").Set(Vt.FloatArray([0, 1, 2, 3, 4, 5]))
    pv.CreatePrimvar("groom_name", Sdf.ValueTypeNames.String, "constant").Set("curly")
    stage.GetRootLayer().Save()


def primvar(path, prim: str, name: str):
    from pxr import Usd, UsdGeom

    stage = Usd.Stage.Open(str(path))  # (held: a prim of a freed stage is invalid)
    p = UsdGeom.PrimvarsAPI(stage.GetPrimAtPath(prim)).GetPrimvar(name)
    return (p.Get(), str(p.GetInterpolation())) if p else (None, None)


@pytest.mark.parametrize("animated", [None, "points"])
def test_children_get_their_guides_primvars(tmp_path, animated):
    write_stage(tmp_path / "s.usda", two_prims(animated))
    add_primvars(tmp_path / "s.usda")
    out = tmp_path / "k.usda"
    assert main(["interpolate", str(tmp_path / "s.usda"), str(out), "--count", "20", "--seed", "2"]) == 0
    src = io.read(tmp_path / "s.usda")
    hair = split(src.rest if hasattr(src, "rest") else src)[0]
    n = shares(20, [6, 4])[0]
    binding = bind_roots(hair, count=n, k=4, seed=2)
    render = "/Root0_0/Hair0Render"
    weight, _ = primvar(tmp_path / "s.usda", "/Root0_0/Hair0", "clump_weight")
    got, got_interp = primvar(out, render, "clump_weight")
    assert got_interp == "vertex" and len(got) == binding.vertex_count
    np.testing.assert_allclose(np.asarray(got), blend_reference(np.asarray(weight), binding), atol=1e-6)
    ids, _ = primvar(out, render, "strand_id")
    assert list(ids) == [7 + int(g) for g in binding.guide_ids[:, 0]]
    stiff, stiff_interp = primvar(out, render, "stiff")
    want = (binding.weights * np.arange(6.0)[binding.guide_ids]).sum(axis=1)
    assert stiff_interp == "uniform"
    np.testing.assert_allclose(np.asarray(stiff), want, atol=1e-6)
    assert primvar(out, render, "groom_name") == ("curly", "constant")
    assert primvar(out, "/Brows1Render", "clump_weight") == (None, None)  # the brows had none


@pytest.mark.parametrize("command", ["freeze", "simulate", "anime"])
def test_the_render_hair_of_freeze_simulate_and_anime_gets_them_too(tmp_path, command):
    scene = two_prims(None)
    write_stage(tmp_path / "s.usda", replace(scene, prims=scene.prims[:1]))
    add_primvars(tmp_path / "s.usda")
    out = tmp_path / "k.usda"
    extra = {"freeze": [], "simulate": ["--frames", "2", "--substeps", "1"], "anime": ["--frames", "2"]}
    assert main([command, str(tmp_path / "s.usda"), str(out), "--count", "9", *extra[command]]) == 0
    ids, interp = primvar(out, "/Root0_0/Hair0Render", "strand_id")
    assert interp == "uniform" and len(ids) == 9 and set(ids) <= set(range(7, 13))
    weight, _ = primvar(out, "/Root0_0/Hair0Render", "clump_weight")
    assert weight is not None and 0 <= min(weight) and max(weight) <= 1
