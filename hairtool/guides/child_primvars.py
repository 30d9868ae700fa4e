"""The custom primvars of a guide prim given to its render hair, as widths and colour are.

A DCC's guides carry primvars of their own (Blender's ``clump_weight``, ``rest_position``,
``surface_uv_coordinate``…), which the hair model does not hold. When ``interpolate`` writes the
children of a USD prim to a USD file, each primvar of the guide prim reaches the children's
render prim: per-vertex values (vertex, varying) blended at every child vertex from its guides
at the same root-to-tip parameter with the binding's weights
(:func:`hairtool.guides.attributes.blend`), per-curve values (uniform) blended by the weights,
constant ones copied. Values that cannot be blended (ints, bools, strings, tokens) are taken
from the child's nearest guide (at the nearest parameter for per-vertex ones). Primvars the
writer authors itself (widths, colour, opacity) and those the render prim already has are left.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from hairtool.guides.attributes import blend
from hairtool.io import usd_basis
from hairtool.io.usd_carry import export_stage

#: Primvars the writer makes from the groom: never taken from the guides.
_OWN = ("displayColor", "displayOpacity", "color", "widths", "normals")


def _nearest(values: np.ndarray, binding, per_vertex: bool) -> np.ndarray:
    """Per child (or child vertex), the value of its nearest guide (at the nearest parameter)."""
    first = binding.guide_ids[:, 0]
    if not per_vertex:
        return values[first]
    guides = binding.rest_guides
    child = np.repeat(np.arange(binding.child_count), binding.counts)
    n = binding.counts[child]
    i = np.arange(binding.vertex_count) - binding.topology.offsets[child]
    g = first[child]
    m = guides.counts[g]
    return values[guides.offsets[g] + np.rint(i * (m - 1) / (n - 1)).astype(np.int64)]


def _child_values(pv, binding, counts, basis: str, wrap: str):
    """``(values, interpolation)`` of one guide primvar for the children, or None to leave it."""
    interp = str(pv.GetInterpolation())
    raw = pv.ComputeFlattened()
    if raw is None or pv.GetElementSize() != 1:
        return None
    if interp == "constant":
        return raw, interp
    values = np.asarray(raw)
    numeric = values.dtype.kind == "f"
    if interp == "uniform":
        if len(values) != len(counts):
            return None
        if numeric:
            w = binding.weights
            mixed = np.einsum("ck,ck...->c...", w, values.astype(np.float64)[binding.guide_ids])
            return mixed.astype(values.dtype), interp
        return _nearest(values, binding, per_vertex=False), interp
    if interp not in ("vertex", "varying"):
        return None
    if usd_basis.expected_count(interp, counts, basis, wrap) != len(values):
        return None
    if numeric:
        per_vertex = usd_basis.per_vertex(values.astype(np.float64), interp, counts, basis, wrap)
        return blend(per_vertex, binding).astype(values.dtype), "vertex"
    if interp != "vertex":
        return None
    return _nearest(values, binding, per_vertex=True), "vertex"


def give_children_primvars(
    source: str | os.PathLike[str], written: str | os.PathLike[str], pairs
) -> list[str]:
    """For each ``(guide prim path in source, render prim path in written, binding)``, the guide
    prim's primvars on the render prim (module doc); ``written`` rewritten atomically when
    anything was added. Returns the primvars added (``path.primvars:name``). Both must be USD."""
    from pxr import Sdf, Usd, UsdGeom

    from hairtool.io.usd import _open_stage

    src, out = Path(source), Path(written)
    stage = _open_stage(src)
    dst = Sdf.Layer.CreateAnonymous(out.suffix)
    dst.TransferContent(Sdf.Layer.OpenAsAnonymous(str(out)))
    target = Usd.Stage.Open(dst)
    added = []
    for guide_path, render_path, binding in pairs:
        prim, hair = stage.GetPrimAtPath(guide_path), target.GetPrimAtPath(render_path)
        if not (prim and hair and prim.IsA(UsdGeom.BasisCurves)):
            continue
        curves = UsdGeom.BasisCurves(prim)
        counts = np.asarray(curves.GetCurveVertexCountsAttr().Get() or [], np.int64)
        if not np.array_equal(counts, binding.rest_guides.counts):
            continue
        basis = "linear" if curves.GetTypeAttr().Get() == "linear" else str(curves.GetBasisAttr().Get())
        wrap = str(curves.GetWrapAttr().Get())
        mine = UsdGeom.PrimvarsAPI(hair)
        for pv in UsdGeom.PrimvarsAPI(prim).GetPrimvars():
            name = str(pv.GetPrimvarName())
            if name in _OWN or mine.HasPrimvar(name) or not pv.HasAuthoredValue():
                continue
            got = _child_values(pv, binding, counts, basis, wrap)
            if got is None:
                continue
            values, interp = got
            made = mine.CreatePrimvar(name, pv.GetTypeName(), interp)
            array = pv.GetTypeName().type.pythonClass
            made.Set(values if interp == "constant" else as_vt(array, values))
            added.append(f"{render_path}.primvars:{name}")
    if added:
        export_stage(dst, out)
    return added


def as_vt(array_class, values: np.ndarray):
    """A Vt array of ``array_class`` holding ``values`` (through numpy where it can).

    Parameters
    ----------
    array_class : type
        The Vt array type a primvar's type name holds (``Vt.FloatArray``…).
    values : ndarray
        The values, one per element.

    Returns
    -------
    object
        The Vt array.
    """
    if hasattr(array_class, "FromNumpy") and values.dtype.kind in "fiub":
        return array_class.FromNumpy(np.ascontiguousarray(values))
    return array_class([v.item() if hasattr(v, "item") else v for v in values])
