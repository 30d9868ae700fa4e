"""What a hair command leaves alone in a USD scene, carried from its source into the file it writes.

The USD writer (:mod:`hairtool.io.usd`) authors the hair: its curves prims, their parents and
transforms, the stage's axis, unit and time codes. A DCC's scene holds more, which a command
that reads and writes USD must not drop: the head mesh, materials, the ``customData`` Blender
marks its root with (without it a re-import nests ``/root/root``), the parents' own properties
and, on a curves prim, its material binding and user properties and, where its curves are the
same ones (the same vertex counts), its other primvars (Blender's ``surface_uv_coordinate``,
``rest_position``…), and a parent's translate/rotate/scale ops where the writer put its static
transform back as one matrix (the same transform), and a curves prim's authored points where
the command left its strands as they were (the writer's are the same up to the rounding of the
way back into the prim's space), every time sample of them, with its time-sampled widths and
colour. Each is copied spec for spec (its bytes as the source had them) from the source's
composed stage; nothing else the writer authored is overwritten.
"""

from __future__ import annotations

import os
from pathlib import Path

from hairtool.io.atomic import atomic_path

#: Properties of a curves prim the writer authors from the groom: never carried.
_OWN = ("points", "extent", "curveVertexCounts", "widths", "type", "basis", "wrap", "purpose")


def export_stage(stage, out: str | os.PathLike[str]) -> None:
    """Write ``stage`` to ``out`` whole or not at all (a temporary name, renamed); FormatError
    naming ``out`` when usd-core cannot write it."""
    with atomic_path(Path(out)) as tmp:
        if not stage.Export(str(tmp)):
            from hairtool.errors import FormatError

            raise FormatError(Path(out), "usd-core could not write it")


def _copy_missing_properties(src, dst, path, prefixes: tuple[str, ...] | None) -> list[str]:
    """The properties of ``src``'s prim at ``path`` that ``dst``'s lacks (those starting with one
    of ``prefixes``, or any with None), copied; their names."""
    from pxr import Sdf

    s, d = src.GetPrimAtPath(path), dst.GetPrimAtPath(path)
    done = []
    for prop in s.properties:
        name = prop.name
        if name in d.properties or name in _OWN or name.startswith("xformOp") or name == "xformOpOrder":
            continue
        if prefixes is not None and not name.startswith(prefixes):
            continue
        if Sdf.CopySpec(src, prop.path, dst, prop.path):
            done.append(str(prop.path))
    return done


USD_SUFFIXES = (".usd", ".usda", ".usdc")


def carry_between(source: str | os.PathLike[str], written: str | os.PathLike[str]) -> list[str]:
    """:func:`carry_scene` when both are USD files (a command's IN and OUT); else nothing.

    Parameters
    ----------
    source : str or os.PathLike
        The command's input.
    written : str or os.PathLike
        Its output.

    Returns
    -------
    list of str
        The prim paths carried.
    """
    src, out = Path(source), Path(written)
    if src.suffix.lower() not in USD_SUFFIXES or out.suffix.lower() not in USD_SUFFIXES or not src.is_file():
        return []
    from hairtool.io.usd import _diagnosed

    return _diagnosed(src, lambda: carry_scene(src, out))


