"""Every brush's stroke log replayed on a Blender USD groom (``hairtool freeze --strokes``), by
hand and as a batch job: the brush-local sub-groom carries its share of the source's prims, so
the replay runs, writes the source's prim back, and gives the points the same log gives on the
groom converted to npz."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from hairtool import io
from hairtool.cli import main
from hairtool.farm.jobs import Job
from hairtool.farm.runner import run_job

DATA = Path(__file__).resolve().parents[1] / "data" / "interop"
PRIM = "/root/Head/Hair/HairData"  # the hair's prim in Blender's export


def fitted_sphere(points: np.ndarray) -> tuple[np.ndarray, float]:
    """The sphere through the roots, least squares (|p|² = 2c·p + r² − |c|²)."""
    p = points.astype(np.float64)
    a = np.column_stack([2 * p, np.ones(len(p))])
    sol = np.linalg.lstsq(a, (p**2).sum(1), rcond=None)[0]
    centre = sol[:3]
    return centre, float(np.sqrt(sol[3] + centre @ centre))


def write_sphere_obj(path: Path, centre: np.ndarray, radius: float, n: int = 24) -> None:
    """A UV sphere as an OBJ, the head the Blender hair grows on."""
    rows = []
    for i in range(1, n):
        th = np.pi * i / n
        for j in range(2 * n):
            ph = np.pi * j / n
            rows.append(
                centre + radius * np.array([np.sin(th) * np.cos(ph), np.sin(th) * np.sin(ph), np.cos(th)])
            )
    pole = np.array([0.0, 0.0, radius])
    rows += [centre + pole, centre - pole]
    top, bottom, m = len(rows) - 1, len(rows), 2 * n
    faces = []
    for i in range(n - 2):
        for j in range(m):
            a, b = i * m + j + 1, i * m + (j + 1) % m + 1
            faces += [(a, a + m, b + m), (a, b + m, b)]
    for j in range(m):
        faces += [(top, j + 1, (j + 1) % m + 1)]
        last = (n - 2) * m
        faces += [(bottom, last + (j + 1) % m + 1, last + j + 1)]
    text = "".join(f"v {x:.9g} {y:.9g} {z:.9g}\n" for x, y, z in rows)
    text += "".join(f"f {a} {b} {c}\n" for a, b, c in faces)
    path.write_text(text)


def stroke(brush: str, cursor, *, direction=(0.0, 0.0, 0.0), radius=0.05, strength=0.5, params=None) -> dict:
    samples = [
        {
            "cursor": list(map(float, cursor + k * np.asarray(direction))),
            "direction": list(direction),
            "radius": radius,
            "strength": strength,
        }
        for k in range(2)
    ]
    return {"brush": brush, "falloff": "smooth", "symmetry": None, "params": params or {}, "samples": samples}


def brush_logs(groom) -> dict[str, list[dict]]:
    """One log per brush, each under the tip (or root) of a strand in the middle of the groom."""
    tips = groom.points[groom.topology.tip_indices].astype(np.float64)
    roots = groom.roots.astype(np.float64)
    s = len(tips) // 2
    tip, root, d = tips[s], roots[s], (0.01, 0.0, -0.005)
    o = int(groom.offsets[s])
    middle = groom.points[o + int(groom.counts[s]) // 2].astype(np.float64)
    return {
        "align": [
            {**stroke("align", tip + np.array([0.02, 0.0, 0.0]), strength=0.7), "params": {"mode": "paper"}}
        ],
        "comb": [stroke("comb", tip, direction=d)],
        "smooth": [stroke("smooth", tip)],
        "length": [stroke("length", tip, strength=-0.2)],
        "puff": [
            stroke("comb", tip, direction=(0.05, 0.0, 0.0), strength=1.0),
            stroke("puff", root, strength=1.0),
        ],
        "pinch": [stroke("pinch", tip)],
        "clump": [stroke("clump", tip, strength=-0.8)],
        "mask": [stroke("mask", tip, strength=1.0), stroke("comb", tip, direction=d)],
        "select": [
            stroke("select", tip, strength=1.0),
            {**stroke("comb", tip, direction=d), "only_selected": True},
        ],
        "snake_hook": [stroke("snake_hook", tip, direction=d)],
        "delete": [stroke("delete", root, radius=0.03)],
        "slide": [stroke("slide", root, direction=d, radius=0.03)],
        "add": [stroke("add", root, params={"count": 3, "seed": 1})],
        "density": [stroke("density", root, params={"spacing": 0.004, "seed": 2})],
        "cut": [stroke("cut", middle, radius=0.01)],
    }


@pytest.fixture(scope="module")
def scene(tmp_path_factory):
    """Blender's Catmull-Rom groom, the same as npz, a sphere head under it and every log."""
    d = tmp_path_factory.mktemp("usd_strokes")
    groom = io.read(DATA / "b.usda")
    io.write(d / "b.npz", groom)
    centre, radius = fitted_sphere(groom.roots)
    write_sphere_obj(d / "head.obj", centre, radius)
    for brush, log in brush_logs(groom).items():
        (d / f"{brush}.json").write_text(json.dumps(log))
    assert main(["freeze", str(DATA / "b.usda"), str(d / "unbrushed.usda"), "--seed", "3"]) == 0
    return d, io.read(d / "unbrushed.usda")


BRUSHES = (
    "align",
    "comb",
    "smooth",
    "length",
    "puff",
    "pinch",
    "clump",
    "mask",
    "select",
    "snake_hook",
    "delete",
    "slide",
    "add",
    "density",
    "cut",
)


