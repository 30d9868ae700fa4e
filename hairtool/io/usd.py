"""USD ``BasisCurves`` (``.usda`` text, ``.usdc`` crate, ``.usd`` either) through usd-core (``pxr``).

Reading takes a stage as DCCs write it (Blender 5's exports in ``shared/data/interop`` are the
test cases):

- every BasisCurves prim, merged in traversal order into one groom; each prim's path, strand
  count, basis and wrap go into the groom's :class:`~hairtool.metadata.Metadata` so that writing
  it back recreates the same prims;
- world points: each prim's local-to-world transform at each time (skipped when it is the
  identity, so round trips are bit-exact). Time-sampled points *or* transforms (hair under a
  head that turns) make an Animation sampled at every authored time code of the union, and the
  time codes themselves are kept (a stage sampled at 1…48 stays at 1…48);
- the stage's ``upAxis``, ``metersPerUnit``, ``timeCodesPerSecond`` and start/end time codes
  are kept as authored, one end without the other too (nothing is rotated or scaled); the time
  code rate is the frame rate;
- curves of any basis (linear, cubic bezier / bspline / catmullRom): the control points are the
  strand's points, the basis is remembered, and so is each prim's ``purpose`` (render hair
  beside its guide curves, purpose ``guide``: :mod:`hairtool.guides.files`);
- ``widths`` of every interpolation (see :mod:`hairtool.io.usd_basis`), colour from
  ``displayColor`` or Blender's ``primvars:color`` (color3f or color4f; its alpha is opacity),
  opacity from ``displayOpacity``. Merging prims keeps each one's: a prim without widths or
  colour beside prims with them gets defaults (80 µm, grey) and its record lists what it
  lacked (:attr:`~hairtool.metadata.CurvesPrim.lacks`), so the writer leaves them out again;

Every value is type-checked before it is used and every lazy read of a crate file is guarded, so
a hostile file ends in one :class:`~hairtool.errors.FormatError`.

Writing: the prims of the metadata (one linear ``/Groom/Strands`` under an Xform by default),
their parents as plain Xforms, world points; ``upAxis`` and ``metersPerUnit`` always (hairtool's
defaults: Y-up, 0.01 m per unit); an animation's points as time samples at its time codes with
``timeCodesPerSecond`` = ``framesPerSecond`` = fps. Widths are vertex ``widths`` (a diameter,
like HAIR's thickness), colours a vertex ``displayColor`` (or ``primvars:color`` color4f when
they came from one), transparency ``displayOpacity`` = 1 − transparency. Frames made on demand
(:class:`FrameStream`: render hair following its guides) are written one at a time, and a
crate file is saved as it grows, so a shot larger than memory can be written.

``pxr`` is imported inside the functions: usd-core takes a second or more to import.
"""

from __future__ import annotations

import contextlib
import os
import re
import sys
import tempfile
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Protocol

import numpy as np

from hairtool import interrupts
from hairtool.bounds import box
from hairtool.errors import FormatError, HairtoolError, ParameterError
from hairtool.groom import Animation, Groom, Topology
from hairtool.io import usd_basis, usd_layers, usda_check, usdc_check
from hairtool.io.atomic import atomic_path
from hairtool.io.binary import require_finite, require_strand_counts
from hairtool.metadata import PURPOSES, CurvesPrim, Metadata, join_attributes

PRIM_PATH = "/Groom/Strands"
FLUSH_BYTES = 32 << 20  # unsaved time samples a crate layer may hold before it is saved


class FrameStream(Protocol):
    """An animation whose frames are made one at a time (never held together): what an
    :class:`~hairtool.groom.Animation` offers, with ``frame_points(f)`` for ``frames[f]``."""

    topology: Topology
    metadata: Metadata
    thickness: np.ndarray | None
    transparency: np.ndarray | None
    colors: np.ndarray | None
    fps: float

    @property
    def counts(self) -> np.ndarray: ...
    @property
    def strand_count(self) -> int: ...
    @property
    def vertex_count(self) -> int: ...
    @property
    def n_frames(self) -> int: ...
    @property
    def time_codes(self) -> np.ndarray: ...
    def frame_points(self, f: int) -> np.ndarray:
        """``(V, 3)`` the points of frame ``f``, made when asked.

        Parameters
        ----------
        f : int
            The frame's index.

        Returns
        -------
        ndarray
            ``(V, 3)`` float32 points.
        """
        ...


Curves = Groom | Animation | FrameStream
FrameProgress = Callable[[int, int], object]


# -- writing -------------------------------------------------------------------------------
def _time_codes(obj: Curves, time_codes: Sequence[float] | None) -> np.ndarray | None:
    if isinstance(obj, Groom):
        if time_codes is not None:
            raise ParameterError("time_codes", time_codes, "None for a static groom")
        return None
    if time_codes is None:
        return np.asarray(obj.time_codes, dtype=np.float64)
    t = np.asarray(time_codes, dtype=np.float64).reshape(-1)
    if t.size != obj.n_frames:
        raise ParameterError("time_codes", f"{t.size} values", f"one per frame ({obj.n_frames})")
    if not np.all(np.isfinite(t)) or np.any(np.diff(t) <= 0):
        raise ParameterError("time_codes", time_codes, "finite, strictly increasing numbers")
    return t


