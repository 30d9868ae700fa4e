"""What a command leaves alone in a USD scene reaches the file it writes: the head mesh, the
root's customData, the parents' properties, and a curves prim's other primvars where its curves
are the same ones, each value byte for byte, and the points, widths and colour of a prim the
command did not touch, every time sample; a groom with nothing beside it is written as before."""

from __future__ import annotations

import tempfile
from pathlib import Path

import numpy as np
from hypothesis import given, settings

from hairtool import io
from hairtool.cli import main
from hairtool.io.usd_carry import carry_scene

from .usd_scenes import scenes, write_stage

DATA = Path(__file__).resolve().parents[1] / "data" / "interop"


def values(path: Path, prim: str) -> dict[str, bytes]:
    """Every authored attribute of ``prim`` (its default value's bytes) and its customData."""
    from pxr import Usd

    stage = Usd.Stage.Open(str(path))
    p = stage.GetPrimAtPath(prim)
    assert p, prim
    out = {
        a.GetName(): np.asarray(a.Get()).tobytes() for a in p.GetAuthoredAttributes() if a.Get() is not None
    }
    out["customData"] = repr(p.GetCustomData()).encode()
    return out


def test_convert_and_freeze_keep_blenders_head_root_and_parents(tmp_path):
    src = DATA / "b.usda"
    assert main(["convert", str(src), str(tmp_path / "c.usdc")]) == 0
    assert main(["freeze", str(src), str(tmp_path / "f.usda")]) == 0
    for out in (tmp_path / "c.usdc", tmp_path / "f.usda"):
        for prim in ("/root", "/root/Head", "/root/Head/Icosphere", "/root/Head/Curves"):
            assert values(out, prim) == values(src, prim), (out.name, prim)
    hair = "/root/Head/Hair/HairData"
    got, was = values(tmp_path / "c.usdc", hair), values(src, hair)
    assert got["userProperties:blender:data_name"] == was["userProperties:blender:data_name"]


@settings(max_examples=5, deadline=None, derandomize=True)
@given(scene=scenes(animated=False))
def test_a_custom_primvar_and_a_mesh_pass_through_convert_and_freeze(scene):
    with tempfile.TemporaryDirectory() as tmp:
        d = Path(tmp)
        write_stage(d / "s.usda", scene)
        assert main(["convert", str(d / "s.usda"), str(d / "c.usda")]) == 0
        assert main(["freeze", str(d / "s.usda"), str(d / "f.usda")]) == 0
        for out in (d / "c.usda", d / "f.usda"):
            if scene.mesh:
                assert values(out, "/Head") == values(d / "s.usda", "/Head")
            for prim in scene.prims:
                if prim.custom:
                    key = "primvars:clump_weight"
                    assert values(out, prim.path)[key] == values(d / "s.usda", prim.path)[key]


def test_a_groom_with_nothing_beside_it_is_written_as_before(tmp_path):
    groom = io.read(DATA / "b_poly.usda")
    io.write(tmp_path / "plain.usda", groom)
    before = (tmp_path / "plain.usda").read_bytes()
    io.write(tmp_path / "again.usda", groom)
    assert carry_scene(tmp_path / "plain.usda", tmp_path / "again.usda") == []
    assert (tmp_path / "again.usda").read_bytes() == before


def test_a_parents_translate_rotate_scale_ops_are_kept_as_authored(tmp_path):
    from pxr import Usd, UsdGeom

    src = DATA / "b_xform.usdc"
    for cmd in ("convert", "freeze"):
        out = tmp_path / f"{cmd}.usda"
        assert main([cmd, str(src), str(out)]) == 0
        stages = {p: Usd.Stage.Open(str(p)) for p in (src, out)}
        ops = {}
        for p, stage in stages.items():
            ops[p] = [
                (str(q.GetPath()), o.GetOpName(), np.asarray(o.Get()).tobytes())
                for q in stage.Traverse()
                if q.IsA(UsdGeom.Xformable)
                for o in UsdGeom.Xformable(q).GetOrderedXformOps()
            ]
        assert ops[out] == ops[src] and any("rotateXYZ" in name for _, name, _ in ops[src])
    back, was = io.read(tmp_path / "convert.usda"), io.read(src)
    np.testing.assert_allclose(back.points, was.points, rtol=0, atol=1e-6)


