"""A hypothesis strategy for USD stages as DCCs write them, and the stage's twin in other axes
and units.

A scene: Y or Z up, 0.01 or 1 m per unit; 1-3 curve prims, each under its own chain of 0-2
Xforms whose transforms are translate/rotate/scale ops or one matrix op; each prim linear,
Catmull-Rom or B-spline, with widths, a colour and a custom primvar each present or absent; a
mesh prim beside them; points (with the prim's widths and colour) or a parent's transform
time-sampled, or neither. A scene is plain data (:class:`Scene`); :func:`write_stage` makes
the file, ``twin=True`` the same hair in the other up axis and unit (points and translations
turned and scaled), so that world-space results can be compared between the two.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from hypothesis import strategies as st

BASES = ("linear", "catmullRom", "bspline")


@dataclass(frozen=True)
class Prim:
    path: str
    #: (path, "trs" or "matrix", (tx, ty, tz, degrees about the up axis, uniform scale))
    parents: tuple[tuple[str, str, tuple[float, ...]], ...]
    basis: str
    counts: tuple[int, ...]
    seed: int
    widths: bool
    colour: bool
    custom: bool


@dataclass(frozen=True)
class Scene:
    up: str
    meters_per_unit: float
    prims: tuple[Prim, ...]
    mesh: bool
    animated: str | None  # None, "points" or "transform" (the first prim's parent)


def _ops(draw) -> tuple[str, tuple[float, ...]]:
    small = st.floats(-1.0, 1.0, allow_nan=False, width=32)
    t = [draw(small) for _ in range(3)]
    angle = draw(st.floats(-90.0, 90.0, width=32))  # about the up axis
    s = draw(st.floats(0.5, 2.0, width=32))
    return draw(st.sampled_from(("trs", "matrix"))), (*t, angle, s)


@st.composite
def scenes(draw, animated: bool = True, motions: tuple = (None, "points", "transform")) -> Scene:
    """A scene (module doc); ``animated`` False: static, else one of ``motions``."""
    n = draw(st.integers(1, 3))
    prims = []
    for k in range(n):
        depth = draw(st.integers(0, 2))
        parents, path = [], ""
        for level in range(depth):
            path += f"/{'Grp' if level else 'Root'}{k}_{level}"
            parents.append((path, *_ops(draw)))
        basis = draw(st.sampled_from(BASES))
        least = 2 if basis == "linear" else 4
        counts = tuple(draw(st.lists(st.integers(least, 8), min_size=1, max_size=12)))
        prims.append(
            Prim(
                f"{path}/Hair{k}",
                tuple(parents),
                basis,
                counts,
                draw(st.integers(0, 2**16)),
                draw(st.booleans()),
                draw(st.booleans()),
                draw(st.booleans()),
            )
        )
    return Scene(
        draw(st.sampled_from(("Y", "Z"))),
        draw(st.sampled_from((0.01, 1.0))),
        tuple(prims),
        draw(st.booleans()),
        draw(st.sampled_from(motions)) if animated else None,
    )


def _to_z(v: np.ndarray) -> np.ndarray:
    """Y-up reference (x, y, z) ↦ Z-up (x, −z, y)."""
    return np.stack([v[..., 0], -v[..., 2], v[..., 1]], axis=-1)


def _local(scene: Scene, up: str, mpu: float, v: np.ndarray) -> np.ndarray:
    """Positions made in a Y-up metre frame, in the stage's axes and unit."""
    v = np.asarray(v, np.float64) / mpu
    return _to_z(v) if up == "Z" else v


