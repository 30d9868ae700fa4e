"""The surface a USD groom sits on: the ``Mesh`` prims beside its curves (a head, a scalp).

A DCC's export of a groom carries the head it was groomed on as ``UsdGeom.Mesh`` prims next to
the ``BasisCurves``. :func:`read_mesh` merges them, in traversal order, into one
:class:`~hairtool.io.obj.Mesh` in world space (each prim's local-to-world transform at the
default time), polygons fan-triangulated, normals area-weighted per vertex; each prim's
triangles form a face set named after the prim. :func:`add_mesh` writes a mesh as one prim
into a stage the groom writer made. Bad data (indices out of range, fewer than 3 corners,
non-finite points) is one :class:`~hairtool.errors.FormatError` naming the file.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from hairtool.errors import FormatError
from hairtool.io import usd
from hairtool.io.atomic import atomic_path
from hairtool.io.obj import Mesh

MESH_PATH = "/Groom/Head"


def _prim_mesh(path: Path, prim, xforms) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """One Mesh prim: world vertices (float64), corner counts and corner vertex indices."""
    from pxr import Gf, Usd, UsdGeom

    mesh = UsdGeom.Mesh(prim)
    name = str(prim.GetPath())
    t = Usd.TimeCode.Default()
    points = usd._value(path, mesh.GetPointsAttr(), t, "vec3[]")
    counts = usd._value(path, mesh.GetFaceVertexCountsAttr(), t, "int[]")
    indices = usd._value(path, mesh.GetFaceVertexIndicesAttr(), t, "int[]")
    if points is None or counts is None or indices is None:
        raise FormatError(path, f"{name}: a mesh needs points, faceVertexCounts and faceVertexIndices")
    p = np.asarray(points, np.float64).reshape(-1, 3)
    sizes = np.asarray(counts, np.int64).reshape(-1)
    idx = np.asarray(indices, np.int64).reshape(-1)
    if sizes.size and sizes.min() < 3:
        raise FormatError(path, f"{name}: a face needs at least 3 corners")
    if int(sizes.sum()) != idx.size:
        total = int(sizes.sum())
        raise FormatError(path, f"{name}: faceVertexCounts add up to {total}, not {idx.size} indices")
    if idx.size and (idx.min() < 0 or idx.max() >= len(p)):
        raise FormatError(path, f"{name}: a face index is out of range (the mesh has {len(p)} points)")
    m = xforms.GetLocalToWorldTransform(prim)
    if m != Gf.Matrix4d(1.0):
        m = np.asarray(m, np.float64)
        if not np.all(np.isfinite(m)):
            raise FormatError(path, f"{name} has a non-finite transform")
        with np.errstate(over="ignore", invalid="ignore"):  # checked just below, as one line
            p = p @ m[:3, :3] + m[3, :3]
    if not np.all(np.isfinite(p)) or (p.size and np.abs(p).max() > np.finfo(np.float32).max):
        raise FormatError(path, f"{name} has a point that is not a finite float32")
    return p, sizes, idx


def fan_triangles(sizes: np.ndarray, corners: np.ndarray) -> np.ndarray:
    """``(T, 3)`` triangles (0, j, j+1) of each polygon of ``sizes`` corners listed in ``corners``.

    Parameters
    ----------
    sizes : ndarray
        Each polygon's corner count.
    corners : ndarray
        The corners, polygon after polygon.

    Returns
    -------
    ndarray
        ``(T, 3)`` int64.
    """
    start = np.cumsum(sizes) - sizes
    n_tri = sizes - 2
    first = np.repeat(start, n_tri)
    j = np.arange(int(n_tri.sum()), dtype=np.int64) - np.repeat(np.cumsum(n_tri) - n_tri, n_tri) + 1
    return corners[np.stack([first, first + j, first + j + 1], axis=1)]


def vertex_normals(vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """Unit area-weighted vertex normals (zero where no face touches a vertex).

    Parameters
    ----------
    vertices : ndarray
        ``(Vm, 3)``.
    faces : ndarray
        ``(F, 3)``.

    Returns
    -------
    ndarray
        ``(Vm, 3)`` float64.
    """
    a, b, c = (vertices[faces[:, k]] for k in range(3))
    face_normals = np.cross(b - a, c - a)  # length = twice the area: area weighting for free
    flat = faces.reshape(-1)
    rep = np.repeat(face_normals, 3, axis=0)
    n = len(vertices)
    summed = np.stack([np.bincount(flat, weights=rep[:, k], minlength=n) for k in range(3)], axis=1)
    length = np.linalg.norm(summed, axis=1, keepdims=True)
    return np.divide(summed, length, out=np.zeros_like(summed), where=length > 0)


def read_mesh(path: str | os.PathLike[str]) -> Mesh | None:
    """The stage's Mesh prims merged into one triangle mesh, or None when it has none.

    Parameters
    ----------
    path : str or os.PathLike
        A USD stage.

    Returns
    -------
    Mesh or None
        The mesh.
    """
    from pxr import Usd, UsdGeom

    p = Path(path)

    def work():
        stage = usd._open_stage(p)
        prims = [q for q in stage.Traverse() if q.IsA(UsdGeom.Mesh)]
        if not prims:
            return None
        xforms = UsdGeom.XformCache(Usd.TimeCode.Default())
        return [(str(q.GetPath()), *_prim_mesh(p, q, xforms)) for q in prims]

    # through the curves reader's guard: usd-core's warnings folded into one line, never stderr
    parts = usd._diagnosed(p, work)
    if parts is None:
        return None
    vertices, faces, groups, base, tri = [], [], {}, 0, 0
    for name, v, sizes, idx in parts:
        f = fan_triangles(sizes, idx) + base
        vertices.append(v)
        faces.append(f)
        groups[name.rsplit("/", 1)[-1]] = np.arange(tri, tri + len(f), dtype=np.int64)
        base, tri = base + len(v), tri + len(f)
    v = np.concatenate(vertices)
    f = np.concatenate(faces)
    if len(f) == 0:
        return None
    if len(v) > np.iinfo(np.int32).max:
        raise FormatError(p, "too many mesh points for int32 face indices")
    normals = vertex_normals(v, f)
    return Mesh(v.astype(np.float32), f.astype(np.int32), normals.astype(np.float32), groups)


def add_mesh(path: str | os.PathLike[str], mesh: Mesh, prim_path: str = MESH_PATH) -> None:
    """Add ``mesh`` as one Mesh prim to the USD file at ``path`` (rewritten atomically).

    Parameters
    ----------
    path : str or os.PathLike
        The USD file.
    mesh : Mesh
        The mesh.
    prim_path : str, default MESH_PATH
        Where the prim goes.
    """
    from pxr import Sdf, UsdGeom, Vt

    p = Path(path)
    try:
        with atomic_path(p) as tmp:
            stage = usd._open_stage(p)
            while stage.GetPrimAtPath(prim_path):
                prim_path += "_"
            parent = Sdf.Path(prim_path).GetParentPath()
            if parent != Sdf.Path.absoluteRootPath and not stage.GetPrimAtPath(parent):
                UsdGeom.Xform.Define(stage, parent)
            prim = UsdGeom.Mesh.Define(stage, prim_path)
            v = np.ascontiguousarray(mesh.vertices, np.float32)
            f = np.ascontiguousarray(mesh.faces, np.int32)
            prim.CreatePointsAttr(Vt.Vec3fArray.FromNumpy(v))
            prim.CreateFaceVertexCountsAttr(Vt.IntArray.FromNumpy(np.full(len(f), 3, np.int32)))
            prim.CreateFaceVertexIndicesAttr(Vt.IntArray.FromNumpy(f.reshape(-1)))
            prim.CreateSubdivisionSchemeAttr(UsdGeom.Tokens.none)
            if len(v):
                prim.CreateExtentAttr(Vt.Vec3fArray.FromNumpy(np.stack([v.min(axis=0), v.max(axis=0)])))
            stage.GetRootLayer().Export(str(tmp))
    except OSError as e:
        raise FormatError(p, f"cannot write: {e}") from None