def carry_scene(source: str | os.PathLike[str], written: str | os.PathLike[str]) -> list[str]:
    """Copy into the USD file ``written`` (rewritten atomically, untouched when there is nothing
    to carry) what its USD ``source`` holds beside the hair (module doc); returns the paths
    carried.

    Parameters
    ----------
    source : str or os.PathLike
        A USD stage.
    written : str or os.PathLike
        The USD file written from it.

    Returns
    -------
    list of str
        The prim paths carried.
    """
    from pxr import Sdf

    from hairtool.io.usd import _open_stage

    stage = _open_stage(Path(source))  # (the reader's checks, and a cached layer reloaded)
    src = stage.Flatten()
    dst = Sdf.Layer.CreateAnonymous(Path(written).suffix)
    dst.TransferContent(Sdf.Layer.OpenAsAnonymous(str(written)))  # (the file as now written)
    curves = set(_curves_paths(dst, Sdf.Path.absoluteRootPath))
    ancestors = {a for c in curves for a in c.GetParentPath().GetPrefixes()}
    carried: list[str] = []

    def visit(spec, placed: bool = True) -> None:
        """``placed``: the prims written above this one stand where the source's do."""
        path = spec.path
        mine = dst.GetPrimAtPath(path)
        if mine is None:
            if path in ancestors or _curves_paths(src, path) or not placed:
                return  # hair the command replaced (or dropped), or where its parents moved
            if Sdf.CopySpec(src, path, dst, path):
                carried.append(str(path))
            return
        carried.extend(_authored_ops(stage, src, dst, path))
        if path in curves:
            if src.GetPrimAtPath(path).typeName == "BasisCurves":
                # a material and user properties hold for any strands; primvars for the same ones
                # (strokes that plant and delete: hairtool.guides.strand_primvars)
                same = _same_counts(src, dst, path)
                kept = ("material:", "userProperties:", *(("primvars:",) if same else ()))
                carried.extend(_copy_missing_properties(src, dst, path, kept))
                if same:
                    carried.extend(_untouched_points(src, dst, path))
                schemas = src.GetPrimAtPath(path).GetInfo("apiSchemas")
                if schemas and not mine.HasInfo("apiSchemas"):
                    mine.SetInfo("apiSchemas", schemas)
            return
        if path in ancestors:
            for key in ("customData", "kind", "active"):
                if spec.HasInfo(key) and not mine.HasInfo(key):
                    mine.SetInfo(key, spec.GetInfo(key))
                    carried.append(f"{path}:{key}")
            carried.extend(_copy_missing_properties(src, dst, path, None))
            # an animated parent's transform is not written (the hair is in world space there):
            # a mesh under it would not move with it, so it stays out
            moved = "xformOpOrder" not in mine.properties and _transformed(stage, path)
            for child in spec.nameChildren:
                visit(child, placed and not moved)

    for root in src.rootPrims:
        visit(root)
    data = src.customLayerData
    if data and not dst.customLayerData:
        dst.customLayerData = data
        carried.append("customLayerData")
    if not carried:
        return carried
    export_stage(dst, written)
    return carried


def keep_emptied(source: str | os.PathLike[str], written: str | os.PathLike[str], prims) -> list[str]:
    """Prims whose every strand a command deleted, written into the USD file ``written`` as
    empty curves prims (no curves, no points; their basis, wrap and purpose, and their parents'
    transform ops from ``source``), as Blender keeps an empty Curves object; the paths kept
    (none where ``written`` is not USD). Call before :func:`carry_between`, which then brings the
    rest of their scene."""
    out = Path(written)
    if out.suffix.lower() not in USD_SUFFIXES:
        return []
    from hairtool.io.usd import _diagnosed

    def work() -> list[str]:
        from pxr import Sdf, Usd, UsdGeom, Vt

        src = None
        if Path(source).suffix.lower() in USD_SUFFIXES and Path(source).is_file():
            from hairtool.io.usd import _open_stage

            src = _open_stage(Path(source)).Flatten()
        dst = Sdf.Layer.CreateAnonymous(out.suffix)
        dst.TransferContent(Sdf.Layer.OpenAsAnonymous(str(out)))
        stage = Usd.Stage.Open(dst)
        kept = []
        for c in prims:
            for parent in Sdf.Path(c.path).GetParentPath().GetPrefixes():
                if stage.GetPrimAtPath(parent):
                    continue
                UsdGeom.Xform.Define(stage, parent)
                theirs = None if src is None else src.GetPrimAtPath(parent)
                for prop in theirs.properties if theirs else ():
                    if prop.name.startswith("xformOp"):
                        Sdf.CopySpec(src, prop.path, dst, prop.path)
            curves = UsdGeom.BasisCurves.Define(stage, c.path)
            curves.CreateTypeAttr("linear" if c.basis == "linear" else "cubic")
            if c.basis != "linear":
                curves.CreateBasisAttr(c.basis)
            if c.wrap != "nonperiodic":
                curves.CreateWrapAttr(c.wrap)
            if c.purpose != "default":
                curves.CreatePurposeAttr(c.purpose)
            curves.CreateCurveVertexCountsAttr(Vt.IntArray())
            curves.CreatePointsAttr(Vt.Vec3fArray())
            kept.append(c.path)
        export_stage(dst, out)
        return kept

    return _diagnosed(out, work)


