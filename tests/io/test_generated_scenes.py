"""Generated USD scenes (:mod:`usd_scenes`) through the commands: ``info``, ``convert``,
``freeze``, ``interpolate`` (animated on an animated stage), ``simulate`` and ``anime`` (a few
frames), and a log of every brush that needs no head replayed by ``freeze --strokes`` (a
custom primvar then fits the strands delete left). Prim paths, bases and the stage's
conventions are kept, and the world-space results equal those of the scene's twin in the other
up axis and unit.

CI runs a few examples (a minute at most); a longer run:
``HAIRTOOL_SCENE_EXAMPLES=200 pytest -n 0 tests/io/test_generated_scenes.py``.
"""

from __future__ import annotations

import json
import os
import tempfile
from pathlib import Path

import numpy as np
from hypothesis import HealthCheck, given, settings

from hairtool import io
from hairtool.cli import main
from hairtool.groom import Animation

from .usd_scenes import Scene, scenes, write_stage

EXAMPLES = int(os.environ.get("HAIRTOOL_SCENE_EXAMPLES", "6"))
RUN = settings(
    max_examples=EXAMPLES,
    deadline=None,
    suppress_health_check=[HealthCheck.too_slow],
    derandomize=EXAMPLES <= 6,
)


def world_metres(obj, scene_up: str, mpu: float) -> np.ndarray:
    """Points (the first frame of an animation) in a Y-up metre frame."""
    p = (obj.frames[0] if isinstance(obj, Animation) else obj.points).astype(np.float64) * mpu
    return np.stack([p[:, 0], p[:, 2], -p[:, 1]], axis=1) if scene_up == "Z" else p


def curve_paths(obj) -> list[str]:
    return [c.path for c in obj.metadata.curves]


def expected_paths(scene: Scene) -> list[str]:
    paths = [p.path for p in scene.prims]
    return [*paths, "/Moving/Strands"] if scene.animated == "transform" else paths


def check_kept(scene: Scene, src, out) -> None:
    assert curve_paths(out) == curve_paths(src) == expected_paths(scene)
    assert [c.basis for c in out.metadata.curves] == [c.basis for c in src.metadata.curves]
    assert (out.metadata.up_axis, out.metadata.meters_per_unit) == (scene.up, scene.meters_per_unit)


def twin_of(scene: Scene) -> tuple[str, float]:
    return ("Y" if scene.up == "Z" else "Z"), (1.0 if scene.meters_per_unit == 0.01 else 0.01)


@RUN
@given(scene=scenes())
def test_info_and_convert_keep_prims_conventions_and_world_points(scene):
    with tempfile.TemporaryDirectory() as tmp:
        d = Path(tmp)
        write_stage(d / "s.usda", scene)
        write_stage(d / "t.usda", scene, twin=True)
        assert main(["info", str(d / "s.usda")]) == 0
        for ext in ("usda", "usdc", "npz"):
            assert main(["convert", str(d / "s.usda"), str(d / f"out.{ext}")]) == 0
        src = io.read(d / "s.usda")
        for ext in ("usda", "usdc"):
            out = io.read(d / f"out.{ext}")
            check_kept(scene, src, out)
            np.testing.assert_allclose(
                out.points if not isinstance(out, Animation) else out.frames,
                src.points if not isinstance(src, Animation) else src.frames,
                rtol=1e-5,
                atol=1e-5 * np.abs(src.points if not isinstance(src, Animation) else src.frames).max(),
            )
        assert main(["convert", str(d / "out.npz"), str(d / "back.usda")]) == 0
        check_kept(scene, src, io.read(d / "back.usda"))
        twin_up, twin_mpu = twin_of(scene)
        twin = io.read(d / "t.usda")
        a = world_metres(src, scene.up, scene.meters_per_unit)
        b = world_metres(twin, twin_up, twin_mpu)
        np.testing.assert_allclose(a, b, atol=2e-6 * max(1.0, np.abs(a).max()))


def custom_primvar(path: Path, prim: str) -> tuple:
    """``(clump_weight values or None, the prim's vertex count)``."""
    from pxr import Usd, UsdGeom

    stage = Usd.Stage.Open(str(path))  # (held: a prim of a freed stage is invalid)
    p = stage.GetPrimAtPath(prim)
    pv = UsdGeom.PrimvarsAPI(p).GetPrimvar("clump_weight")
    counts = UsdGeom.BasisCurves(p).GetCurveVertexCountsAttr().Get()
    return (list(pv.Get()) if pv else None), int(sum(counts))


COMB = [{"brush": "comb", "falloff": "smooth", "symmetry": None, "params": {}, "samples": []}]


#: The brushes that need no head: one stroke each in :func:`brush_log`'s log.
HEADLESS = (
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
)


