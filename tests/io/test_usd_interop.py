"""USD as Blender 5 writes it (``shared/data/interop``): space, units, time codes, transforms, bases,
colour, and a convert → read-back with pxr that puts the hair where it was."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from hairtool.cli import main
from hairtool.groom import Animation, Groom
from hairtool.io import read, usd, write
from hairtool.keys.export import keys_record, write_key_poses
from hairtool.metadata import CurvesPrim, Metadata

INTEROP = Path(__file__).resolve().parents[1] / "data" / "interop"
HAIR = "/root/Head/Hair/HairData"


@pytest.fixture(scope="module")
def interop():
    if not INTEROP.is_dir():
        pytest.fail(f"Blender exports are expected in {INTEROP}")
    return INTEROP


def _raw(path, prim=HAIR, name="points", time=None):
    """An attribute's value straight from pxr, as float64."""
    from pxr import Usd

    stage = Usd.Stage.Open(str(path))
    attr = stage.GetPrimAtPath(prim).GetAttribute(name)
    return np.asarray(attr.Get(Usd.TimeCode.Default() if time is None else Usd.TimeCode(time)), np.float64)


def _ops_matrix(path, prim, time=None) -> np.ndarray:
    """``prim``'s local transform from its translate / rotateXYZ / scale ops, by hand (column vectors)."""
    from pxr import Usd

    stage = Usd.Stage.Open(str(path))
    p = stage.GetPrimAtPath(prim)
    t = Usd.TimeCode.Default() if time is None else Usd.TimeCode(time)
    m = np.eye(4)
    for name in p.GetAttribute("xformOpOrder").Get() or []:
        v = np.asarray(p.GetAttribute(name).Get(t), np.float64)
        op = np.eye(4)
        if name == "xformOp:translate":
            op[:3, 3] = v
        elif name == "xformOp:scale":
            op[:3, :3] = np.diag(v)
        elif name == "xformOp:rotateXYZ":  # X first, then Y, then Z
            rx, ry, rz = np.radians(v)
            x = np.array([[1, 0, 0], [0, np.cos(rx), -np.sin(rx)], [0, np.sin(rx), np.cos(rx)]])
            y = np.array([[np.cos(ry), 0, np.sin(ry)], [0, 1, 0], [-np.sin(ry), 0, np.cos(ry)]])
            z = np.array([[np.cos(rz), -np.sin(rz), 0], [np.sin(rz), np.cos(rz), 0], [0, 0, 1]])
            op[:3, :3] = z @ y @ x
        else:
            raise AssertionError(f"unexpected op {name}")
        m = m @ op
    return m


def _world(path, local_points, time=None) -> np.ndarray:
    m = np.eye(4)
    for prim in ("/root", "/root/Head", "/root/Head/Hair", HAIR):
        m = m @ _ops_matrix(path, prim, time)
    return local_points @ m[:3, :3].T + m[:3, 3]


def test_catmull_rom_export_reads_points_widths_colour_basis_and_space(interop):
    g = read(interop / "b.usda")
    assert isinstance(g, Groom) and g.strand_count == 300 and np.all(g.counts == 12)
    np.testing.assert_array_equal(g.points, _raw(interop / "b.usda").astype(np.float32))
    np.testing.assert_array_equal(g.thickness, _raw(interop / "b.usda", name="widths").astype(np.float32))
    rgba = _raw(interop / "b.usda", name="primvars:color")
    np.testing.assert_array_equal(g.colors, rgba[:, :3].astype(np.float32))
    assert g.transparency is None  # Blender's alpha is 1 everywhere
    m = g.metadata
    assert (m.up_axis, m.meters_per_unit, m.color_primvar) == ("Z", 1.0, "color")
    assert m.curves == (CurvesPrim(HAIR, 300, "catmullRom", "pinned"),)
    poly = read(interop / "b_poly.usda")
    assert poly.metadata.curves == (CurvesPrim(HAIR, 300, "linear", "nonperiodic"),)
    np.testing.assert_array_equal(poly.points, g.points)  # the same hair, drawn as polylines


def test_static_parent_transform_is_applied(interop):
    g = read(interop / "b_xform.usdc")
    local = _raw(interop / "b_xform.usdc")
    np.testing.assert_allclose(g.points, _world(interop / "b_xform.usdc", local), atol=2e-6)
    assert not np.allclose(g.points, local, atol=1e-2)  # moved, rotated and scaled ×2


