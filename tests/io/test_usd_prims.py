"""Hair and eyebrows stay apart: each curve prim of a scene is frozen as a groom of its own,
``--prim`` picks prims (globs) and the others are written as they were, and render hair grows
from one picked prim at a time."""

from __future__ import annotations

import numpy as np
import pytest

from hairtool import io
from hairtool.cli import main
from hairtool.groom import Groom
from hairtool.metadata import CurvesPrim, Metadata
from hairtool.prims import join, per_prim, picked, split

HAIR, BROWS = "/root/Head/Hair/HairData", "/root/Face/Brows/BrowData"


def write_scene(path, prims=(HAIR, BROWS)) -> None:
    """Blender's layout of hair plus eyebrows: Z-up metres, the hair (Catmull-Rom, pinned, 10 cm
    strands) on a head moved by translate/rotate/scale ops, the brows (linear, 15 mm, their
    own colour) under another parent."""
    from pxr import Gf, Usd, UsdGeom, Vt

    stage = Usd.Stage.CreateNew(str(path))
    UsdGeom.SetStageUpAxis(stage, UsdGeom.Tokens.z)
    UsdGeom.SetStageMetersPerUnit(stage, 1.0)
    UsdGeom.Xform.Define(stage, "/root")
    head = UsdGeom.Xform.Define(stage, "/root/Head")
    head.AddTranslateOp().Set(Gf.Vec3d(0.0, 0.1, 1.6))
    head.AddRotateXYZOp().Set(Gf.Vec3f(5.0, 0.0, 20.0))
    head.AddScaleOp().Set(Gf.Vec3f(1.1, 1.1, 1.1))
    face = UsdGeom.Xform.Define(stage, "/root/Face")
    face.AddTranslateOp().Set(Gf.Vec3d(0.0, -0.09, 1.65))
    for path_, strands, n, length, basis in ((HAIR, 60, 8, 0.1, "catmullRom"), (BROWS, 16, 4, 0.015, None)):
        if path_ not in prims:
            continue
        UsdGeom.Xform.Define(stage, path_.rsplit("/", 1)[0])
        rng = np.random.default_rng(strands)  # (each prim its own draws: the same with or without the other)
        if basis:  # roots on the upper half of a 10 cm sphere, strands outward and down
            d = rng.normal(size=(strands, 3))
            d[:, 2] = np.abs(d[:, 2])
        else:  # two rows of brows, growing sideways
            across, up = rng.uniform(-1, 1, strands), rng.uniform(-0.2, 0.2, strands)
            d = np.column_stack([across, -np.ones(strands), up])
        d /= np.linalg.norm(d, axis=1, keepdims=True)
        roots = 0.1 * d if basis else np.column_stack([d[:, 0] * 0.03, np.zeros(strands), d[:, 2] * 0.01])
        grow = d + np.array([0.0, 0.0, -0.5]) if basis else np.tile([0.8, -0.2, 0.1], (strands, 1))
        grow /= np.linalg.norm(grow, axis=1, keepdims=True)
        t = np.linspace(0.0, length, n)
        pts = (roots[:, None, :] + t[None, :, None] * grow[:, None, :]).reshape(-1, 3).astype(np.float32)
        curves = UsdGeom.BasisCurves.Define(stage, path_)
        if basis:
            curves.CreateTypeAttr("cubic")
            curves.CreateBasisAttr(basis)
            curves.CreateWrapAttr("pinned")
        else:
            curves.CreateTypeAttr("linear")
        curves.CreateCurveVertexCountsAttr(Vt.IntArray([n] * strands))
        curves.CreatePointsAttr(Vt.Vec3fArray.FromNumpy(pts))
        curves.CreateWidthsAttr(Vt.FloatArray.FromNumpy(np.full(strands * n, 8e-5, np.float32)))
        curves.SetWidthsInterpolation("vertex")
        colour = (0.3, 0.2, 0.1) if basis else (0.05, 0.04, 0.03)
        colours = Vt.Vec3fArray.FromNumpy(np.tile(colour, (strands * n, 1)).astype(np.float32))
        curves.CreateDisplayColorPrimvar("vertex").Set(colours)
    stage.GetRootLayer().Save()


