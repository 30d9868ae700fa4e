"""The scene description (hairtool.metadata) through every command.

The Blender 5 export ``tests/data/interop/b.usda`` (Z-up, metres, ``/root/Head/Hair/HairData``,
Catmull-Rom pinned, ``primvars:color``) and its twin in Y-up centimetres (the same hair turned
into Y-up and scaled by 100) go through simulate, anime, interpolate, freeze, freeze --count,
convert through .npz and keys --export: each output keeps its input's space, prim paths, basis,
widths and colour primvar, and the two land at the same place in the world.
"""

from __future__ import annotations

import ast
from pathlib import Path

import numpy as np
import pytest

from hairtool import io
from hairtool.cli import main
from hairtool.groom import Animation, Groom
from hairtool.metadata import HAIR_WIDTH_M, CurvesPrim, Metadata
from hairtool.simulate.head_motion import head_motion

INTEROP = Path(__file__).resolve().parent / "data" / "interop"
HAIR = "/root/Head/Hair/HairData"
# The twins' float32 points round differently (cm vs m): almost every vertex agrees to 2 µm; a
# few amplify that rounding to a few tenths of a millimetre (a strand hanging nearly along up,
# whose bend axis chord × up is short and renormalised; a vertex just at the fitted head
# sphere, collided in one twin and not the other). A wrong axis or unit moves every strand by
# centimetres.
WORLD_TOL_M = 5e-4
TYPICAL_TOL_M = 2e-6


@pytest.fixture(scope="module")
def scenes(tmp_path_factory):
    d = tmp_path_factory.mktemp("scene")
    z = io.read(INTEROP / "b.usda")
    assert isinstance(z, Groom) and z.metadata.up_axis == "Z" and z.metadata.meters_per_unit == 1.0
    twin = z.metadata.with_(up_axis="Y", meters_per_unit=0.01)
    pts = (z.points.astype(np.float64) @ z.metadata.frame) / 0.01  # into y-up axes, in cm
    y = Groom(pts, z.topology, thickness=z.thickness / 0.01, colors=z.colors, metadata=twin)
    io.write(d / "y.usda", y)
    return {"z": INTEROP / "b.usda", "y": d / "y.usda", "dir": d}


def _world(obj) -> np.ndarray:
    """Points (every frame) in metres, in hairtool's reference axes (y up)."""
    a = obj.frames if isinstance(obj, Animation) else obj.points
    m = obj.metadata
    return (a.astype(np.float64) * m.meters_per_unit) @ m.frame


def _stage(path):
    """What pxr itself reads: (up axis, metres per unit, {prim path: authored facts})."""
    from pxr import Usd, UsdGeom

    stage = Usd.Stage.Open(str(path))
    prims = {}
    for p in stage.Traverse():
        if not p.IsA(UsdGeom.BasisCurves):
            continue
        c = UsdGeom.BasisCurves(p)
        authored = {a.GetName() for a in p.GetAuthoredAttributes()}
        prims[str(p.GetPath())] = {
            "type": c.GetTypeAttr().Get(),
            "basis": c.GetBasisAttr().Get(),
            "wrap": c.GetWrapAttr().Get(),
            "purpose": c.GetPurposeAttr().Get(),
            "widths": np.asarray(c.GetWidthsAttr().Get()) if "widths" in authored else None,
            "color": "primvars:color" in authored,
            "displayColor": "primvars:displayColor" in authored,
        }
    return str(UsdGeom.GetStageUpAxis(stage)), float(UsdGeom.GetStageMetersPerUnit(stage)), prims, stage


def _run(argv) -> None:
    assert main([str(a) for a in argv]) == 0


#: name → (command, options); every one reads IN and writes OUT.
COMMANDS = {
    "simulate": ("simulate", ["--frames", "4", "--motion", "nod", "--fit-head", "--gusts", "1"]),
    "simulate --count": ("simulate", ["--frames", "3", "--motion", "turn", "--fit-head", "--count", "40"]),
    "anime": ("anime", ["--frames", "4"]),
    "anime --count": ("anime", ["--frames", "3", "--count", "40"]),
    "interpolate": ("interpolate", ["--count", "40"]),
    "freeze": ("freeze", []),
    "freeze --count": ("freeze", ["--count", "40"]),
}
RENDER = {"simulate --count", "anime --count", "interpolate", "freeze --count"}