def _wrap_for(basis: str, wrap: str) -> str:
    """The schema defines ``pinned`` for bspline and catmullRom only; elsewhere it is nonperiodic."""
    return "nonperiodic" if wrap == "pinned" and basis in ("linear", "bezier") else wrap


def _extent(points: np.ndarray, half_width: float):
    """The box of the points grown by the half width (NaN where a point is not finite)."""
    from pxr import Vt

    lo, hi = box(points)
    lo = lo.astype(np.float64) - half_width
    hi = hi.astype(np.float64) + half_width
    return Vt.Vec3fArray.FromNumpy(np.stack([lo, hi]).astype(np.float32))


def _prims(obj: Curves) -> tuple[CurvesPrim, ...]:
    from pxr import Sdf

    prims = obj.metadata.for_strands(obj.strand_count).curves
    if not prims or not all(Sdf.Path.IsValidPathString(c.path) for c in prims):
        return (CurvesPrim(PRIM_PATH, obj.strand_count),)
    return prims


def _set_transform(prim, meta: Metadata) -> None:
    """The source's local transform of ``prim`` (one ``xformOp:transform``), if it had one."""
    from pxr import Gf, UsdGeom

    table = dict(meta.xforms)
    m = table.get(str(prim.GetPath()))
    if m is not None:
        UsdGeom.Xformable(prim).AddTransformOp().Set(Gf.Matrix4d(*m))


def _define_parents(stage, paths: Sequence[str], meta: Metadata) -> None:
    """Xforms for every ancestor of the curves prims, with the source's transforms where it had
    them (:attr:`~hairtool.metadata.Metadata.xforms`); the first root is the default prim. Each
    curves prim is declared after its ancestors and before the next prim's, so that a reader
    traverses the prims in the source's order (a prim at the root listed first stays first)."""
    from pxr import Sdf, UsdGeom

    for p in paths:
        for parent in Sdf.Path(p).GetParentPath().GetPrefixes():
            if not stage.GetPrimAtPath(parent):
                _set_transform(UsdGeom.Xform.Define(stage, parent).GetPrim(), meta)
        UsdGeom.BasisCurves.Define(stage, p)
    first_root = Sdf.Path(paths[0]).GetPrefixes()[0]
    if not stage.GetPrimAtPath(first_root):
        UsdGeom.Xform.Define(stage, first_root)
    stage.SetDefaultPrim(stage.GetPrimAtPath(first_root))


def _write_attributes(curves, obj: Curves, vs: slice, color_primvar: str, lacks: Sequence[str] = ()) -> float:
    """Widths, colour and opacity of one prim's vertices (not those the prim ``lacks``: it was
    merged with prims that had them); returns the half width for its extent."""
    from pxr import Sdf, UsdGeom, Vt

    half_width = 0.0
    thickness = None if "thickness" in lacks else obj.thickness
    colors = None if "colors" in lacks else obj.colors
    transparency = None if "transparency" in lacks else obj.transparency
    if thickness is not None:
        curves.CreateWidthsAttr(Vt.FloatArray.FromNumpy(np.ascontiguousarray(thickness[vs])))
        curves.SetWidthsInterpolation(UsdGeom.Tokens.vertex)
        half_width = float(np.abs(thickness[vs]).max()) / 2
    opacity = None if transparency is None else (1.0 - transparency[vs]).astype(np.float32)
    if colors is not None and color_primvar == "color":
        rgba = np.ones((colors[vs].shape[0], 4), dtype=np.float32)
        rgba[:, :3] = colors[vs]
        if opacity is not None:
            rgba[:, 3] = opacity
            opacity = None
        pv = UsdGeom.PrimvarsAPI(curves.GetPrim()).CreatePrimvar(
            "color", Sdf.ValueTypeNames.Color4fArray, UsdGeom.Tokens.vertex
        )
        pv.Set(Vt.Vec4fArray.FromNumpy(rgba))
    elif colors is not None:
        values = Vt.Vec3fArray.FromNumpy(np.ascontiguousarray(colors[vs]))
        curves.CreateDisplayColorPrimvar(UsdGeom.Tokens.vertex).Set(values)
    if opacity is not None:
        curves.CreateDisplayOpacityPrimvar(UsdGeom.Tokens.vertex).Set(Vt.FloatArray.FromNumpy(opacity))
    return half_width


def _write_prim(stage, prim: CurvesPrim, obj: Curves, strands: slice, times):
    """One prim's topology, basis and attributes; its points and extent now for a groom, or the
    attributes and vertex range for :func:`_write_samples` to fill frame by frame."""
    from pxr import UsdGeom, Vt

    counts = obj.counts[strands]
    off = obj.topology.offsets
    vs = slice(int(off[strands.start]), int(off[strands.stop]))
    curves = UsdGeom.BasisCurves.Define(stage, prim.path)
    _set_transform(curves.GetPrim(), obj.metadata)
    to_local = _to_local(obj.metadata, prim.path)
    basis = prim.basis if usd_basis.fits(counts, prim.basis, prim.wrap) else "linear"
    if basis == "linear":
        curves.CreateTypeAttr(UsdGeom.Tokens.linear)
    else:
        curves.CreateTypeAttr(UsdGeom.Tokens.cubic)
        curves.CreateBasisAttr(basis)
    wrap = _wrap_for(basis, prim.wrap) if usd_basis.fits(counts, basis, prim.wrap) else "nonperiodic"
    if wrap != "nonperiodic":
        curves.CreateWrapAttr(wrap)
    curves.CreateCurveVertexCountsAttr(Vt.IntArray.FromNumpy(counts.astype(np.int32)))
    if prim.purpose != "default":
        curves.CreatePurposeAttr(prim.purpose)
    half_width = _write_attributes(curves, obj, vs, obj.metadata.color_primvar, prim.lacks)
    points_attr = curves.CreatePointsAttr()
    extent_attr = curves.CreateExtentAttr()
    if times is None:
        pts = to_local(obj.points[vs])
        points_attr.Set(Vt.Vec3fArray.FromNumpy(pts))
        extent_attr.Set(_extent(pts, half_width))
        return None
    return points_attr, extent_attr, vs, half_width, to_local