def test_hair_under_an_animated_head_is_an_animation(interop):
    path = interop / "b_xformanim.usdc"
    a = read(path)
    assert isinstance(a, Animation) and a.n_frames == 24 and a.fps == 24
    np.testing.assert_array_equal(a.time_codes, np.arange(1, 25))
    local = _raw(path)
    for f in (0, 11, 23):
        np.testing.assert_allclose(a.frames[f], _world(path, local, time=f + 1), atol=2e-6)
    assert np.abs(a.frames[23] - a.frames[0]).max() > 0.01  # the head turns
    assert usd.time_codes(path) == list(range(1, 25))


def test_hairtool_keys_accepts_hair_under_an_animated_head(interop, tmp_path, capsys):
    out = tmp_path / "keys.usda"
    assert main(["keys", str(interop / "b_xformanim.usdc"), "--keys", "4", "--export", str(out)]) == 0
    codes = usd.time_codes(out)
    assert len(codes) == 4 and codes[0] >= 1 and codes[-1] <= 24


def test_time_codes_starting_at_1_stay_at_1_everywhere(interop, tmp_path):
    src = interop / "b_gnanim.usdc"
    a = read(src)
    assert a.n_frames == 48
    np.testing.assert_array_equal(a.time_codes, np.arange(1, 49))
    from pxr import Usd

    # USD: converted and read back with pxr.
    assert main(["convert", str(src), str(tmp_path / "a.usdc")]) == 0
    stage = Usd.Stage.Open(str(tmp_path / "a.usdc"))
    points = stage.GetPrimAtPath(HAIR).GetAttribute("points")
    assert points.GetTimeSamples() == list(range(1, 49))
    assert (stage.GetStartTimeCode(), stage.GetEndTimeCode(), stage.GetTimeCodesPerSecond()) == (1, 48, 24)
    np.testing.assert_array_equal(np.asarray(points.Get(7), np.float32), a.frames[6])
    # The .npz cache.
    write(tmp_path / "a.npz", a)
    np.testing.assert_array_equal(read(tmp_path / "a.npz").time_codes, np.arange(1, 49))
    # Key poses and the keys record.
    keys = [0, 10, 47]
    write_key_poses(tmp_path / "k.usda", a, keys)
    assert usd.time_codes(tmp_path / "k.usda") == [1, 11, 48]
    record = keys_record({"frames": 48, "fps": 24.0, "keys": keys}, src, time_codes=a.time_codes)
    assert [k["time_code"] for k in record["keys"]] == [1, 11, 48]
    assert record["keys"][1]["time"] == pytest.approx(11 / 24)
    assert json.loads(json.dumps(record))["keys"][0] == {"frame": 0, "time_code": 1.0, "time": 1 / 24}


def test_blender_export_converted_keeps_z_up_metres_its_place_and_its_prim(interop, tmp_path):
    from pxr import Usd, UsdGeom

    out = tmp_path / "b.usdc"
    assert main(["convert", str(interop / "b_xform.usdc"), str(out)]) == 0
    stage = Usd.Stage.Open(str(out))
    assert UsdGeom.GetStageUpAxis(stage) == "Z" and UsdGeom.GetStageMetersPerUnit(stage) == 1.0
    curves = UsdGeom.BasisCurves(stage.GetPrimAtPath(HAIR))
    assert curves and stage.GetDefaultPrim().GetPath() == "/root"
    world = UsdGeom.Xformable(curves.GetPrim()).ComputeLocalToWorldTransform(Usd.TimeCode.Default())
    pts = (
        np.asarray(curves.GetPointsAttr().Get(), np.float64) @ np.asarray(world)[:3, :3]
        + np.asarray(world)[3, :3]
    )
    np.testing.assert_allclose(pts, read(interop / "b_xform.usdc").points, atol=1e-6)
    color = UsdGeom.PrimvarsAPI(curves.GetPrim()).GetPrimvar("color")
    assert color.GetTypeName() == "color4f[]"


def test_catmull_rom_basis_and_colour_are_written_back(interop, tmp_path):
    from pxr import Usd, UsdGeom

    out = tmp_path / "b.usda"
    assert main(["convert", str(interop / "b.usda"), str(out)]) == 0
    stage = Usd.Stage.Open(str(out))
    curves = UsdGeom.BasisCurves(stage.GetPrimAtPath(HAIR))
    assert (curves.GetTypeAttr().Get(), curves.GetBasisAttr().Get()) == ("cubic", "catmullRom")
    assert curves.GetWrapAttr().Get() == "pinned"
    a, b = read(interop / "b.usda"), read(out)
    assert b.points.tobytes() == a.points.tobytes() and b.colors.tobytes() == a.colors.tobytes()
    assert b.thickness.tobytes() == a.thickness.tobytes() and b.metadata.curves == a.metadata.curves