@pytest.mark.parametrize("name", list(COMMANDS))
def test_every_command_keeps_the_scene_and_lands_at_the_same_place_from_z_up_m_and_y_up_cm(scenes, name):
    command, options = COMMANDS[name]
    results = {}
    for src, (up, mpu) in {"z": ("Z", 1.0), "y": ("Y", 0.01)}.items():
        out = scenes["dir"] / f"{name.replace(' --', '_')}_{src}.usda"
        _run([command, scenes[src], out, *options])
        stage_up, stage_mpu, prims, stage = _stage(out)
        assert (stage_up, stage_mpu) == (up, mpu)
        want = [HAIR + "Render", HAIR] if name in RENDER else [HAIR]
        assert list(prims) == want  # the groom's own prim: a layer over the groom it came from
        for path, p in prims.items():
            assert (p["type"], p["basis"], p["wrap"]) == ("cubic", "catmullRom", "pinned"), path
            assert p["color"] and not p["displayColor"], path  # Blender's primvar name kept
            assert p["widths"] is not None, path
            # Widths in physical size: the guides' 4 mm → 0.8 mm whatever the unit.
            w_m = p["widths"] * mpu
            assert w_m.max() == pytest.approx(0.004, rel=1e-5)
            assert w_m.min() == pytest.approx(0.0008, rel=1e-5)
        if name in RENDER:
            assert prims[HAIR]["purpose"] == "guide" and prims[HAIR + "Render"]["purpose"] == "default"
        results[src] = io.read(out)
        if isinstance(results[src], Animation):
            assert stage.HasAuthoredTimeCodeRange()
        else:
            assert not stage.HasAuthoredTimeCodeRange()
    a, b = results["z"], results["y"]
    assert type(a) is type(b) and a.strand_count == b.strand_count
    gap = np.linalg.norm(_world(a) - _world(b), axis=-1)
    assert gap.max() < WORLD_TOL_M and np.quantile(gap, 0.99) < TYPICAL_TOL_M
    if name == "simulate":  # the simulation starts where the groom stands, bit for bit
        np.testing.assert_array_equal(a.frames[0], io.read(scenes["z"]).points)
        assert np.abs(_world(a)[-1] - _world(a)[0]).max() > 0.01  # and the head nodded


def test_render_hair_children_follow_the_guides_widths_and_colour(scenes):
    out = scenes["dir"] / "children.usda"
    _run(["interpolate", scenes["z"], out, "--count", "50", "--guides-per-child", "1", "--frizz", "0"])
    from hairtool.guides.files import split_guides

    hair, guides = split_guides(io.read(out))
    # One guide per child, same vertex count: each child carries its guide's widths and colours.
    src = io.read(scenes["z"])
    per_guide = src.thickness.reshape(src.strand_count, -1)
    assert {tuple(r) for r in hair.thickness.reshape(50, -1)} <= {tuple(r) for r in per_guide}
    assert {tuple(c) for c in hair.colors.reshape(-1, 3)} <= {tuple(c) for c in src.colors}
    np.testing.assert_array_equal(guides.thickness, src.thickness)


def test_render_hair_without_guide_widths_gets_80_micron_hair_in_the_scene_unit(tmp_path):
    from hairtool import samples

    g = samples.scalp(20, 6, seed=1)  # 0.1 m per unit, no widths
    assert g.thickness is None and g.metadata.meters_per_unit == 0.1
    out = tmp_path / "h.usda"
    io.write(tmp_path / "g.npz", g)
    _run(["interpolate", tmp_path / "g.npz", out, "--count", "10"])
    from hairtool.guides.files import split_guides

    hair, guides = split_guides(io.read(out))
    assert hair.thickness.max() * 0.1 == pytest.approx(HAIR_WIDTH_M, rel=1e-5)  # at the roots
    assert guides.thickness * 0.1 == pytest.approx(HAIR_WIDTH_M, rel=1e-5)