@pytest.fixture(scope="module")
def scenes(tmp_path_factory):
    d = tmp_path_factory.mktemp("prims")
    write_scene(d / "both.usda")
    write_scene(d / "hair.usda", (HAIR,))
    write_scene(d / "brows.usda", (BROWS,))
    return d


def strand_lengths(g: Groom) -> np.ndarray:
    seg = np.linalg.norm(np.diff(g.points.astype(np.float64), axis=0), axis=1)
    seg[g.offsets[1:-1] - 1] = 0.0  # (the steps from one strand's tip to the next root)
    return np.add.reduceat(seg, g.offsets[:-1])


def test_each_prim_is_frozen_as_a_groom_of_its_own(scenes):
    d = scenes
    for name in ("both", "hair", "brows"):
        assert main(["freeze", str(d / f"{name}.usda"), str(d / f"{name}_frozen.usda"), "--seed", "5"]) == 0
    both = io.read(d / "both_frozen.usda")
    assert [(c.path, c.basis, c.wrap) for c in both.metadata.curves] == [
        (HAIR, "catmullRom", "pinned"),
        (BROWS, "linear", "nonperiodic"),
    ]
    hair, brows = split(both)
    np.testing.assert_array_equal(hair.points, io.read(d / "hair_frozen.usda").points)
    np.testing.assert_array_equal(brows.points, io.read(d / "brows_frozen.usda").points)
    np.testing.assert_array_equal(brows.colors, split(io.read(d / "both.usda"))[1].colors)
    assert strand_lengths(brows).max() < 0.025  # brows stay brows (15 mm, some stretch noise)


def authored_points(path, prim: str) -> bytes:
    from pxr import Sdf

    layer = Sdf.Layer.OpenAsAnonymous(str(path))  # (held: a spec of a freed layer is invalid)
    return np.asarray(layer.GetAttributeAtPath(prim + ".points").default).tobytes()


