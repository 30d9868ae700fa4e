"""USD ``BasisCurves`` (``.usda`` text, ``.usdc`` crate, ``.usd`` either) through usd-core (``pxr``).

Writing: one linear BasisCurves prim ``/Groom/Strands`` under an Xform that is the default prim;
an animation's points are time samples (frame f at time code f, or ``time_codes[f]``) with
``timeCodesPerSecond`` = ``framesPerSecond`` = fps and start/end time codes set. Thickness is
written as vertex ``widths`` (a diameter, like HAIR's thickness), colours as a vertex
``displayColor`` primvar, transparency as ``displayOpacity`` = 1 − transparency.

Reading: every BasisCurves prim on the stage is merged in traversal order, each moved into world
space by its local-to-world transform (skipped when it is the identity, so round trips are
bit-exact). Prims with time-sampled points make an Animation sampled at every authored time code
of the union (a sparse export reads back as its key poses only); the up axis is kept as authored
(a z-up stage reads z-up). Curve bases other than linear are read as their control points.

``pxr`` is imported inside the functions: usd-core takes a second or more to import.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from hairtool.errors import FormatError, ParameterError
from hairtool.groom import Animation, Groom
from hairtool.io.atomic import atomic_path
from hairtool.io.binary import require_finite, require_strand_counts

PRIM_PATH = "/Groom/Strands"


def _time_codes(obj: Groom | Animation, time_codes: Sequence[float] | None) -> np.ndarray | None:
    if isinstance(obj, Groom):
        if time_codes is not None:
            raise ParameterError("time_codes", time_codes, "None for a static groom")
        return None
    if time_codes is None:
        return np.arange(obj.n_frames, dtype=np.float64)
    t = np.asarray(time_codes, dtype=np.float64).reshape(-1)
    if t.size != obj.n_frames:
        raise ParameterError("time_codes", f"{t.size} values", f"one per frame ({obj.n_frames})")
    if not np.all(np.isfinite(t)) or np.any(np.diff(t) <= 0):
        raise ParameterError("time_codes", time_codes, "finite, strictly increasing numbers")
    return t


def _extent(points: np.ndarray, half_width: float):
    from pxr import Vt

    lo = points.min(axis=0).astype(np.float64) - half_width
    hi = points.max(axis=0).astype(np.float64) + half_width
    return Vt.Vec3fArray.FromNumpy(np.stack([lo, hi]).astype(np.float32))


def write(path: Path, obj: Groom | Animation, *, time_codes: Sequence[float] | None = None) -> None:
    """Write a groom, or an animation as time-sampled points.

    ``time_codes``: for an animation, the time code of each frame (F strictly increasing
    numbers; default 0..F−1) — a keys-only export writes just its key poses at their frame
    numbers, and USD readers interpolate linearly between them.
    """
    times = _time_codes(obj, time_codes)
    from pxr import Usd, UsdGeom, Vt

    with atomic_path(path) as tmp:
        stage = Usd.Stage.CreateNew(str(tmp))
        if stage is None:
            raise FormatError(path, "usd-core could not create the stage")
        UsdGeom.SetStageUpAxis(stage, UsdGeom.Tokens.y)
        root = UsdGeom.Xform.Define(stage, PRIM_PATH.rsplit("/", 1)[0])
        stage.SetDefaultPrim(root.GetPrim())
        curves = UsdGeom.BasisCurves.Define(stage, PRIM_PATH)
        curves.CreateTypeAttr(UsdGeom.Tokens.linear)
        curves.CreateCurveVertexCountsAttr(Vt.IntArray.FromNumpy(obj.counts.astype(np.int32)))
        half_width = 0.0
        if obj.thickness is not None:
            curves.CreateWidthsAttr(Vt.FloatArray.FromNumpy(obj.thickness))
            curves.SetWidthsInterpolation(UsdGeom.Tokens.vertex)
            half_width = float(np.abs(obj.thickness).max()) / 2
        if obj.colors is not None:
            curves.CreateDisplayColorPrimvar(UsdGeom.Tokens.vertex).Set(Vt.Vec3fArray.FromNumpy(obj.colors))
        if obj.transparency is not None:
            opacity = (1.0 - obj.transparency).astype(np.float32)
            curves.CreateDisplayOpacityPrimvar(UsdGeom.Tokens.vertex).Set(Vt.FloatArray.FromNumpy(opacity))
        points_attr = curves.CreatePointsAttr()
        extent_attr = curves.CreateExtentAttr()
        if times is None:
            points_attr.Set(Vt.Vec3fArray.FromNumpy(obj.points))
            extent_attr.Set(_extent(obj.points, half_width))
        else:
            for f, t in enumerate(times):
                code = Usd.TimeCode(float(t))
                points_attr.Set(Vt.Vec3fArray.FromNumpy(obj.frames[f]), code)
                extent_attr.Set(_extent(obj.frames[f], half_width), code)
            stage.SetStartTimeCode(float(times[0]))
            stage.SetEndTimeCode(float(times[-1]))
            stage.SetTimeCodesPerSecond(obj.fps)
            stage.SetFramesPerSecond(obj.fps)
        stage.GetRootLayer().Save()
        del stage


def _last_line(error: Exception) -> str:
    """The last line of a pxr error; its message may quote undecodable bytes of the file."""
    try:
        text = str(error).strip()
    except UnicodeDecodeError:
        return "the file is not valid USD (undecodable bytes)"
    return text.splitlines()[-1].strip() if text else "unknown error"


def _open_stage(path: Path):
    from pxr import Sdf, Tf, Usd

    if path.stat().st_size == 0:
        raise FormatError(path, "the file is empty")
    try:
        layer = Sdf.Layer.Find(str(path))
        # A layer still cached from an earlier open may be stale: the file can have been replaced.
        if layer is not None and not layer.Reload(True):
            raise FormatError(path, "usd-core cannot reload it")
        if layer is None:
            layer = Sdf.Layer.FindOrOpen(str(path))
        stage = Usd.Stage.Open(layer) if layer is not None else None
    except Tf.ErrorException as e:
        raise FormatError(path, f"usd-core cannot open it: {_last_line(e)}") from None
    if stage is None:
        raise FormatError(path, "usd-core cannot open it")
    return stage


def _per_vertex(values, interpolation: str, counts: np.ndarray, width: int) -> np.ndarray | None:
    """Expand a constant / uniform / vertex primvar to one value per vertex; None if it does not fit."""
    if values is None:
        return None
    a = np.asarray(values, dtype=np.float32).reshape(-1, width) if len(values) else None
    if a is None:
        return None
    v, s = int(counts.sum()), counts.size
    if a.shape[0] == v and interpolation in ("vertex", "varying"):
        out = a
    elif a.shape[0] == s and interpolation == "uniform":
        out = np.repeat(a, counts, axis=0)
    elif a.shape[0] == 1 and interpolation == "constant":
        out = np.repeat(a, v, axis=0)
    else:
        return None
    if not np.all(np.isfinite(out)):
        return None
    return out if width > 1 else out.reshape(-1)


class _Curves:
    """One BasisCurves prim: its topology, points attribute and world transform."""

    def __init__(self, path: Path, prim) -> None:
        from pxr import Usd, UsdGeom

        self.curves = UsdGeom.BasisCurves(prim)
        name = str(prim.GetPath())
        raw = self.curves.GetCurveVertexCountsAttr().Get(Usd.TimeCode.EarliestTime())
        if raw is None or len(raw) == 0:
            raise FormatError(path, f"{name} has no curveVertexCounts")
        self.counts = np.asarray(raw, dtype=np.int64)
        require_strand_counts(path, self.counts)
        self.vertex_count = int(self.counts.sum())
        self.points = self.curves.GetPointsAttr()
        self.times = [float(t) for t in self.points.GetTimeSamples()]
        self.name, self.path, self.prim = name, path, prim

    def at(self, time) -> np.ndarray:
        from pxr import Gf, UsdGeom

        value = self.points.Get(time)
        if value is None:
            raise FormatError(self.path, f"{self.name} has no points")
        p = np.asarray(value, dtype=np.float32)
        if p.ndim != 2 or p.shape != (self.vertex_count, 3):
            raise FormatError(
                self.path,
                f"{self.name}: curveVertexCounts add up to {self.vertex_count} points "
                f"but points has {p.shape[0] if p.ndim else 0}",
            )
        m = UsdGeom.Xformable(self.prim).ComputeLocalToWorldTransform(time)
        if m != Gf.Matrix4d(1.0):
            m = np.asarray(m, dtype=np.float64)
            p = (p.astype(np.float64) @ m[:3, :3] + m[3, :3]).astype(np.float32)
        require_finite(self.path, p, f"{self.name} points")
        return p

    def attributes(self) -> dict[str, np.ndarray | None]:
        from pxr import UsdGeom

        widths = self.curves.GetWidthsAttr().Get()
        thickness = _per_vertex(widths, self.curves.GetWidthsInterpolation(), self.counts, 1)
        pv = UsdGeom.PrimvarsAPI(self.prim)
        color_pv, opacity_pv = pv.GetPrimvar("displayColor"), pv.GetPrimvar("displayOpacity")
        colors = opacity = None
        if color_pv and color_pv.HasValue():
            colors = _per_vertex(color_pv.ComputeFlattened(), color_pv.GetInterpolation(), self.counts, 3)
        if opacity_pv and opacity_pv.HasValue():
            opacity = _per_vertex(
                opacity_pv.ComputeFlattened(), opacity_pv.GetInterpolation(), self.counts, 1
            )
        transparency = None if opacity is None else (1.0 - opacity).astype(np.float32)
        return {"thickness": thickness, "transparency": transparency, "colors": colors}


def _merge_attributes(parts: list[_Curves]) -> dict[str, np.ndarray]:
    """An attribute survives the merge only if every prim has it."""
    per_prim = [c.attributes() for c in parts]
    out = {}
    for name in ("thickness", "transparency", "colors"):
        values = [a[name] for a in per_prim]
        if all(v is not None for v in values):
            out[name] = np.concatenate(values)
    return out


def read(path: Path) -> Groom | Animation:
    """Merge every BasisCurves prim; time-sampled points make an Animation at the union of time codes."""
    from pxr import Usd, UsdGeom

    stage = _open_stage(path)
    prims = [p for p in stage.Traverse() if p.IsA(UsdGeom.BasisCurves)]
    if not prims:
        raise FormatError(path, "no BasisCurves prim on the stage")
    parts = [_Curves(path, p) for p in prims]
    counts = np.concatenate([c.counts for c in parts])
    attrs = _merge_attributes(parts)
    times = sorted(set().union(*(c.times for c in parts)))
    if not times:
        points = np.concatenate([c.at(Usd.TimeCode.Default()) for c in parts])
        return Groom(points, counts, **attrs)
    frames = np.stack([np.concatenate([c.at(Usd.TimeCode(t)) for c in parts]) for t in times])
    fps = float(stage.GetTimeCodesPerSecond())
    if not (np.isfinite(fps) and fps > 0):
        raise FormatError(path, f"timeCodesPerSecond is {fps}; expected a positive number")
    return Animation(frames, counts, fps, **attrs)


def time_codes(path: str | os.PathLike[str]) -> list[float]:
    """The union of the authored time codes of every BasisCurves prim's points (empty when static)."""
    from pxr import UsdGeom

    p = Path(path)
    stage = _open_stage(p)
    prims = [q for q in stage.Traverse() if q.IsA(UsdGeom.BasisCurves)]
    return sorted(set().union(*(UsdGeom.BasisCurves(q).GetPointsAttr().GetTimeSamples() for q in prims)))