@pytest.mark.parametrize("src", ["z", "y"])
def test_usd_npz_usd_gives_back_the_same_stage(scenes, src):
    d = scenes["dir"]
    _run(["convert", scenes[src], d / f"c_{src}.npz"])
    _run(["convert", d / f"c_{src}.npz", d / f"c_{src}.usda"])
    up0, mpu0, prims0, _ = _stage(scenes[src])
    up1, mpu1, prims1, _ = _stage(d / f"c_{src}.usda")
    assert (up0, mpu0) == (up1, mpu1)
    assert list(prims0) == list(prims1) == [HAIR]
    for key in ("type", "basis", "wrap", "purpose", "color", "displayColor"):
        assert prims0[HAIR][key] == prims1[HAIR][key], key
    np.testing.assert_array_equal(prims0[HAIR]["widths"], prims1[HAIR]["widths"])
    a, b = io.read(scenes[src]), io.read(d / f"c_{src}.usda")
    np.testing.assert_array_equal(a.points, b.points)
    np.testing.assert_array_equal(a.colors, b.colors)
    assert a.metadata == b.metadata


def test_keys_export_of_a_cached_simulation_lands_on_the_groom(scenes):
    d = scenes["dir"]
    _run(["simulate", scenes["z"], d / "sim.npz", "--frames", "8", "--motion", "nod", "--fit-head"])
    _run(["keys", d / "sim.npz", "--keys", "3", "--export", d / "keys.usda"])
    up, mpu, prims, _ = _stage(d / "keys.usda")
    assert (up, mpu, list(prims)) == ("Z", 1.0, [HAIR])
    assert prims[HAIR]["basis"] == "catmullRom" and prims[HAIR]["color"]
    sim, keys = io.read(d / "sim.npz"), io.read(d / "keys.usda")
    assert keys.n_frames == 3
    for k, t in enumerate(keys.time_codes):
        np.testing.assert_array_equal(keys.frames[k], sim.frames[int(t)])


def test_freeze_refuses_an_animation_without_frame_and_freezes_the_named_pose(scenes, capsys):
    d = scenes["dir"]
    _run(["simulate", scenes["z"], d / "anim.usda", "--frames", "3", "--motion", "nod", "--fit-head"])
    capsys.readouterr()
    assert main(["freeze", str(d / "anim.usda"), str(d / "f.usda")]) == 2
    err = capsys.readouterr().err
    assert "--frame" in err and "3 frames" in err and len(err.strip().splitlines()) == 1
    assert not (d / "f.usda").exists()
    _run(["freeze", d / "anim.usda", d / "f.usda", "--frame", "2", "--no-freeze", "--no-clump"])
    up, mpu, prims, stage = _stage(d / "f.usda")
    assert (up, mpu, list(prims)) == ("Z", 1.0, [HAIR]) and not stage.HasAuthoredTimeCodeRange()
    np.testing.assert_array_equal(io.read(d / "f.usda").points, io.read(d / "anim.usda").frames[2])
    assert main(["freeze", str(d / "anim.usda"), str(d / "g.usda"), "--frame", "3"]) == 2


def test_info_counts_render_hair_and_guides_apart(scenes, capsys):
    out = scenes["dir"] / "info.usda"
    _run(["interpolate", scenes["z"], out, "--count", "30"])
    capsys.readouterr()
    _run(["info", out])
    text = capsys.readouterr().out
    assert "render hair 30 strands, 360 vertices" in text and "guides      300 strands, 3600 vertices" in text


def test_convert_to_a_format_without_a_scene_warns_once(scenes, capsys):
    _run(["convert", scenes["z"], scenes["dir"] / "b.hair"])
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "cannot hold the scene description" in err[0]
    assert "Z-up" in err[0] and "1 m per unit" in err[0] and HAIR in err[0]