def _to_local(meta: Metadata, path: str):
    """World points → the prim's own space under the transforms the writer puts back
    (the points as they are where there are none)."""
    m = meta.world_matrix(path)
    if m is None:
        return lambda p: np.ascontiguousarray(p, dtype=np.float32)
    inv = np.linalg.inv(m[:3, :3])
    t = m[3, :3]
    return lambda p: np.ascontiguousarray((np.asarray(p, np.float64) - t) @ inv, dtype=np.float32)


def _frame_points(obj: Curves, f: int) -> np.ndarray:
    if isinstance(obj, Animation):
        return obj.frames[f]
    p = np.asarray(obj.frame_points(f))
    if p.shape != (obj.vertex_count, 3):
        raise ParameterError("frame", f, f"({obj.vertex_count}, 3) points")
    return p


def _write_samples(stage, obj: Curves, prims: list, times, progress: FrameProgress | None) -> None:
    """Every frame's points and extents, frame after frame (the frames of a stream are made one
    at a time). A crate (``.usdc``) layer is saved whenever FLUSH_BYTES of samples are pending:
    usd-core appends them to the file and lets them go from memory, so a long shot of render
    hair needs a few frames of memory, not the whole shot (a text layer keeps every sample until
    the end)."""
    from pxr import Usd, Vt

    layer = stage.GetRootLayer()
    crate = layer.GetFileFormat().formatId == "usdc"
    pending = 0
    for f, t in enumerate(times):
        code = Usd.TimeCode(float(t))
        frame = _frame_points(obj, f)
        for points_attr, extent_attr, vs, half_width, to_local in prims:
            pts = to_local(frame[vs])
            extent = _extent(pts, half_width)
            if not np.all(np.isfinite(np.asarray(extent))):  # a stream's frames are not checked yet
                raise ParameterError("frame", f, "finite points")
            points_attr.Set(Vt.Vec3fArray.FromNumpy(pts), code)
            extent_attr.Set(extent, code)
        del frame
        pending += obj.vertex_count * 12
        if crate and pending >= FLUSH_BYTES and f + 1 < len(times):
            layer.Save()
            pending = 0
        if progress is not None:
            progress(f + 1, len(times))


def _write_stage_metadata(stage, obj: Curves, times) -> None:
    from pxr import UsdGeom

    meta = obj.metadata
    UsdGeom.SetStageUpAxis(stage, UsdGeom.Tokens.z if meta.up_axis == "Z" else UsdGeom.Tokens.y)
    UsdGeom.SetStageMetersPerUnit(stage, meta.meters_per_unit)
    start, end = meta.start_time_code, meta.end_time_code
    if times is not None:
        start = float(times[0]) if start is None else min(start, float(times[0]))
        end = float(times[-1]) if end is None else max(end, float(times[-1]))
        stage.SetTimeCodesPerSecond(obj.fps)
        stage.SetFramesPerSecond(obj.fps)
    elif meta.time_codes_per_second is not None:
        stage.SetTimeCodesPerSecond(meta.time_codes_per_second)
    if start is not None:  # (each end as the source authored it: one alone stays alone)
        stage.SetStartTimeCode(start)
    if end is not None:
        stage.SetEndTimeCode(end)


def write(
    path: Path,
    obj: Curves,
    *,
    time_codes: Sequence[float] | None = None,
    progress: FrameProgress | None = None,
) -> None:
    """Write a groom, or an animation as time-sampled points.

    ``obj``: a Groom, an Animation, or frames made on demand (:class:`FrameStream`, e.g. render
    hair following an animation of its guides), written one frame at a time. ``time_codes``:
    for an animation, the time code of each frame (F strictly increasing numbers; default: the
    animation's own, :attr:`Animation.time_codes`) — a keys-only export writes just its key
    poses at their time codes, and USD readers interpolate linearly between. ``progress(done,
    total)`` after every frame; an exception it raises (e.g. Cancelled) stops the write and
    leaves no file.

    Parameters
    ----------
    path : Path
        The stage, written atomically.
    obj : Groom, Animation or FrameStream
        What to write.
    time_codes : sequence of float, optional
        One per frame, strictly increasing (None: the animation's own).
    progress : callable, optional
        ``progress(done, total)`` after every frame.
    """
    times = _time_codes(obj, time_codes)
    prims = _prims(obj)
    from pxr import Usd

    with atomic_path(path) as tmp:
        stage = Usd.Stage.CreateNew(str(tmp))
        if stage is None:
            raise FormatError(path, "usd-core could not create the stage")
        _write_stage_metadata(stage, obj, times)
        _define_parents(stage, [c.path for c in prims], obj.metadata)
        first, sampled = 0, []
        for prim in prims:
            sampled.append(_write_prim(stage, prim, obj, slice(first, first + prim.strands), times))
            first += prim.strands
        if times is not None:
            _write_samples(stage, obj, sampled, times, progress)
        stage.GetRootLayer().Save()
        del stage


