"""A prim's custom primvars after strokes that plant and delete strands (``freeze --strokes``
on Blender's groom, given a per-curve int and a per-vertex float): a kept strand keeps its
values, a planted one takes those of the kept strand whose root is nearest, a deleted one's go
with it; ``interpolate`` of the result and ``freeze --count`` give them to the children."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from hairtool import io
from hairtool.cli import main

from .test_usd_stroke_logs import DATA, PRIM, brush_logs, fitted_sphere, write_sphere_obj


def primvar(path: Path, prim: str, name: str):
    from pxr import Usd, UsdGeom

    stage = Usd.Stage.Open(str(path))  # (held: a prim of a freed stage is invalid)
    p = UsdGeom.PrimvarsAPI(stage.GetPrimAtPath(prim)).GetPrimvar(name)
    return (np.asarray(p.ComputeFlattened()), str(p.GetInterpolation())) if p else (None, None)


@pytest.fixture(scope="module")
def planted(tmp_path_factory):
    """Blender's groom with ``strand_id`` (uniform int) and ``stiff`` (vertex float), a sphere
    head under it, and a log that deletes strands, then plants six."""
    from pxr import Sdf, Usd, UsdGeom, Vt

    d = tmp_path_factory.mktemp("planted")
    stage = Usd.Stage.Open(str(DATA / "b.usda"))
    stage.Export(str(d / "b.usda"))
    stage = Usd.Stage.Open(str(d / "b.usda"))
    groom = io.read(DATA / "b.usda")
    pv = UsdGeom.PrimvarsAPI(stage.GetPrimAtPath(PRIM))
    ids = Vt.IntArray([100 + s for s in range(groom.strand_count)])
    pv.CreatePrimvar("strand_id", Sdf.ValueTypeNames.IntArray, "uniform").Set(ids)
    stiff = np.random.default_rng(1).uniform(0, 1, groom.vertex_count).astype(np.float32)
    pv.CreatePrimvar("stiff", Sdf.ValueTypeNames.FloatArray, "vertex").Set(Vt.FloatArray.FromNumpy(stiff))
    stage.GetRootLayer().Save()
    centre, radius = fitted_sphere(groom.roots)
    write_sphere_obj(d / "head.obj", centre, radius)
    logs = brush_logs(groom)
    (d / "log.json").write_text(json.dumps(logs["delete"] + logs["add"]))
    out = d / "f.usda"
    args = [
        "freeze",
        str(d / "b.usda"),
        str(out),
        "--strokes",
        str(d / "log.json"),
        "--scalp",
        str(d / "head.obj"),
    ]
    assert main(args) == 0
    return d, groom, stiff, out


def test_kept_strands_keep_their_values_and_planted_ones_take_the_nearest_kept(planted):
    _, groom, stiff, out = planted
    now = io.read(out)
    # roots never move: a strand now whose root is a source root is that strand, kept
    gaps = ((now.roots[:, None].astype(np.float64) - groom.roots[None]) ** 2).sum(-1)
    same = gaps.min(axis=1) == 0
    origin = np.where(same, gaps.argmin(axis=1), -1)
    assert (~same).sum() == 6 and len(np.unique(origin[same])) < groom.strand_count  # planted, deleted
    kept = np.unique(origin[same])
    near = kept[gaps[:, kept].argmin(axis=1)]
    source = np.where(same, origin, near)
    ids, interp = primvar(out, PRIM, "strand_id")
    assert interp == "uniform"
    np.testing.assert_array_equal(ids, 100 + source)
    values, interp = primvar(out, PRIM, "stiff")
    assert interp == "vertex" and values.dtype == np.float32
    rows = [stiff[groom.offsets[s] : groom.offsets[s + 1]] for s in source]  # (12 vertices each)
    np.testing.assert_array_equal(values, np.concatenate(rows))


def test_the_children_get_them_from_the_guides_now(planted):
    d, _, _, out = planted
    guide_ids, _ = primvar(out, PRIM, "strand_id")
    render = PRIM + "Render"
    for cmd, src in (("interpolate", out), ("freeze", d / "b.usda")):
        dst = d / f"k_{cmd}.usda"
        args = [cmd, str(src), str(dst), "--count", "40", "--seed", "1"]
        if cmd == "freeze":
            args += ["--strokes", str(d / "log.json"), "--scalp", str(d / "head.obj")]
        assert main(args) == 0
        kids = io.read(dst)
        (hair,) = [c for c in kids.metadata.curves if c.path == render]
        ids, interp = primvar(dst, render, "strand_id")
        assert interp == "uniform" and len(ids) == hair.strands and set(ids) <= set(guide_ids), cmd
        values, interp = primvar(dst, render, "stiff")
        vertices = int(kids.counts[: hair.strands].sum())  # (the render prim comes first)
        assert interp == "vertex" and len(values) == vertices and 0 <= values.min() <= values.max() <= 1
    # freeze --count wrote the same guides as freeze alone, with the same values
    np.testing.assert_array_equal(primvar(d / "k_freeze.usda", PRIM, "strand_id")[0], guide_ids)