def test_merging_prims_keeps_each_ones_widths_and_colour(tmp_path):
    """One prim without widths or colour no longer strips them from the others, and is written
    back without them."""
    from pxr import Usd, UsdGeom, Vt

    path = tmp_path / "two.usda"
    stage = Usd.Stage.CreateNew(str(path))
    UsdGeom.SetStageUpAxis(stage, UsdGeom.Tokens.z)
    UsdGeom.SetStageMetersPerUnit(stage, 1.0)
    for name, widths in (("A", True), ("B", False)):
        c = UsdGeom.BasisCurves.Define(stage, f"/G/{name}")
        c.CreateTypeAttr("linear")
        c.CreateCurveVertexCountsAttr(Vt.IntArray([3, 3]))
        c.CreatePointsAttr(Vt.Vec3fArray.FromNumpy(np.arange(18, dtype=np.float32).reshape(6, 3)))
        if widths:
            c.CreateWidthsAttr(Vt.FloatArray([0.001] * 6))
            c.SetWidthsInterpolation(UsdGeom.Tokens.vertex)
            c.CreateDisplayColorPrimvar(UsdGeom.Tokens.vertex).Set(Vt.Vec3fArray([(1, 0, 0)] * 6))
    stage.GetRootLayer().Save()
    g = io.read(path)
    assert g.thickness is not None and g.colors is not None
    np.testing.assert_allclose(g.thickness[:6], 0.001)
    np.testing.assert_allclose(g.thickness[6:], HAIR_WIDTH_M)  # 80 µm in a metre scene
    assert [c.lacks for c in g.metadata.curves] == [(), ("thickness", "colors")]
    for out in (tmp_path / "back.usda", tmp_path / "back.npz"):
        io.write(out, g)
        again = io.read(out)
        assert again.metadata == g.metadata
        np.testing.assert_array_equal(again.thickness, g.thickness)
    _, _, prims, _ = _stage(tmp_path / "back.usda")
    assert prims["/G/B"]["widths"] is None and not prims["/G/B"]["displayColor"]
    np.testing.assert_allclose(prims["/G/A"]["widths"], 0.001)


def test_head_turns_about_the_scene_up_and_nods_about_its_lateral_axis():
    for up_axis, up in (("Y", [0, 1, 0]), ("Z", [0, 0, 1])):
        frame = Metadata(up_axis=up_axis).frame
        turn = head_motion("turn", 1.0, frame=frame)(0.25)[:3, :3]
        nod = head_motion("nod", 1.0, frame=frame)(0.25)[:3, :3]
        np.testing.assert_allclose(turn @ up, up, atol=1e-12)  # the up axis is the turn's axis
        assert abs(float(np.asarray(up) @ nod @ up)) < 0.999  # a nod tips the up axis …
        np.testing.assert_allclose(nod @ [1, 0, 0], [1, 0, 0], atol=1e-12)  # … about x


def test_npz_metadata_member_is_checked(tmp_path):
    g = Groom(np.zeros((2, 3)), [2], metadata=Metadata(up_axis="Z", meters_per_unit=1.0))
    io.write(tmp_path / "ok.npz", g)
    assert io.read(tmp_path / "ok.npz").metadata == g.metadata
    with np.load(tmp_path / "ok.npz") as z:
        members = {k: z[k] for k in z.files}
    import json

    from hairtool.errors import FormatError

    record = json.loads(str(members["metadata"]))
    singular = json.dumps(record | {"xforms": [["/A", [0.0] * 16]]})
    overflowing = (
        json.dumps(record).replace('"xforms"', '"x"')[:-1] + ', "xforms": [["/A", [' + "9" * 400 + "]]]}"
    )
    for bad in (
        '{"up_axis": "X"}',
        "[" * 100_000,
        '{"up_axis": "Z", "meters_per_unit": ' + "9" * 5000 + "}",
        singular,
        overflowing,
    ):
        np.savez(tmp_path / "bad.npz", **(members | {"metadata": np.array(bad)}))
        with pytest.raises(FormatError, match="metadata"):
            io.read(tmp_path / "bad.npz")