def test_own_grooms_declare_y_up_centimetres_and_convert_overrides(grooms_dir, tmp_path, capsys):
    from pxr import Usd, UsdGeom

    src = grooms_dir / "ponytail_tail.tfx"
    assert main(["convert", str(src), str(tmp_path / "y.usda")]) == 0
    stage = Usd.Stage.Open(str(tmp_path / "y.usda"))
    layer = stage.GetRootLayer()  # authored explicitly, not left to USD's fallbacks
    assert layer.pseudoRoot.GetInfo("upAxis") == "Y" and layer.pseudoRoot.GetInfo("metersPerUnit") == 0.01
    argv = ["convert", str(src), str(tmp_path / "z.usdc"), "--up-axis", "z", "--meters-per-unit", "0.001"]
    assert main(argv) == 0
    stage = Usd.Stage.Open(str(tmp_path / "z.usdc"))
    assert UsdGeom.GetStageUpAxis(stage) == "Z" and UsdGeom.GetStageMetersPerUnit(stage) == 0.001
    assert read(tmp_path / "z.usdc").points.tobytes() == read(src).points.tobytes()  # relabelled, not moved
    capsys.readouterr()
    assert main(["convert", str(src), str(tmp_path / "z.obj"), "--up-axis", "Z"]) == 2
    assert main(["convert", str(src), str(tmp_path / "z.usda"), "--meters-per-unit", "0"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 2 and "USD output" in err[0] and "meters-per-unit" in err[1]


def test_several_prims_are_written_back_as_the_same_prims(tmp_path):
    rng = np.random.default_rng(4)
    counts = np.array([2, 3, 4, 7, 4, 4])
    meta = Metadata(
        up_axis="Z",
        meters_per_unit=1.0,
        curves=(
            CurvesPrim("/A/Left", 2),
            CurvesPrim("/A/Right", 1, "bezier"),
            CurvesPrim("/B", 3, "bspline"),
        ),
    )
    g = Groom(rng.standard_normal((int(counts.sum()), 3)), counts, metadata=meta)
    write(tmp_path / "g.usda", g)
    back = read(tmp_path / "g.usda")
    assert back.metadata.curves == meta.curves and back.points.tobytes() == g.points.tobytes()
    write(tmp_path / "again.usdc", back)
    assert read(tmp_path / "again.usdc").metadata.curves == meta.curves
    # A subset keeps the prims it draws from (across prims backwards: one default prim);
    # counts a cubic basis cannot draw, as linear curves.
    write(tmp_path / "sub.usda", g.subset([0, 1, 4]))
    assert read(tmp_path / "sub.usda").metadata.curves == (
        CurvesPrim("/A/Left", 2),
        CurvesPrim("/B", 1, "bspline"),
    )
    write(tmp_path / "back.usda", g.subset([4, 0]))
    assert read(tmp_path / "back.usda").metadata.curves == (CurvesPrim(usd.PRIM_PATH, 2),)
    odd = Groom(g.points[:5], [5], metadata=Metadata(curves=(CurvesPrim("/Odd", 1, "bezier"),)))
    write(tmp_path / "odd.usda", odd)
    assert read(tmp_path / "odd.usda").metadata.curves == (CurvesPrim("/Odd", 1, "linear"),)


def test_info_says_which_basis_and_space(interop, capsys):
    assert main(["info", str(interop / "b.usda")]) == 0
    text = capsys.readouterr().out
    assert "Z-up, 1 m per unit" in text and f"{HAIR}: 300 strands, cubic catmullRom, pinned" in text
    assert main(["info", str(interop / "b_gnanim.usdc"), "--json"]) == 0
    info = json.loads(capsys.readouterr().out)
    assert info["time_codes"] == {"first": 1.0, "last": 48.0}
    assert info["usd"]["curves"][0]["basis"] == "catmullRom"


def test_info_reads_bvh(motion_dir, capsys):
    assert main(["info", str(motion_dir / "mocapbank_walk.bvh"), "--json"]) == 0
    info = json.loads(capsys.readouterr().out)
    assert (info["kind"], info["joints"], info["channels"], info["frames"]) == ("motion", 19, 60, 455)
    assert info["fps"] == 30 and info["frame_time"] == pytest.approx(1 / 30, rel=1e-3)
    assert main(["info", str(motion_dir / "pymo_walk.bvh")]) == 0
    assert "frames      1064 at 120 fps" in capsys.readouterr().out