def test_simulate_and_anime_keep_the_head_root_and_custom_primvars(tmp_path):
    """(They carried nothing before: the head mesh, Blender's root and custom primvars were dropped.)"""
    from .test_animated_interpolate import two_prims

    write_stage(tmp_path / "g.usda", two_prims(None))
    for src, kept in (
        (DATA / "b.usda", ("/root", "/root/Head", "/root/Head/Icosphere")),
        (tmp_path / "g.usda", ("/Head",)),
    ):
        sim, cycle = tmp_path / f"s_{src.stem}.usda", tmp_path / f"a_{src.stem}.usda"
        assert main(["simulate", str(src), str(sim), "--frames", "2", "--substeps", "1", "--fit-head"]) == 0
        assert main(["anime", str(src), str(cycle), "--frames", "2"]) == 0
        for out in (sim, cycle):
            for prim in kept:
                assert values(out, prim) == values(src, prim), (out.name, prim)
    hair = "/Root0_0/Hair0"
    for out in (tmp_path / "s_g.usda", tmp_path / "a_g.usda"):
        assert (
            values(out, hair)["primvars:clump_weight"]
            == values(tmp_path / "g.usda", hair)["primvars:clump_weight"]
        )


def test_a_keys_export_keeps_the_head_and_custom_primvars(tmp_path):
    from .test_animated_interpolate import two_prims

    write_stage(tmp_path / "g.usda", two_prims("points"))
    for bake in ([], ["--bake"]):
        out = tmp_path / f"k{len(bake)}.usda"
        assert main(["keys", str(tmp_path / "g.usda"), "--export", str(out), *bake]) == 0
        assert values(out, "/Head") == values(tmp_path / "g.usda", "/Head")
        hair = "/Root0_0/Hair0"
        assert (
            values(out, hair)["primvars:clump_weight"]
            == values(tmp_path / "g.usda", hair)["primvars:clump_weight"]
        )


def samples(path: Path, prim: str, signed_zeros: bool = True) -> dict[str, list]:
    """Every authored attribute of ``prim``: ``(time, bytes)`` of each time sample, or of its
    default where it has none (``signed_zeros`` False: −0.0 as 0.0, which is all usd-core's
    crate format keeps of it: it stores whole numbers compactly)."""
    from pxr import Usd

    def raw(value) -> bytes:
        a = np.asarray(value)
        return (a + 0.0 if not signed_zeros and a.dtype.kind == "f" else a).tobytes()

    stage = Usd.Stage.Open(str(path))
    p = stage.GetPrimAtPath(prim)
    assert p, prim
    out = {}
    for a in p.GetAuthoredAttributes():
        times = a.GetTimeSamples() or [None]
        out[a.GetName()] = [(t, raw(a.Get() if t is None else a.Get(t))) for t in times]
    return out


@settings(max_examples=6, deadline=None, derandomize=True)
@given(scene=scenes(motions=("points", "transform")))
def test_untouched_prims_keep_every_time_sample_byte_for_byte(scene):
    """The first prim's points, widths and colour are time-sampled, or a parent of other hair
    beside the prims is: ``convert`` copies the samples, and the static prims beside them stay
    static, under their parents' own transform ops (the writer had sampled them at every frame,
    in world space under a turning parent beside them); ``interpolate --prim`` of the last prim
    passes the others through the same way, and writes its guides' points as they were."""
    with tempfile.TemporaryDirectory() as tmp:
        d = Path(tmp)
        write_stage(d / "s.usda", scene)
        for ext in ("usda", "usdc"):
            assert main(["convert", str(d / "s.usda"), str(d / f"c.{ext}")]) == 0
            signed = ext == "usda"
            for prim in scene.prims:
                was = samples(d / "s.usda", prim.path, signed)
                got = samples(d / f"c.{ext}", prim.path, signed)
                assert {k: got[k] for k in was if k in got} == was, (ext, prim.path)
                for parent, *_ in prim.parents:
                    assert samples(d / f"c.{ext}", parent, signed) == samples(d / "s.usda", parent, signed)
        last = scene.prims[-1].path
        args = ["interpolate", str(d / "s.usda"), str(d / "k.usda"), "--count", "6", "--prim", last]
        assert main(args) == 0
        for prim in scene.prims:
            was, got = samples(d / "s.usda", prim.path), samples(d / "k.usda", prim.path)
            names = ["points"] if prim.path == last else list(was)
            assert {k: got[k] for k in names} == {k: was[k] for k in names}, prim.path