def test_every_groom_and_animation_the_library_builds_names_its_record():
    """By construction: a Groom(...) or Animation(...) call in hairtool/ without ``metadata=``
    (or ``**`` of a caller's keywords) would make a groom in the default space and lose the
    scene, so there is none."""
    root = Path(__file__).resolve().parents[1] / "hairtool"
    missing = []
    for f in sorted(root.rglob("*.py")):
        for node in ast.walk(ast.parse(f.read_text(encoding="utf-8"))):
            if isinstance(node, ast.Call) and getattr(node.func, "id", None) in ("Groom", "Animation"):
                kws = {k.arg for k in node.keywords}
                if "metadata" not in kws and None not in kws:
                    missing.append(f"{f.relative_to(root)}:{node.lineno}")
    assert missing == []


def test_curves_prim_lacks_is_checked():
    from hairtool.errors import ParameterError

    assert CurvesPrim("/A", 1, lacks=("colors", "thickness")).lacks == ("thickness", "colors")
    with pytest.raises(ParameterError, match="lacks"):
        CurvesPrim("/A", 1, lacks=("hat",))


def test_child_attribute_blend_matches_its_reference():
    from hairtool import samples
    from hairtool.guides.attributes import blend, blend_reference
    from hairtool.guides.binding import bind_roots

    g = samples.scalp(12, 7, seed=3)
    mixed = Groom.from_strands([g.strand(s)[: 4 + s % 4] for s in range(12)])  # 4 … 7 vertices
    rng = np.random.default_rng(0)
    mixed = Groom(
        mixed.points, mixed.topology, colors=rng.random((mixed.vertex_count, 3)), metadata=g.metadata
    )
    b = bind_roots(mixed, count=30, k=3, vertices=9, seed=1)
    widths = rng.random(mixed.vertex_count)
    np.testing.assert_allclose(blend(widths, b), blend_reference(widths, b), rtol=1e-6)
    np.testing.assert_allclose(blend(mixed.colors, b), blend_reference(mixed.colors, b), rtol=1e-6)
    assert b.build().colors is not None and b.build().thickness is None  # the guides had no widths


@pytest.mark.slow(seconds=8)
def test_a_batch_of_commands_keeps_the_scene_as_the_commands_do(scenes, tmp_path, capsys):
    pytest.importorskip("distributed", reason="the farm extra (dask[distributed]) is not installed")
    import json
    import shutil

    shutil.copy(scenes["z"], tmp_path / "b.usda")
    jobs = [
        {
            "command": "simulate",
            "args": ["b.usda", "out/sim.usda", "--frames", "3", "--motion", "nod", "--fit-head"],
        },
        {"command": "anime", "args": ["b.usda", "out/cycle.npz", "--frames", "3"]},
    ]
    (tmp_path / "jobs.json").write_text(json.dumps({"jobs": jobs}))
    assert main(["batch", str(tmp_path / "jobs.json"), "--workers", "1"]) == 0
    for job in jobs:
        by_hand = tmp_path / ("hand" + Path(job["args"][1]).suffix)
        _run([job["command"], tmp_path / "b.usda", by_hand, *job["args"][2:]])
        farmed, mine = io.read(tmp_path / job["args"][1]), io.read(by_hand)
        np.testing.assert_array_equal(farmed.frames, mine.frames)
        assert farmed.metadata == mine.metadata
        assert (farmed.metadata.up_axis, farmed.metadata.meters_per_unit) == ("Z", 1.0)
        assert [c.path for c in farmed.metadata.curves] == [HAIR]


def test_a_simulation_layered_over_its_groom_replaces_the_hair_and_keeps_the_head(scenes, tmp_path):
    from pxr import Sdf, Usd, UsdGeom

    _run(["simulate", scenes["z"], tmp_path / "sim.usda", "--frames", "4", "--motion", "nod", "--fit-head"])
    shot = Sdf.Layer.CreateNew(str(tmp_path / "shot.usda"))
    shot.subLayerPaths.append(str(tmp_path / "sim.usda"))  # stronger: the simulation
    shot.subLayerPaths.append(str(scenes["z"]))  # weaker: the groom with its head
    shot.Save()
    stage = Usd.Stage.Open(str(tmp_path / "shot.usda"))
    assert stage.GetPrimAtPath("/root/Head/Icosphere").IsA(UsdGeom.Mesh)
    curves = [p.GetPath() for p in stage.Traverse() if p.IsA(UsdGeom.BasisCurves)]
    assert [str(p) for p in curves] == [HAIR]
    sim = io.read(tmp_path / "sim.usda")
    points = UsdGeom.BasisCurves(stage.GetPrimAtPath(HAIR)).GetPointsAttr()
    for f, t in enumerate(sim.time_codes):
        np.testing.assert_array_equal(np.asarray(points.Get(Usd.TimeCode(t)), np.float32), sim.frames[f])