def _same_counts(src, dst, path) -> bool:
    """Whether the curves prim at ``path`` holds the same curves (vertex counts) in both layers."""
    a = src.GetAttributeAtPath(path.AppendProperty("curveVertexCounts"))
    b = dst.GetAttributeAtPath(path.AppendProperty("curveVertexCounts"))
    return a is not None and b is not None and list(a.default or []) == list(b.default or [])


#: How far (in float32 spacings at the points' magnitude) the writer's points of a prim may lie
#: from the source's and still be the source's own: the round trip into world space and back
#: through the prim's transforms rounds each coordinate by an ULP or two.
_ROUNDING_ULPS = 4


def _values_of(layer, attr) -> dict:
    """``{time: value}`` of an attribute spec: its time samples, or its default at None."""
    times = layer.ListTimeSamplesForPath(attr.path)
    if times:
        return {float(t): layer.QueryTimeSample(attr.path, t) for t in times}
    return {} if attr.default is None else {None: attr.default}


def _rounded_only(was, now) -> bool:
    """Whether the points ``now`` are ``was`` up to the rounding of the way back into a prim's
    own space (the same shape, within _ROUNDING_ULPS at ``was``'s magnitude)."""
    import numpy as np

    was, now = np.asarray(was, np.float32), np.asarray(now, np.float32)
    if was.shape != now.shape or was.size == 0:
        return False
    ulp = np.spacing(np.float32(np.abs(was).max()))
    off = np.abs(now.astype(np.float64) - was).max() if np.all(np.isfinite(now)) else np.inf
    return bool(off <= _ROUNDING_ULPS * ulp)


def _untouched_points(src, dst, path) -> list[str]:
    """Where the command left a prim's strands as they were (the points the writer wrote are the
    source's at every time it wrote them, up to the rounding of the way back into the prim's own
    space), the source's authored ``points`` and ``extent`` themselves, byte for byte, every
    time sample with them; then the source's time-sampled widths and colour, which the writer
    wrote once (:func:`_sampled_attributes`). A static prim the writer sampled at the source's
    time codes (an animation beside it) is the source's static points again; frames a command
    made (a simulation of a static groom) stay its own."""
    from pxr import Sdf

    done = []
    a = src.GetAttributeAtPath(path.AppendProperty("points"))
    b = dst.GetAttributeAtPath(path.AppendProperty("points"))
    if a is None or b is None:
        return done
    was, now = _values_of(src, a), _values_of(dst, b)
    if not was or not now:
        return done
    if list(was) == [None]:  # static in the source: every value written is that one, at the
        if not set(now) <= {None, *map(float, src.ListAllTimeSamples())}:  # source's own times
            return done  # (frames the command made, a simulation's: the points of an animation)
        pairs = [(was[None], v) for v in now.values()]
    elif set(was) == set(now):
        pairs = [(was[t], now[t]) for t in was]
    else:
        return done
    if not all(_rounded_only(x, y) for x, y in pairs):
        return done
    same = list(was) == list(now) and all(_floats(x).tobytes() == _floats(y).tobytes() for x, y in pairs)
    for name in () if same else ("points", "extent"):  # (written as the source has them already)
        prop = path.AppendProperty(name)
        if src.GetAttributeAtPath(prop) is not None and Sdf.CopySpec(src, prop, dst, prop):
            done.append(str(prop))
    return done + _sampled_attributes(src, dst, path)