def test_prim_picks_prims_and_the_others_pass_through(scenes, capsys):
    d = scenes
    out = d / "brows_only.usda"
    assert main(["freeze", str(d / "both.usda"), str(out), "--prim", "/root/Face/*"]) == 0
    src_hair, src_brows = split(io.read(d / "both.usda"))
    hair, brows = split(io.read(out))
    # untouched: the source's authored points, byte for byte (not rewritten through the
    # parent's scale and rotation, which rounds them by an ULP)
    np.testing.assert_array_equal(hair.points, src_hair.points)
    assert authored_points(out, HAIR) == authored_points(d / "both.usda", HAIR)
    assert not np.array_equal(brows.points, src_brows.points)
    capsys.readouterr()
    assert main(["freeze", str(d / "both.usda"), str(d / "x.usda"), "--prim", "/root/Tail*"]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "/root/Tail*" in err and HAIR in err and BROWS in err
    assert not (d / "x.usda").exists()


def test_render_hair_grows_from_one_picked_prim(scenes, capsys):
    d = scenes
    capsys.readouterr()
    assert main(["freeze", str(d / "both.usda"), str(d / "c.usda"), "--count", "50"]) == 2
    err = capsys.readouterr().err.strip()
    assert "--prim" in err and HAIR in err and BROWS in err and not (d / "c.usda").exists()
    assert main(["freeze", str(d / "both.usda"), str(d / "c.usda"), "--count", "50", "--prim", HAIR]) == 0
    out = io.read(d / "c.usda")
    assert out.strand_count == 50 + 60


def test_split_and_join_are_inverse_and_work_sees_one_prim():
    meta = Metadata(curves=(CurvesPrim("/A", 2, "bspline"), CurvesPrim("/B", 1), CurvesPrim("/C", 2)))
    rng = np.random.default_rng(1)
    g = Groom(rng.standard_normal((5 * 4, 3)), [4] * 5, thickness=rng.uniform(0, 1, 20), metadata=meta)
    parts = split(g)
    assert [p.metadata.curves for p in parts] == [(c,) for c in meta.curves]
    back = join(parts, parts)
    assert back.points.tobytes() == g.points.tobytes() and back.metadata == meta
    seen = []
    out = per_prim(g, lambda p: seen.append(p.metadata.curves) or p.subset([0]), ["/A", "/C"])
    assert seen == [(meta.curves[0],), (meta.curves[2],)]
    assert out.metadata.curves == (CurvesPrim("/A", 1, "bspline"), CurvesPrim("/B", 1), CurvesPrim("/C", 1))
    assert picked(g, None) == [True] * 3 and picked(g, ["/?"]) == [True] * 3


def test_interpolate_grows_each_prims_children_into_its_own_render_prim(scenes, capsys):
    d = scenes
    assert main(["interpolate", str(d / "both.usda"), str(d / "kids.usda"), "--count", "100"]) == 0
    out = io.read(d / "kids.usda")
    got = [(c.path, c.strands, c.basis, c.purpose) for c in out.metadata.curves]
    assert got == [
        (HAIR + "Render", 79, "catmullRom", "default"),
        (HAIR, 60, "catmullRom", "guide"),
        (BROWS + "Render", 21, "linear", "default"),
        (BROWS, 16, "linear", "guide"),
    ]
    hair_kids, hair, brow_kids, brows = split(out)
    for kids, guides in ((hair_kids, hair), (brow_kids, brows)):
        lo, hi = guides.bounds
        pad = 0.25 * float(np.linalg.norm(hi - lo))
        assert np.all(kids.roots >= lo - pad) and np.all(kids.roots <= hi + pad)
    assert strand_lengths(brow_kids).max() < 0.025  # brows' children are brows
    assert (
        main(["interpolate", str(d / "both.usda"), str(d / "b.usda"), "--count", "30", "--prim", BROWS]) == 0
    )
    out = io.read(d / "b.usda")
    assert [(c.path, c.strands, c.purpose) for c in out.metadata.curves] == [
        (HAIR, 60, "default"),
        (BROWS + "Render", 30, "default"),
        (BROWS, 16, "guide"),
    ]
    np.testing.assert_allclose(
        split(out)[0].points, split(io.read(d / "both.usda"))[0].points, rtol=0, atol=4e-7
    )
    capsys.readouterr()
    assert (
        main(["interpolate", str(d / "both.usda"), str(d / "x.usda"), "--from-dense", "--guides", "5"]) == 2
    )
    err = capsys.readouterr().err
    assert "--prim" in err and HAIR in err and not (d / "x.usda").exists()


def test_deleting_every_strand_of_a_prim_keeps_it_empty(scenes, capsys):
    """As Blender keeps an empty Curves object: the brows' prim stays, with no curves, beside
    the hair; the command says so in one line, and the next command carries it through."""
    import json

    d = scenes
    brows = split(io.read(d / "both.usda"))[1]
    centre = (brows.points.min(axis=0) + brows.points.max(axis=0)) / 2
    sample = {"cursor": centre.tolist(), "direction": [0, 0, 0], "radius": 1.0, "strength": 1.0}
    log = [{"brush": "delete", "falloff": "smooth", "symmetry": None, "params": {}, "samples": [sample]}]
    (d / "gone.json").write_text(json.dumps(log))
    out = d / "no_brows.usda"
    capsys.readouterr()
    args = [
        "freeze",
        str(d / "both.usda"),
        str(out),
        "--prim",
        "/root/Face/*",
        "--strokes",
        str(d / "gone.json"),
    ]
    assert main(args) == 0
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and BROWS in err[0] and "kept empty" in err[0]
    hair = io.read(out)
    assert [c.path for c in hair.metadata.curves] == [HAIR]
    assert hair.points.tobytes() == split(io.read(d / "both.usda"))[0].points.tobytes()
    from pxr import Sdf

    layer = Sdf.Layer.OpenAsAnonymous(str(out))
    assert list(layer.GetAttributeAtPath(BROWS + ".curveVertexCounts").default) == []
    assert main(["convert", str(out), str(d / "again.usdc")]) == 0
    again = Sdf.Layer.OpenAsAnonymous(str(d / "again.usdc"))
    assert list(again.GetAttributeAtPath(BROWS + ".curveVertexCounts").default) == []
    # every prim emptied: refused in one line
    assert main(["freeze", str(d / "both.usda"), str(d / "x.usda"), "--strokes", str(d / "gone.json")]) == 2