# -- reading -------------------------------------------------------------------------------
# One diagnostic of a pxr error: "Error in 'function' at line N in file F : 'message'".
_PXR_ERROR = re.compile(r"Error in '[^']*' at line \d+ in file \S+ : '(.*?)'\s*(?=Error in '|$)", re.S)
# A message that says where in the file: "name.usda:4:21: ...".
_PLACED = re.compile(r":\d+:\d+: ")


def _last_line(error: Exception) -> str:
    """One line from a pxr error: the message of its diagnostic that says where in the file, else
    its last one; the message may quote undecodable bytes of the file."""
    try:
        text = str(error).strip()
    except UnicodeDecodeError:
        return "the file is not valid USD (undecodable bytes)"
    messages = [" ".join(m.split()) for m in _PXR_ERROR.findall(text)]
    placed = [m for m in messages if _PLACED.search(m)]
    if placed or messages:
        return (placed or messages)[-1]
    lines = [line.strip() for line in text.splitlines() if line.strip()]
    return lines[-1] if lines else "unknown error"


def _check_specs(path: Path, layer) -> None:
    """Refuse a layer whose prim specs a corrupt crate left nameless or missing.

    usd-core reads such a crate (it warns "Invalid prim name") but composing a stage on it can
    crash the process, so the specs are walked, without recursion, before a stage is made.
    """
    from pxr import Sdf

    stack = [layer.pseudoRoot]
    while stack:
        spec = stack.pop()
        for child in spec.nameChildren:
            if child is None or not Sdf.Path.IsValidIdentifier(child.name):
                raise FormatError(path, f"a prim under {spec.path} has no valid name (corrupt file?)")
            stack.append(child)


def _open_stage(path: Path):
    from pxr import Sdf, Tf, Usd

    if path.stat().st_size == 0:
        raise FormatError(path, "the file is empty")
    usdc_check.check(path)  # before usd-core allocates from a crate's counts
    usda_check.check(path)  # before usd-core's text parser holds every value of an array
    try:
        layer = Sdf.Layer.Find(str(path))
        # A layer still cached from an earlier open may be stale: the file can have been replaced.
        if layer is not None and not layer.Reload(True):
            raise FormatError(path, "usd-core cannot reload it")
        if layer is None:
            layer = Sdf.Layer.FindOrOpen(str(path))
        if layer is not None:
            _check_specs(path, layer)
            usd_layers.check_dependencies(path, layer)  # no FIFO or device for usd-core to follow
        stage = Usd.Stage.Open(layer) if layer is not None else None
    except Tf.ErrorException as e:
        raise FormatError(path, f"usd-core cannot open it: {_last_line(e)}") from None
    if stage is None:
        raise FormatError(path, "usd-core cannot open it")
    return stage


_WORDS = {
    "vec3[]": "an array of 3-vectors",
    "vec4[]": "an array of 4-vectors",
    "float[]": "an array of numbers",
    "int[]": "an array of whole numbers",
    "vec3": "a 3-vector",
    "float": "a number",
    "quat": "a quaternion",
    "matrix": "a 4×4 matrix",
    "token": "a token",
}


def _type_names() -> dict[str, set]:
    """The Tf types (roles aside: vector3d is double3) a transform op or token may be declared as."""
    from pxr import Sdf

    v = Sdf.ValueTypeNames
    return {
        "vec3": {v.Float3.type, v.Double3.type, v.Half3.type},
        "float": {v.Float.type, v.Double.type, v.Half.type},
        "quat": {v.Quatf.type, v.Quatd.type, v.Quath.type},
        "matrix": {v.Matrix4d.type},
        "token": {v.Token.type},
    }


def _require_type(path: Path, attr, kinds: str) -> None:
    """A declared type other than ``kinds`` (a string, an unregistered type) is a FormatError."""
    allowed = _type_names()
    tn = attr.GetTypeName()
    ok = bool(tn) and any(tn.type in allowed[k] for k in kinds.split("|"))
    if not ok:
        what = str(attr.GetPrim().GetPath()) + "." + attr.GetName()
        kind = " or ".join(_WORDS[k] for k in kinds.split("|"))
        raise FormatError(path, f"{what} is declared {str(tn) or 'with an unknown type'}, not {kind}")


def _array_classes() -> dict[str, tuple]:
    from pxr import Vt

    return {
        "vec3[]": (Vt.Vec3fArray, Vt.Vec3dArray, Vt.Vec3hArray),
        "vec4[]": (Vt.Vec4fArray, Vt.Vec4dArray, Vt.Vec4hArray),
        "float[]": (Vt.FloatArray, Vt.DoubleArray, Vt.HalfArray),
        "int[]": (Vt.IntArray, Vt.Int64Array, Vt.UIntArray),
    }