def brush_log(groom, path: Path) -> None:
    """A stroke of every brush that needs no head, at the middle strand's tip, radius a third of
    the groom's size; delete at the root of the last strand of a prim of two or more, with a
    radius that reaches no other root (a prim's last strand cannot be deleted)."""
    tip = groom.points[groom.topology.tip_indices][groom.strand_count // 2].astype(np.float64)
    ends = np.cumsum([c.strands for c in groom.metadata.curves])
    several = [int(e) - 1 for c, e in zip(groom.metadata.curves, ends, strict=True) if c.strands > 1]
    root = groom.roots[several[0] if several else 0].astype(np.float64)
    size = float(np.linalg.norm(np.ptp(groom.points, axis=0)))
    gaps = np.linalg.norm(groom.roots.astype(np.float64) - root, axis=1)
    alone = float(np.min(gaps[gaps > 0], initial=size)) / 2
    log = []
    for brush in HEADLESS if several else HEADLESS[:-1]:
        at, radius, strength = (root, alone, 1.0) if brush == "delete" else (tip, size / 3, 0.8)
        sample = {
            "cursor": at.tolist(),
            "direction": [size * 0.05, 0, 0],
            "radius": radius,
            "strength": strength,
        }
        params = {"mode": "paper"} if brush == "align" else {}
        log.append({**COMB[0], "brush": brush, "params": params, "samples": [sample]})
    path.write_text(json.dumps(log))


@RUN
@given(scene=scenes())
def test_freeze_and_a_stroke_log_keep_prims_and_conventions(scene):
    with tempfile.TemporaryDirectory() as tmp:
        d = Path(tmp)
        write_stage(d / "s.usda", scene)
        src = io.read(d / "s.usda")
        pose = ["--frame", "0"] if isinstance(src, Animation) else []
        assert main(["freeze", str(d / "s.usda"), str(d / "f.usda"), "--seed", "2", *pose]) == 0
        out = io.read(d / "f.usda")
        check_kept(scene, src, out)
        assert out.strand_count == src.strand_count
        first = src.frame(0) if isinstance(src, Animation) else src
        brush_log(first, d / "comb.json")
        args = ["freeze", str(d / "s.usda"), str(d / "c.usda"), "--strokes", str(d / "comb.json"), *pose]
        assert main(args) == 0
        check_kept(scene, src, io.read(d / "c.usda"))
        for prim in scene.prims:  # a custom primvar fits the strands the log left (delete's too)
            got, vertices = custom_primvar(d / "c.usda", prim.path)
            assert (got is not None) == prim.custom and (got is None or len(got) == vertices), prim.path
        assert main(["interpolate", str(d / "s.usda"), str(d / "k.usda"), "--count", "12"]) == 0
        kids = io.read(d / "k.usda")
        want = [x for p in curve_paths(src) for x in ((p + "Render", "default"), (p, "guide"))]
        assert [(c.path, c.purpose) for c in kids.metadata.curves] == want
        assert (kids.metadata.up_axis, kids.metadata.meters_per_unit) == (scene.up, scene.meters_per_unit)
        if isinstance(src, Animation):  # children on every frame, at the source's time codes
            assert isinstance(kids, Animation) and list(kids.time_codes) == list(src.time_codes)
        # --prim: the first prim frozen, the others as they were
        assert (
            main(["freeze", str(d / "s.usda"), str(d / "p.usda"), "--prim", scene.prims[0].path, *pose]) == 0
        )
        picked = io.read(d / "p.usda")
        check_kept(scene, src, picked)
        n0 = sum(scene.prims[0].counts)
        rest = first.subset(np.arange(n0, first.strand_count)) if first.strand_count > n0 else None
        if rest is not None:
            got = picked.subset(np.arange(n0, picked.strand_count))
            np.testing.assert_allclose(
                got.points, rest.points, rtol=0, atol=1e-6 * max(1.0, np.abs(rest.points).max())
            )


@RUN
@given(scene=scenes())
def test_clumping_gives_the_same_world_hair_in_any_axes_and_unit(scene):
    with tempfile.TemporaryDirectory() as tmp:
        d = Path(tmp)
        write_stage(d / "s.usda", scene)
        write_stage(d / "t.usda", scene, twin=True)
        pose = ["--frame", "0"] if scene.animated else []
        for name in ("s", "t"):
            args = ["freeze", str(d / f"{name}.usda"), str(d / f"{name}_f.usda"), "--no-freeze", *pose]
            assert main(args) == 0
        twin_up, twin_mpu = twin_of(scene)
        a = world_metres(io.read(d / "s_f.usda"), scene.up, scene.meters_per_unit)
        b = world_metres(io.read(d / "t_f.usda"), twin_up, twin_mpu)
        np.testing.assert_allclose(a, b, rtol=0, atol=1e-5 * max(1.0, float(np.abs(a).max())))


@RUN
@given(scene=scenes())
def test_simulate_and_anime_keep_prims_conventions_and_the_source_start(scene):
    """A few frames each; on an animated stage the simulation's roots are the source's."""
    with tempfile.TemporaryDirectory() as tmp:
        d = Path(tmp)
        write_stage(d / "s.usda", scene)
        src = io.read(d / "s.usda")
        first = float(src.time_codes[0]) if isinstance(src, Animation) else 0.0
        args = ["simulate", str(d / "s.usda"), str(d / "sim.usda"), "--fit-head", "--substeps", "1"]
        assert main([*args, "--frames", "3"]) == 0
        sim = io.read(d / "sim.usda")
        check_kept(scene, src, sim)
        assert isinstance(sim, Animation) and sim.time_codes[0] == first and sim.n_frames == 3
        if isinstance(src, Animation):
            idx = src.topology.root_indices
            scale = max(1.0, float(np.abs(src.frames).max()))
            np.testing.assert_allclose(sim.frames[:, idx], src.frames[:3, idx], rtol=0, atol=1e-6 * scale)
        assert main(["anime", str(d / "s.usda"), str(d / "a.usda"), "--frames", "3"]) == 0
        cycle = io.read(d / "a.usda")
        check_kept(scene, src, cycle)
        assert isinstance(cycle, Animation) and cycle.time_codes[0] == first
        # children: each prim's beside its own guides, as interpolate --count writes them
        assert main([*args, "--frames", "2", "--count", "6", "--no-clump-children"]) == 0
        kids = io.read(d / "sim.usda")
        want = [x for p in curve_paths(src) for x in ((p + "Render", "default"), (p, "guide"))]
        assert [(c.path, c.purpose) for c in kids.metadata.curves] == want
