"""The custom primvars of a curves prim whose strands a stroke log planted and deleted.

A DCC's hair prim carries primvars the hair model does not hold (Blender's ``clump_weight``,
``surface_uv_coordinate``…). When ``freeze --strokes`` adds, deletes or thins strands, the prim
written back holds other strands than the source's, so its primvars cannot be copied as they
were. The frozen pipeline records, for each strand it now has, the source strand it comes from
(its ``origin``, −1 for a planted one: :attr:`~hairtool.frozen.pipeline.FrozenPipeline.origin`).
Each primvar is given to the strands now as planting gives widths and colour
(:func:`~hairtool.frozen.brushes.add.append_strands`):

- a kept strand keeps its own values (per curve, and per vertex where its vertex count is the
  same, to the bit);
- a planted strand takes those of the nearest kept strand by root (the lower index on a tie),
  per-vertex values by the vertex parameter: floats interpolated linearly, ints, bools and
  strings at the nearest parameter;
- a deleted strand's values go with it; constant primvars are copied.

Per-vertex values are written ``vertex`` (``varying`` ones of cubic curves made per vertex, as
the reader does for widths). Children grown from the result then get their guides' values as
always (:mod:`hairtool.guides.child_primvars`).
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from hairtool.frozen.root_grid import nearest_root
from hairtool.groom import Groom
from hairtool.io import usd_basis
from hairtool.io.usd_carry import export_stage

#: Primvars the writer makes from the groom: never taken from the source.
_OWN = ("displayColor", "displayOpacity", "color", "widths", "normals")


def sources_of(origin: np.ndarray, was: Groom, now: Groom) -> np.ndarray:
    """Per strand of ``now``, the strand of ``was`` whose values it takes: its ``origin``, or
    for a planted one (origin −1) the kept strand whose root is nearest.

    Parameters
    ----------
    origin : ndarray
        ``(S_now,)`` the strand of ``was`` each strand of ``now`` comes from, −1 where planted.
    was, now : Groom
        The prim's strands before and after the strokes.

    Returns
    -------
    ndarray
        ``(S_now,)`` int64 indices into ``was``'s strands.
    """
    origin = np.asarray(origin, np.int64)
    out = origin.copy()
    planted = np.flatnonzero(origin < 0)
    kept = np.unique(origin[origin >= 0])
    if len(planted):
        pool = kept if len(kept) else np.arange(was.strand_count)
        near = nearest_root(was.roots[pool].astype(np.float64), now.roots[planted].astype(np.float64))
        out[planted] = pool[near]
    return out


def per_strand_values(values: np.ndarray, sources: np.ndarray, was_counts, now_counts) -> np.ndarray:
    """Per-vertex ``values`` of the strands ``was_counts`` given to the strands ``now_counts``,
    each from its source strand (``sources``): its rows where the vertex counts agree, else
    resampled by the vertex parameter (floats linearly, other kinds at the nearest parameter).

    Parameters
    ----------
    values : ndarray
        ``(V_was, ...)`` per-vertex values.
    sources : ndarray
        ``(S_now,)`` each new strand's source strand.
    was_counts, now_counts : ndarray
        The vertex counts of the strands before and after.

    Returns
    -------
    ndarray
        ``(V_now, ...)`` values of ``values``' dtype.
    """
    was_counts, now_counts = np.asarray(was_counts, np.int64), np.asarray(now_counts, np.int64)
    was_off = np.concatenate([[0], np.cumsum(was_counts)])
    rows = []
    for s, n in zip(np.asarray(sources, np.int64), now_counts, strict=True):
        m = int(was_counts[s])
        own = values[was_off[s] : was_off[s] + m]
        if m == n:
            rows.append(own)
            continue
        t_now = np.linspace(0.0, 1.0, int(n)) if n > 1 else np.zeros(1)
        t_was = np.linspace(0.0, 1.0, m) if m > 1 else np.zeros(1)
        if values.dtype.kind == "f" and m > 1:
            flat = own.reshape(m, -1).astype(np.float64)
            cols = [np.interp(t_now, t_was, flat[:, c]) for c in range(flat.shape[1])]
            rows.append(np.column_stack(cols).reshape((int(n), *own.shape[1:])).astype(values.dtype))
        else:
            rows.append(own[np.rint(t_now * (m - 1)).astype(np.int64)])
    if not rows:
        return values[:0]
    return np.concatenate(rows)


def _strand_values(pv, sources, was: Groom, now: Groom, basis: str, wrap: str):
    """``(values, interpolation)`` of one primvar for the strands now, or None to leave it."""
    interp = str(pv.GetInterpolation())
    raw = pv.ComputeFlattened()
    if raw is None or pv.GetElementSize() != 1:
        return None
    if interp == "constant":
        return raw, interp
    values = np.asarray(raw)
    if interp == "uniform":
        return (values[sources], interp) if len(values) == was.strand_count else None
    if interp not in ("vertex", "varying"):
        return None
    if usd_basis.expected_count(interp, was.counts, basis, wrap) != len(values):
        return None
    if interp == "varying" and values.dtype.kind != "f" and basis != "linear":
        return None  # (ints between the segment ends of cubic curves: no per-vertex form)
    if interp == "varying" and basis != "linear":
        values = usd_basis.per_vertex(values.astype(np.float64), interp, was.counts, basis, wrap)
        values = values.astype(np.asarray(raw).dtype)
    return per_strand_values(values, sources, was.counts, now.counts), "vertex"


def give_strands_primvars(
    source: str | os.PathLike[str], written: str | os.PathLike[str], prims
) -> list[str]:
    """For each ``(source prim path, written prim path, origin, was, now)`` (the prim's strands
    before and after the strokes, each strand's origin), the source prim's primvars on the
    written prim (module doc), replacing any the written prim has of the same name; ``written``
    rewritten atomically when anything was given. Returns the primvars given
    (``path.primvars:name``). Both USD.

    Parameters
    ----------
    source : str or os.PathLike
        The command's USD input.
    written : str or os.PathLike
        The USD file it wrote.
    prims : iterable
        ``(source path, written path, origin, was, now)`` per prim whose strands changed.

    Returns
    -------
    list of str
        The primvars given.
    """
    from pxr import Sdf, Usd, UsdGeom

    from hairtool.guides.child_primvars import as_vt
    from hairtool.io.usd import _open_stage

    stage = _open_stage(Path(source))
    out = Path(written)
    dst = Sdf.Layer.CreateAnonymous(out.suffix)
    dst.TransferContent(Sdf.Layer.OpenAsAnonymous(str(out)))
    target = Usd.Stage.Open(dst)
    given = []
    for path, path_now, origin, was, now in prims:
        prim, mine = stage.GetPrimAtPath(path), target.GetPrimAtPath(path_now)
        if not (prim and mine and prim.IsA(UsdGeom.BasisCurves)):
            continue
        curves = UsdGeom.BasisCurves(prim)
        counts = np.asarray(curves.GetCurveVertexCountsAttr().Get() or [], np.int64)
        if not np.array_equal(counts, was.counts):
            continue
        basis = "linear" if curves.GetTypeAttr().Get() == "linear" else str(curves.GetBasisAttr().Get())
        wrap = str(curves.GetWrapAttr().Get())
        sources = sources_of(origin, was, now)
        api = UsdGeom.PrimvarsAPI(mine)
        for pv in UsdGeom.PrimvarsAPI(prim).GetPrimvars():
            name = str(pv.GetPrimvarName())
            if name in _OWN or not pv.HasAuthoredValue():
                continue
            got = _strand_values(pv, sources, was, now, basis, wrap)
            if got is None:
                continue
            values, interp = got
            if api.HasPrimvar(name):  # (one the scene's carry copied onto strands it does not fit)
                mine.RemoveProperty(f"primvars:{name}")
                mine.RemoveProperty(f"primvars:{name}:indices")
            made = api.CreatePrimvar(name, pv.GetTypeName(), interp)
            array = pv.GetTypeName().type.pythonClass
            made.Set(values if interp == "constant" else as_vt(array, values))
            given.append(f"{path_now}.primvars:{name}")
    if given:
        export_stage(dst, out)
    return given