def _value(path: Path, attr, time, kinds: str):
    """``attr``'s value at ``time``, which must be an array of one of ``kinds`` (None when unset).

    Schema attributes report their schema's type whatever a file authors, so the value itself is
    checked: a string or an unregistered type where points, counts or widths belong is refused.
    """
    value = attr.Get(time)
    if value is None:
        return None
    classes = _array_classes()
    if not any(isinstance(value, classes[k]) for k in kinds.split("|")):
        what = f"{attr.GetPrim().GetPath()}.{attr.GetName()}"
        kind = " or ".join(_WORDS[k] for k in kinds.split("|"))
        raise FormatError(path, f"{what} holds a {type(value).__name__}, not {kind}")
    return value


def _op_kind(op) -> str | None:
    """The value type a transform op needs, by its op type (None for an invalid op)."""
    from pxr import UsdGeom

    t, x = op.GetOpType(), UsdGeom.XformOp
    if t in (x.TypeRotateX, x.TypeRotateY, x.TypeRotateZ):
        return "float"
    if t == x.TypeOrient:
        return "quat"
    if t == x.TypeTransform:
        return "matrix"
    return None if t == x.TypeInvalid else "vec3"


def _lineage(prim):
    """The prim and its ancestors up to (not including) the pseudo-root."""
    while prim and not prim.IsPseudoRoot():
        yield prim
        prim = prim.GetParent()


def _transform_samples(path: Path, prim) -> set[float]:
    """Check every transform op above the hair holds the type its op names; their time samples."""
    from pxr import UsdGeom

    times: set[float] = set()
    for p in _lineage(prim):
        xf = UsdGeom.Xformable(p)
        if not xf:
            continue
        for op in xf.GetOrderedXformOps():
            kind = _op_kind(op)
            if kind is None:
                raise FormatError(path, f"{p.GetPath()} has an invalid transform op {op.GetOpName()!r}")
            _require_type(path, op.GetAttr(), kind)
            times.update(float(t) for t in op.GetTimeSamples())
    return times


def _token(path: Path, attr, allowed: Sequence[str], what: str) -> str:
    _require_type(path, attr, "token")
    value = str(attr.Get())
    if value not in allowed:
        raise FormatError(path, f"{attr.GetPrim().GetPath()}: {what} is {value!r}; expected one of {allowed}")
    return value


def _empty(prim) -> bool:
    """Whether a curves prim holds no curves, as written (Blender's empty Curves object, a prim
    whose every strand was deleted): no groom to read, and the commands carry it through as it is
    (:mod:`hairtool.io.usd_carry`)."""
    from pxr import UsdGeom

    attr = UsdGeom.BasisCurves(prim).GetCurveVertexCountsAttr()
    if not attr.HasAuthoredValue():
        return False
    value = attr.Get()
    return value is not None and len(value) == 0