def _floats(value):
    import numpy as np

    return np.ascontiguousarray(np.asarray(value, np.float32))


#: A curves prim's attributes the writer authors once from what the reader took (the earliest
#: value) that a source may time-sample.
_SAMPLED = ("widths", "primvars:displayColor", "primvars:displayOpacity", "primvars:color")


def _sampled_attributes(src, dst, path) -> list[str]:
    """For a prim whose points are the source's: each of its time-sampled widths and colours
    whose earliest sample is what the writer wrote (the command left it as it was read), the
    source's attribute with every sample, byte for byte (written once, it would stand still)."""
    from pxr import Sdf

    done = []
    for name in _SAMPLED:
        a = src.GetAttributeAtPath(path.AppendProperty(name))
        b = dst.GetAttributeAtPath(path.AppendProperty(name))
        if a is None or b is None or b.default is None or not src.ListTimeSamplesForPath(a.path):
            continue
        first = min(src.ListTimeSamplesForPath(a.path))
        value = src.QueryTimeSample(a.path, first)
        if value is None or _floats(value).tobytes() != _floats(b.default).tobytes():
            continue
        if Sdf.CopySpec(src, a.path, dst, b.path):
            done.append(str(a.path))
    return done


def _curves_paths(layer, under) -> list:
    """The BasisCurves prim specs at and below ``under`` in ``layer`` that hold curves (an empty
    one, which no reader takes as hair, is carried as it is)."""
    found = []

    def look(p) -> None:
        if p.IsPrimPath() and layer.GetPrimAtPath(p).typeName == "BasisCurves":
            counts = layer.GetAttributeAtPath(p.AppendProperty("curveVertexCounts"))
            if counts is None or counts.default is None or len(counts.default) > 0:
                found.append(p)

    layer.Traverse(under, look)
    return found


def _transformed(stage, path) -> bool:
    """Whether the source prim at ``path`` moves what is under it (a transform that is not the
    identity, or one that changes over time)."""
    from pxr import Gf, Usd, UsdGeom

    xf = UsdGeom.Xformable(stage.GetPrimAtPath(path))
    if not xf:
        return False
    return xf.TransformMightBeTimeVarying() or xf.GetLocalTransformation(
        Usd.TimeCode.Default()
    ) != Gf.Matrix4d(1.0)


def _authored_ops(stage, src, dst, path) -> list[str]:
    """Where the writer put a prim's static source transform back as one matrix (or wrote none
    for ops that come to the identity), the source's own ops instead (translate, rotate, scale
    as authored: the same transform, and an artist's channels kept); returns the ops carried."""
    from pxr import Gf, Sdf, Usd, UsdGeom

    mine, theirs = dst.GetPrimAtPath(path), src.GetPrimAtPath(path)
    if "xformOpOrder" not in theirs.properties:
        return []
    xf = UsdGeom.Xformable(stage.GetPrimAtPath(path))
    if not xf or xf.TransformMightBeTimeVarying() or xf.GetResetXformStack():
        return []
    if "xformOpOrder" not in mine.properties:  # none written: the source's ops come to identity
        ops = xf.GetOrderedXformOps()  # (a transform set at one time code is in the points)
        identity = xf.GetLocalTransformation(Usd.TimeCode.Default()) == Gf.Matrix4d(1.0)
        if not identity or any(op.GetAttr().GetNumTimeSamples() for op in ops):
            return []
    ours = [p.name for p in mine.properties if p.name.startswith("xformOp")]
    for name in ours:
        mine.RemoveProperty(mine.properties[name])
    done = []
    for prop in theirs.properties:
        if prop.name.startswith("xformOp") and Sdf.CopySpec(src, prop.path, dst, prop.path):
            done.append(str(prop.path))
    return done