def write_stage(path, scene: Scene, *, twin: bool = False) -> None:
    """The scene as a USD file; ``twin``: in the other up axis and unit (the same hair in
    the world, every point and translation turned and scaled; rotations about the up axis)."""
    from pxr import Gf, Sdf, Usd, UsdGeom, Vt

    up = scene.up if not twin else ("Y" if scene.up == "Z" else "Z")
    mpu = scene.meters_per_unit if not twin else (1.0 if scene.meters_per_unit == 0.01 else 0.01)
    stage = Usd.Stage.CreateNew(str(path))
    UsdGeom.SetStageUpAxis(stage, up)
    UsdGeom.SetStageMetersPerUnit(stage, mpu)
    times = (1.0, 2.0, 3.0) if scene.animated else ()
    if times:
        stage.SetStartTimeCode(1.0)
        stage.SetEndTimeCode(3.0)
        stage.SetTimeCodesPerSecond(24.0)
    for k, prim in enumerate(scene.prims):
        for ppath, kind, (tx, ty, tz, angle, s) in prim.parents:
            xf = UsdGeom.Xform.Define(stage, ppath)
            t = _local(scene, up, mpu, [tx * 0.1, ty * 0.1, tz * 0.1])
            # a turn about the up axis (the same turn in both frames) and a uniform scale
            axis = Gf.Vec3d(0, 0, 1) if up == "Z" else Gf.Vec3d(0, 1, 0)
            if kind == "trs":
                xf.AddTranslateOp().Set(Gf.Vec3d(*t))
                (xf.AddRotateZOp() if up == "Z" else xf.AddRotateYOp()).Set(angle)
                xf.AddScaleOp().Set(Gf.Vec3f(s, s, s))
            else:
                m = Gf.Matrix4d().SetScale(Gf.Vec3d(s, s, s)) * Gf.Matrix4d().SetRotate(
                    Gf.Rotation(axis, angle)
                )
                m = m * Gf.Matrix4d().SetTranslate(Gf.Vec3d(*t))
                xf.AddTransformOp().Set(m)
        rng = np.random.default_rng(prim.seed)
        counts = np.asarray(prim.counts)
        v = int(counts.sum())
        ref = np.concatenate(
            [
                rng.normal(size=3) * 0.05 + np.linspace(0, 1, c)[:, None] * (rng.normal(size=3) * 0.03)
                for c in counts
            ]
        )
        curves = UsdGeom.BasisCurves.Define(stage, prim.path)
        if prim.basis == "linear":
            curves.CreateTypeAttr("linear")
        else:
            curves.CreateTypeAttr("cubic")
            curves.CreateBasisAttr(prim.basis)
            curves.CreateWrapAttr("pinned")
        curves.CreateCurveVertexCountsAttr(Vt.IntArray([int(c) for c in counts]))
        pts = curves.CreatePointsAttr()
        local = _local(scene, up, mpu, ref).astype(np.float32)
        if scene.animated == "points" and k == 0:
            for f, t in enumerate(times):
                pts.Set(Vt.Vec3fArray.FromNumpy((local * (1 + 0.1 * f)).astype(np.float32)), t)
        else:
            pts.Set(Vt.Vec3fArray.FromNumpy(local))
        # the time-sampled prim samples its widths and colour too, the first sample as a static one
        sampled = times if scene.animated == "points" and k == 0 else (None,)
        if prim.widths:
            widths = curves.CreateWidthsAttr()
            for f, t in enumerate(sampled):
                at = () if t is None else (t,)
                widths.Set(Vt.FloatArray.FromNumpy(np.full(v, 8e-5 * (1 + f) / mpu, np.float32)), *at)
            curves.SetWidthsInterpolation("vertex")
        pv = UsdGeom.PrimvarsAPI(curves.GetPrim())
        if prim.colour:
            colour = rng.uniform(0, 1, (v, 3)).astype(np.float32)
            shown = curves.CreateDisplayColorPrimvar("vertex")
            for f, t in enumerate(sampled):
                at = () if t is None else (t,)
                shown.Set(Vt.Vec3fArray.FromNumpy(colour * np.float32(1 - 0.2 * f)), *at)
        if prim.custom:
            pv.CreatePrimvar("clump_weight", Sdf.ValueTypeNames.FloatArray, "vertex").Set(
                Vt.FloatArray.FromNumpy(rng.uniform(0, 1, v).astype(np.float32))
            )
    if scene.animated == "transform":
        root = UsdGeom.Xform.Define(stage, "/Moving")
        op = root.AddTranslateOp()
        for f, t in enumerate(times):
            op.Set(Gf.Vec3d(*_local(scene, up, mpu, [0.01 * f, 0.0, 0.0])), t)
        curves = UsdGeom.BasisCurves.Define(stage, "/Moving/Strands")
        curves.CreateTypeAttr("linear")
        curves.CreateCurveVertexCountsAttr(Vt.IntArray([2, 2]))
        ends = _local(scene, up, mpu, [[0, 0, 0], [0, 0.02, 0], [0.01, 0, 0], [0.01, 0.02, 0.0]])
        curves.CreatePointsAttr(Vt.Vec3fArray.FromNumpy(ends.astype(np.float32)))
    if scene.mesh:
        mesh = UsdGeom.Mesh.Define(stage, "/Head")
        quad = _local(scene, up, mpu, [[0, 0, 0], [0.1, 0, 0], [0.1, 0.1, 0], [0, 0.1, 0]])
        mesh.CreatePointsAttr(Vt.Vec3fArray.FromNumpy(quad.astype(np.float32)))
        mesh.CreateFaceVertexCountsAttr(Vt.IntArray([4]))
        mesh.CreateFaceVertexIndicesAttr(Vt.IntArray([0, 1, 2, 3]))
    stage.GetRootLayer().Save()