class _Curves:
    """One BasisCurves prim: its topology, basis, points attribute and transform."""

    def __init__(self, path: Path, prim) -> None:
        from pxr import Usd, UsdGeom

        self.curves = UsdGeom.BasisCurves(prim)
        self.name, self.path, self.prim = str(prim.GetPath()), path, prim
        counts_attr = self.curves.GetCurveVertexCountsAttr()
        raw = _value(path, counts_attr, Usd.TimeCode.EarliestTime(), "int[]")
        if raw is None or len(raw) == 0:
            raise FormatError(path, f"{self.name} has no curveVertexCounts")
        self.counts = np.asarray(raw, dtype=np.int64)
        require_strand_counts(path, self.counts)
        self.vertex_count = int(self.counts.sum())
        self.points = self.curves.GetPointsAttr()
        if not self.points.HasAuthoredValue():
            raise FormatError(path, f"{self.name} has no points")
        # The counts are checked against the points before anything is sized from them.
        self._check_length(_value(path, self.points, Usd.TimeCode.EarliestTime(), "vec3[]"))
        self.transform_times = _transform_samples(path, prim)
        kind = _token(path, self.curves.GetTypeAttr(), ("linear", "cubic"), "type")
        basis = _token(path, self.curves.GetBasisAttr(), ("bezier", "bspline", "catmullRom"), "basis")
        wrap = _token(path, self.curves.GetWrapAttr(), ("nonperiodic", "periodic", "pinned"), "wrap")
        basis = "linear" if kind == "linear" else basis
        if not usd_basis.fits(self.counts, basis, _wrap_for(basis, wrap)):
            basis = "linear"  # a cubic basis these counts cannot draw: the points as a polyline
        self.basis, self.wrap = basis, _wrap_for(basis, wrap)
        self.purpose = _token(path, self.curves.GetPurposeAttr(), PURPOSES, "purpose")
        self.times = {float(t) for t in self.points.GetTimeSamples()}

    def _check_length(self, value) -> None:
        if value is None:
            raise FormatError(self.path, f"{self.name} has no points")
        if len(value) != self.vertex_count:
            raise FormatError(
                self.path,
                f"{self.name}: curveVertexCounts add up to {self.vertex_count} points "
                f"but points has {len(value)}",
            )

    def info(self, lacks: Sequence[str] = ()) -> CurvesPrim:
        return CurvesPrim(self.name, int(self.counts.size), self.basis, self.wrap, self.purpose, tuple(lacks))

    def at(self, time, xforms) -> np.ndarray:
        from pxr import Gf

        value = _value(self.path, self.points, time, "vec3[]")
        self._check_length(value)
        p = np.asarray(value, dtype=np.float32).reshape(self.vertex_count, 3)
        m = xforms.GetLocalToWorldTransform(self.prim)
        if m != Gf.Matrix4d(1.0):
            m = np.asarray(m, dtype=np.float64)
            if not np.all(np.isfinite(m)):
                raise FormatError(self.path, f"{self.name} has a non-finite transform")
            with np.errstate(over="ignore", invalid="ignore"):  # checked just below, as one line
                p = (p.astype(np.float64) @ m[:3, :3] + m[3, :3]).astype(np.float32)
        require_finite(self.path, p, f"{self.name} points")
        return p

    def _primvar(self, values, interpolation: str, width: tuple[int, ...], what: str) -> np.ndarray:
        need = usd_basis.expected_count(interpolation, self.counts, self.basis, self.wrap)
        if need is None:
            raise FormatError(self.path, f"{self.name}: {what} has unknown interpolation {interpolation!r}")
        count = 0 if values is None else len(values)
        if count == need:  # counted before a float64 copy is made of it
            a = np.asarray(values if values is not None else [], dtype=np.float64)
            count = a.shape[0] if a.ndim else 0
        if count != need or a.shape != (need, *width):
            raise FormatError(
                self.path,
                f"{self.name}: {what} has {count} values; {interpolation} interpolation needs {need}",
            )
        require_finite(self.path, a, f"{self.name} {what}")
        return usd_basis.per_vertex(a, interpolation, self.counts, self.basis, self.wrap)

    def attributes(self) -> tuple[dict[str, np.ndarray | None], str]:
        """Thickness, transparency and colours (None where absent), and the colour's primvar name."""
        from pxr import Usd, UsdGeom

        first = Usd.TimeCode.EarliestTime()
        out: dict[str, np.ndarray | None] = {"thickness": None, "transparency": None, "colors": None}
        widths = self.curves.GetWidthsAttr()
        if widths.HasAuthoredValue():
            value = _value(self.path, widths, first, "float[]")
            w = self._primvar(value, self.curves.GetWidthsInterpolation(), (), "widths")
            out["thickness"] = w.astype(np.float32)
        pv = UsdGeom.PrimvarsAPI(self.prim)
        source, alpha = "displayColor", None
        color = pv.GetPrimvar("displayColor")
        if not (color and color.HasAuthoredValue()):
            color, source = pv.GetPrimvar("color"), "color"
        if color and color.HasAuthoredValue():
            value = _value(self.path, color.GetAttr(), first, "vec3[]|vec4[]")
            wide = isinstance(value, _array_classes()["vec4[]"])
            c = self._primvar(value, color.GetInterpolation(), (4 if wide else 3,), f"primvars:{source}")
            out["colors"] = c[:, :3].astype(np.float32)
            if wide and np.any(c[:, 3] != 1.0):
                alpha = c[:, 3]
        opacity = pv.GetPrimvar("displayOpacity")
        if opacity and opacity.HasAuthoredValue():
            value = _value(self.path, opacity.GetAttr(), first, "float[]")
            alpha = self._primvar(value, opacity.GetInterpolation(), (), "displayOpacity")
        if alpha is not None:
            out["transparency"] = (1.0 - alpha).astype(np.float32)
        return out, source


def _merge_attributes(
    parts: list[_Curves], meters_per_unit: float
) -> tuple[dict[str, np.ndarray | None], str, list[tuple[str, ...]]]:
    """The prims' attributes end to end: one prim lacking widths or colour does not strip the
    others; its vertices get defaults (80 µm, no transparency, grey) and its prim records what
    it lacked, so writing it back authors them on the prims that had them only. Also the colour
    primvar's name and each prim's lacks."""
    read = [c.attributes() for c in parts]
    attrs, lacks = join_attributes([a for a, _ in read], [c.vertex_count for c in parts], meters_per_unit)
    sources = {s for a, s in read if a["colors"] is not None}
    return attrs, ("color" if sources == {"color"} else "displayColor"), lacks


def _stage_metadata(path: Path, stage) -> dict:
    from pxr import UsdGeom

    up = str(UsdGeom.GetStageUpAxis(stage))
    if up not in ("Y", "Z"):
        raise FormatError(path, f"upAxis is {up!r}; USD allows Y or Z")
    mpu = float(UsdGeom.GetStageMetersPerUnit(stage))
    if not (np.isfinite(mpu) and mpu > 0):
        raise FormatError(path, f"metersPerUnit is {mpu}; expected a positive number")
    fps = float(stage.GetTimeCodesPerSecond())
    if not (np.isfinite(fps) and fps > 0):
        raise FormatError(path, f"timeCodesPerSecond is {fps}; expected a positive number")
    layer = stage.GetRootLayer()
    out = {"up_axis": up, "meters_per_unit": mpu, "fps": fps}
    out["time_codes_per_second"] = (
        fps if layer.HasTimeCodesPerSecond() or layer.HasFramesPerSecond() else None
    )
    start, end = _authored_range(stage)
    for name, value in (("startTimeCode", start), ("endTimeCode", end)):
        if value is not None and not np.isfinite(value):
            raise FormatError(path, f"{name} is {value}; expected a finite number")
    if start is not None and end is not None and start > end:
        raise FormatError(path, f"the time code range {start}…{end} is not a range")
    out.update(start_time_code=start, end_time_code=end)
    return out