def test_a_project_keeps_the_scene_description(scenes, tmp_path):
    from hairtool import project
    from hairtool.errors import FormatError

    rest = io.read(scenes["z"])
    anim = rest.animate(np.stack([rest.points] * 3), 24.0)
    proj = project.Project(rest=rest, animation=anim, animation_source="simulate")
    project.save(tmp_path / "p.hairproj", proj)
    back = project.load(tmp_path / "p.hairproj")
    assert back.rest.metadata == rest.metadata and back.animation.metadata == anim.metadata
    assert (back.rest.metadata.up_axis, back.rest.metadata.curves[0].path) == ("Z", HAIR)
    # A hand-edited scene record is one line naming it.
    manifest, arrays = project.manifest_and_arrays(proj)
    manifest["groom"]["scene"]["meters_per_unit"] = "big"
    import json
    import zipfile

    with zipfile.ZipFile(tmp_path / "bad.hairproj", "w") as zf:
        zf.writestr("manifest.json", json.dumps(manifest))
        for name, a in arrays.items():
            import io as _io

            buf = _io.BytesIO()
            np.save(buf, a)
            zf.writestr(name, buf.getvalue())
    with pytest.raises(FormatError, match="groom scene"):
        project.load(tmp_path / "bad.hairproj")


def test_hair_under_transformed_parents_is_written_in_their_space_and_layers_over_its_source(tmp_path):
    """b_xform.usdc: the hair sits under /root/Head and /root/Head/Hair with their own translate,
    rotate and scale. The output puts those transforms back and writes the points in the prim's
    space, so alone it stands where the source does, and sublayered over the source the hair is
    moved once, not twice."""
    from pxr import Sdf, Usd, UsdGeom

    src = INTEROP / "b_xform.usdc"
    _run(["simulate", src, tmp_path / "sim.usda", "--frames", "3", "--motion", "nod", "--fit-head"])
    shot = Sdf.Layer.CreateNew(str(tmp_path / "shot.usda"))
    shot.subLayerPaths.append(str(tmp_path / "sim.usda"))
    shot.subLayerPaths.append(str(src))
    shot.Save()
    sim = io.read(tmp_path / "sim.usda")
    source = Usd.Stage.Open(str(src))
    np.testing.assert_allclose(sim.frames[0], io.read(src).points, atol=1e-6)  # where the groom stands
    for stage_path in (tmp_path / "sim.usda", tmp_path / "shot.usda"):
        stage = Usd.Stage.Open(str(stage_path))
        for prim in ("/root/Head", "/root/Head/Hair"):
            t = Usd.TimeCode.Default()
            mine = UsdGeom.Xformable(stage.GetPrimAtPath(prim)).ComputeLocalToWorldTransform(t)
            theirs = UsdGeom.Xformable(source.GetPrimAtPath(prim)).ComputeLocalToWorldTransform(t)
            np.testing.assert_allclose(np.asarray(mine), np.asarray(theirs), atol=1e-12)
        hair = UsdGeom.BasisCurves(stage.GetPrimAtPath(HAIR))
        for f, t in enumerate(sim.time_codes):
            m = np.asarray(hair.ComputeLocalToWorldTransform(Usd.TimeCode(t)))
            local = np.asarray(hair.GetPointsAttr().Get(Usd.TimeCode(t)), np.float64)
            np.testing.assert_allclose(local @ m[:3, :3] + m[3, :3], sim.frames[f], atol=1e-6)
    _run(["convert", tmp_path / "sim.usda", tmp_path / "sim.npz"])
    assert io.read(tmp_path / "sim.npz").metadata == sim.metadata and sim.metadata.xforms