def test_the_logs_cover_every_brush(scene):
    from hairtool.frozen.brushes import BRUSHES as LOGGED

    assert set(BRUSHES) == {"align", *LOGGED}


#: How the strokes that plant and remove strands change their count (a 2-sample stroke).
STRAND_COUNT = {
    "delete": lambda now, was: now < was,
    "add": lambda now, was: now == was + 6,
    "density": lambda now, was: now != was,
}


@pytest.mark.parametrize("brush", BRUSHES)
def test_every_brushs_log_replays_on_a_usd_groom(scene, brush):
    d, unbrushed = scene
    out = {}
    for src in ("b.npz", str(DATA / "b.usda")):
        dst = d / f"{brush}_{Path(src).stem}.{'usda' if src.endswith('usda') else 'npz'}"
        args = ["freeze", str(d / src) if src == "b.npz" else src, str(dst), "--seed", "3"]
        args += ["--strokes", str(d / f"{brush}.json"), "--scalp", str(d / "head.obj")]
        assert main(args) == 0, brush
        out[src] = io.read(dst)
    usd, npz = out[str(DATA / "b.usda")], out["b.npz"]
    np.testing.assert_array_equal(usd.points, npz.points)
    (prim,) = usd.metadata.curves
    assert (prim.path, prim.basis, prim.wrap) == (PRIM, "catmullRom", "pinned")
    assert prim.strands == usd.strand_count
    assert (usd.metadata.up_axis, usd.metadata.meters_per_unit) == ("Z", 1.0)
    before = unbrushed
    if len(json.loads((d / f"{brush}.json").read_text())) > 1 and brush not in ("mask", "select"):
        prefix = json.loads((d / f"{brush}.json").read_text())[:-1]  # the last stroke must do something
        (d / f"{brush}_prefix.json").write_text(json.dumps(prefix))
        args = ["freeze", str(DATA / "b.usda"), str(d / f"{brush}_prefix.usda"), "--seed", "3"]
        assert main([*args, "--strokes", str(d / f"{brush}_prefix.json")]) == 0
        before = io.read(d / f"{brush}_prefix.usda")
    if brush in STRAND_COUNT:
        assert STRAND_COUNT[brush](usd.strand_count, unbrushed.strand_count), usd.strand_count
    else:
        assert usd.strand_count == before.strand_count
        assert not np.array_equal(usd.points, before.points)


@pytest.mark.slow(seconds=15)
def test_a_batch_job_replays_a_comb_log_on_a_usd_groom(scene):
    d, _ = scene
    job = Job(0, "freeze", (str(DATA / "b.usda"), "batch_out.usda", "--strokes", "comb.json"), str(d))
    result = run_job(job)
    assert result["status"] == "done" and result["error"] is None, result["error"]
    by_hand = ["freeze", str(DATA / "b.usda"), str(d / "by_hand.usda"), "--strokes", str(d / "comb.json")]
    assert main(by_hand) == 0
    assert (d / "batch_out.usda").read_bytes() == (d / "by_hand.usda").read_bytes()


def test_deleting_strands_keeps_the_prim_its_basis_and_its_parents_transforms(scene):
    d, _ = scene
    src = io.read(DATA / "b_xform.usdc")
    assert src.metadata.xforms  # the hair's parent is translated, rotated and scaled
    out = d / "deleted.usdc"
    assert main(["freeze", str(DATA / "b_xform.usdc"), str(out), "--strokes", str(d / "xdelete.json")]) == 0
    got = io.read(out)
    (prim,) = got.metadata.curves
    (was,) = src.metadata.curves
    assert got.strand_count < src.strand_count
    assert (prim.path, prim.basis, prim.wrap) == (was.path, was.basis, was.wrap)
    assert got.metadata.xforms == src.metadata.xforms
    from pxr import Usd, UsdGeom

    stage = Usd.Stage.Open(str(out))
    parent = stage.GetPrimAtPath(prim.path).GetParent()
    assert UsdGeom.Xformable(parent).GetOrderedXformOps()  # the transform is on the parent again


@pytest.fixture(scope="module", autouse=True)
def _xform_delete_log(scene):
    d, _ = scene
    g = io.read(DATA / "b_xform.usdc")
    root = g.roots[len(g.roots) // 2].astype(np.float64)
    size = float(np.linalg.norm(np.ptp(g.points, axis=0)))
    (d / "xdelete.json").write_text(json.dumps([stroke("delete", root, radius=size / 8)]))


def test_the_pipeline_keeps_the_prim_through_delete_and_add(scene):
    """Below the command (which writes each result as its source's prim): the pipeline's own result."""
    from hairtool.frozen.pipeline import FrozenPipeline
    from hairtool.frozen.strokes import read_strokes
    from hairtool.guides.planting import HeadSurface
    from hairtool.io.obj import read_mesh

    d, _ = scene
    groom = io.read(DATA / "b.usda")
    (was,) = groom.metadata.curves
    head = HeadSurface(read_mesh(d / "head.obj"))
    for brush in ("delete", "add"):
        pipe = FrozenPipeline(groom, surface=head)
        for s in read_strokes(d / f"{brush}.json"):
            pipe.apply_samples(s.pipeline_samples(float(pipe.scalp_centre[0])))
        pipe.settle()
        (prim,) = pipe.result.metadata.curves
        assert (prim.path, prim.basis, prim.wrap) == (was.path, was.basis, was.wrap)
        assert prim.strands == pipe.result.strand_count != groom.strand_count