def _authored_range(stage) -> tuple[float | None, float | None]:
    """The stage's start and end time codes, each as usd-core's stage reports it where a layer
    it reads them from (the session or the root layer) authors it, None where neither does.

    A stage may author one end alone (``startTimeCode = 1`` without an end): usd-core and
    Blender's importer then still start it there (``Usd.Stage.GetStartTimeCode`` is 1, and so is
    Blender's first frame), so the authored end is kept on its own and the other stays unset
    (usd-core's fallback, 0, would turn a start after 0 into an empty range)."""
    layers = [stage.GetRootLayer(), stage.GetSessionLayer()]
    has_start = any(layer is not None and layer.HasStartTimeCode() for layer in layers)
    has_end = any(layer is not None and layer.HasEndTimeCode() for layer in layers)
    start = float(stage.GetStartTimeCode()) if has_start else None
    end = float(stage.GetEndTimeCode()) if has_end else None
    return start, end


def _sample_times(parts: list[_Curves]) -> list[float]:
    """The animation's time codes: every sample of points and transforms; [] for a static groom
    (no point samples, and transforms set at one time code at most)."""
    point_times = set().union(*(c.times for c in parts))
    times = sorted(point_times.union(*(c.transform_times for c in parts)))
    return times if point_times or len(times) > 1 else []


def _static_xforms(parts: list[_Curves]) -> tuple:
    """The curves prims' and their ancestors' local transforms (non-identity ones) that are not
    time-sampled: :attr:`hairtool.metadata.Metadata.xforms`, so a writer can put them back. A
    sampled one (a head that turns) is left out: the writer bakes it into the points of the hair
    under it (written in the space of the static transforms it puts back), and the hair beside
    it, under static parents, keeps them."""
    from pxr import Gf, Usd, UsdGeom

    table: dict[str, tuple[float, ...]] = {}
    for c in parts:
        for p in _lineage(c.prim):
            xf = UsdGeom.Xformable(p)
            if not xf:
                continue
            if xf.GetResetXformStack():
                return ()  # a prim that ignores its parents: not kept (the points stay world)
            if any(op.GetAttr().GetNumTimeSamples() for op in xf.GetOrderedXformOps()):
                continue
            m = xf.GetLocalTransformation(Usd.TimeCode.Default())
            if m != Gf.Matrix4d(1.0):
                table[str(p.GetPath())] = tuple(float(v) for v in np.asarray(m, np.float64).reshape(-1))
    return tuple(sorted(table.items()))


def _memory_bytes() -> int:
    """The memory this process may use: physical memory, or less under an address-space or data
    limit (a farm worker's ``ulimit -v``); 0 where the OS says neither."""
    sizes = []
    try:
        sizes.append(os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES"))
    except (ValueError, OSError, AttributeError):
        pass
    try:
        import resource

        for limit in (resource.RLIMIT_AS, resource.RLIMIT_DATA):
            soft = resource.getrlimit(limit)[0]
            if soft != resource.RLIM_INFINITY:
                sizes.append(soft)
    except (ImportError, ValueError, OSError):
        pass
    return min(sizes, default=0)


def _require_room(path: Path, frames: int, points: int) -> None:
    """Refuse an animation whose frames cannot fit in half of memory, before allocating them.

    A transform sampled at a million time codes over a groom of a million points is a small
    file that asks for 12 TB: the frames are counted from the union of every sample, so the
    file's size says nothing of what it unpacks to.
    """
    need = frames * points * 3 * 4
    room = _memory_bytes() // 2
    if room and need > room:
        raise FormatError(
            path,
            f"{frames:,} time samples of {points:,} points need {need / 2**30:,.1f} GiB, more than "
            f"half of the memory this process may use ({room * 2 / 2**30:,.1f} GiB); "
            "split the shot into shorter ranges",
        )


def _read_stage(path: Path, stage) -> Groom | Animation:
    from pxr import Usd, UsdGeom

    prims = [p for p in stage.Traverse() if p.IsA(UsdGeom.BasisCurves) and not _empty(p)]
    if not prims:
        raise FormatError(path, "no BasisCurves prim with curves on the stage")
    parts = [_Curves(path, p) for p in prims]
    counts = np.concatenate([c.counts for c in parts])
    stage_meta = _stage_metadata(path, stage)
    attrs, color_source, lacks = _merge_attributes(parts, stage_meta["meters_per_unit"])
    fps = stage_meta.pop("fps")
    curves = tuple(c.info(lack) for c, lack in zip(parts, lacks, strict=True))
    try:
        stage_meta["xforms"] = Metadata(xforms=_static_xforms(parts)).xforms
    except HairtoolError:
        stage_meta["xforms"] = ()  # a transform these writers cannot put back (projective, singular)
    times = _sample_times(parts)
    if not times:
        once = set().union(*(c.transform_times for c in parts))  # a transform set at one time code
        code = Usd.TimeCode(once.pop()) if once else Usd.TimeCode.Default()
        xforms = UsdGeom.XformCache(code)
        points = np.concatenate([c.at(code, xforms) for c in parts])
        meta = Metadata(**stage_meta, curves=curves, color_primvar=color_source)
        return Groom(points, counts, **attrs, metadata=meta)
    _require_room(path, len(times), int(counts.sum()))
    frames = np.empty((len(times), int(counts.sum()), 3), dtype=np.float32)
    for f, t in enumerate(times):
        code = Usd.TimeCode(t)
        xforms = UsdGeom.XformCache(code)
        frames[f] = np.concatenate([c.at(code, xforms) for c in parts])
    meta = Metadata(**stage_meta, time_codes=tuple(times), curves=curves, color_primvar=color_source)
    return Animation(frames, counts, fps, **attrs, metadata=meta)


@contextlib.contextmanager
def _pxr_conversion_noise_hidden():
    """Hide the stray line usd-core prints when it cannot hand a corrupt value's error to Python.

    Reading a corrupt crate value, usd-core raises its error (which the reader turns into a
    FormatError) but first reports, through ``sys.excepthook``, a TypeError "No to_python
    (by-value) converter found" for the value it could not convert, and a UnicodeDecodeError for
    a token whose bytes are not UTF-8 (the value then reads as None, which the reader refuses).
    Only those reports are hidden, and only while the reader runs; anything else still reaches
    the previous hook.
    """
    previous = sys.excepthook

    def hook(kind, value, tb):
        if not ((kind is TypeError and "to_python" in str(value)) or kind is UnicodeDecodeError):
            previous(kind, value, tb)

    sys.excepthook = hook
    try:
        yield
    finally:
        if sys.excepthook is hook:
            sys.excepthook = previous


def _commentary(diagnostic) -> str:
    try:
        return " ".join(str(diagnostic.commentary).split())
    except UnicodeDecodeError:
        return "a message quoting undecodable bytes of the file"


@contextlib.contextmanager
def _usd_diagnostics(notes: list[str]):
    """usd-core's own warnings and status lines while it reads ("Invalid prim name", "Integer
    literal … out of range"), kept off stderr and appended to ``notes``: through its
    ``Tf.DiagnosticTrap`` (a TfDiagnosticMgr trap), or, in a usd-core without one, by pointing
    fd 2 at a temporary file."""
    from pxr import Tf

    if hasattr(Tf, "DiagnosticTrap"):
        with Tf.DiagnosticTrap() as trap:
            try:
                yield
            finally:
                notes.extend(_commentary(d) for d in (*trap.GetWarnings(), *trap.GetStatuses()))
                trap.Clear()  # what is left in a trap is printed when it closes
        return
    sys.stderr.flush()
    with tempfile.TemporaryFile() as f:
        saved = os.dup(2)
        os.dup2(f.fileno(), 2)
        try:
            yield
        finally:
            interrupts.restore_stderr(saved)
            os.close(saved)
            f.seek(0)
            text = f.read().decode("utf-8", "replace")
            lines = (line.split(" -- ", 1)[-1] for line in text.splitlines() if line.strip())
            notes.extend(" ".join(line.split()) for line in lines)


def _diagnosed(path: Path, work: Callable[[], object]):
    """``work()`` reading ``path`` through usd-core, every failure one FormatError.

    usd-core's diagnostics never reach stderr: when the file is refused, the first is folded
    into the error's line (it often says what is wrong, and where); when it reads, they are
    dropped: hairtool checks every value it uses itself, so what usd-core repaired on the way
    (an integer literal out of range read as a double) is a value that passed those checks.
    """
    from pxr import Tf

    notes: list[str] = []
    try:
        with _usd_diagnostics(notes), _pxr_conversion_noise_hidden():
            try:
                return work()
            except HairtoolError:
                raise
            except Tf.ErrorException as e:  # a crate's values are read lazily, inside Get()
                raise FormatError(path, f"usd-core cannot read it: {_last_line(e)}") from None
            except (ValueError, TypeError, OverflowError, MemoryError) as e:
                raise FormatError(path, f"not readable as hair curves ({type(e).__name__}: {e})") from None
    except FormatError as e:
        if not notes:
            raise
        more = f"; {len(notes) - 1} more" if len(notes) > 1 else ""
        note = notes[0] if len(notes[0]) <= 200 else notes[0][:200] + "…"
        raise FormatError(e.path, f"{e.reason} (usd-core warned: {note}{more})") from None


def read(path: Path) -> Groom | Animation:
    """Merge every BasisCurves prim; time-sampled points or transforms make an Animation.

    Parameters
    ----------
    path : Path
        A ``.usd``, ``.usda`` or ``.usdc`` stage.

    Returns
    -------
    Groom or Animation
        Every hair prim of the stage, with its scene record.
    """
    return _diagnosed(path, lambda: _read_stage(path, _open_stage(path)))


def time_codes(path: str | os.PathLike[str]) -> list[float]:
    """The authored time codes of the file's hair: its points' and transforms' samples (empty when static).

    Parameters
    ----------
    path : str or os.PathLike
        A USD stage.

    Returns
    -------
    list of float
        The time codes, ascending.
    """
    from pxr import UsdGeom

    p = Path(path)

    def work() -> list[float]:
        stage = _open_stage(p)
        prims = [q for q in stage.Traverse() if q.IsA(UsdGeom.BasisCurves) and not _empty(q)]
        return _sample_times([_Curves(p, q) for q in prims])

    return _diagnosed(p, work)
