"""The scalp children grow on, read from a USD stage or an OBJ and brought into the groom's frame.

A USD scalp is the stage's Mesh prims (:func:`hairtool.io.usd_mesh.read_mesh`), in the up axis
and unit the stage declares. An OBJ says neither: it is taken in the groom's unit, and in the
groom's up axis unless ``up_axis`` names the file's (Blender's default OBJ export is Y-up while
its USD grooms are Z-up). Either is turned and scaled into the groom's frame, and refused in one
line, with both bounding boxes, when its surface lies far from the guide roots: a head in the
wrong axis or unit would otherwise grow every child away from its guides.
"""

from __future__ import annotations

import os
from dataclasses import replace
from pathlib import Path

import numpy as np

from hairtool.errors import FormatError, ParameterError
from hairtool.io.obj import Mesh
from hairtool.metadata import Metadata

USD_SUFFIXES = (".usd", ".usda", ".usdc")
UP_AXES = ("y", "z")
#: The scalp is refused when the median guide root lies farther from its surface than this
#: share of the groom's size (the diagonal of its bounding box).
FAR_SHARE = 0.1
#: Guide roots the fit is measured on at most (evenly picked), so a dense groom costs no more.
FIT_ROOTS = 128


def is_usd(path: str | os.PathLike[str]) -> bool:
    """Whether ``path`` names a USD file (by its suffix).

    Parameters
    ----------
    path : str or os.PathLike
        The scalp's path.

    Returns
    -------
    bool
        True for ``.usd``, ``.usda`` and ``.usdc``.
    """
    return Path(path).suffix.lower() in USD_SUFFIXES


def check_up_axis(path: str | os.PathLike[str] | None, up_axis: str | None) -> None:
    """Refuse ``--scalp-up-axis`` without a scalp, or for a USD scalp (its stage says its own).

    Parameters
    ----------
    path : str or os.PathLike or None
        The scalp (None: none given).
    up_axis : str or None
        ``"y"`` or ``"z"``, the OBJ's up axis (None: the groom's).
    """
    if up_axis is None:
        return
    if path is None:
        raise ParameterError("scalp-up-axis", up_axis, "a --scalp MESH.obj whose up axis it names")
    if is_usd(path):
        raise ParameterError("scalp-up-axis", up_axis, f"none for a USD scalp ({path} declares its up axis)")
    if str(up_axis).lower() not in UP_AXES:
        raise ParameterError("scalp-up-axis", up_axis, " or ".join(UP_AXES))


def _stage_frame(path: Path) -> Metadata:
    """The up axis and unit a USD stage declares."""
    from hairtool.io import usd

    def work():
        return usd._stage_metadata(path, usd._open_stage(path))

    found = usd._diagnosed(path, work)
    return Metadata(up_axis=found["up_axis"], meters_per_unit=found["meters_per_unit"])


def to_frame(mesh: Mesh, source: Metadata, target: Metadata) -> Mesh:
    """``mesh`` in ``source``'s up axis and unit, turned and scaled into ``target``'s (through
    hairtool's reference frame, :attr:`~hairtool.metadata.Metadata.frame`); the same mesh when
    both agree.

    Parameters
    ----------
    mesh : Mesh
        The scalp as read.
    source : Metadata
        Its up axis and unit.
    target : Metadata
        The groom's.

    Returns
    -------
    Mesh
        The scalp in the groom's frame.
    """
    turn = source.frame @ target.frame.T  # scene rows -> reference -> the target's scene
    scale = source.meters_per_unit / target.meters_per_unit
    if source.up_axis == target.up_axis and scale == 1.0:
        return mesh
    v = (mesh.vertices.astype(np.float64) @ turn) * scale
    if not np.all(np.isfinite(v)) or (v.size and np.abs(v).max() > np.finfo(np.float32).max):
        raise ParameterError("scalp", "a mesh that overflows float32", "finite points in the groom's unit")
    n = mesh.normals.astype(np.float64) @ turn
    return replace(mesh, vertices=v.astype(np.float32), normals=n.astype(np.float32))


def read_scalp(path: str | os.PathLike[str], frame: Metadata, up_axis: str | None = None) -> Mesh:
    """The scalp at ``path`` in the frame (up axis, unit) of the groom whose metadata is ``frame``.

    Parameters
    ----------
    path
        A USD file with Mesh prims (world space, in its stage's up axis and unit), or an OBJ.
    frame
        The groom's metadata: its up axis and meters per unit.
    up_axis
        ``"y"`` or ``"z"``: an OBJ's up axis (default: the groom's); None for USD.

    Raises
    ------
    FormatError
        The file is missing, unreadable, or (USD) has no Mesh prim.
    ParameterError
        ``up_axis`` given for a USD file, or not y/z.
    """
    check_up_axis(path, up_axis)
    p = Path(path)
    if is_usd(p):
        from hairtool.io.usd_mesh import read_mesh

        if not p.is_file():
            raise FormatError(p, "no such file")
        mesh = read_mesh(p)
        if mesh is None:
            raise FormatError(p, "no Mesh prim with faces to grow hair on")
        source = _stage_frame(p)
    else:
        from hairtool.io.obj import read_mesh

        mesh = read_mesh(p)
        source = Metadata(up_axis=(up_axis or frame.up_axis).upper(), meters_per_unit=frame.meters_per_unit)
    return to_frame(mesh, source, frame)


def _box(points: np.ndarray) -> str:
    lo, hi = points.min(axis=0), points.max(axis=0)
    return "[" + ", ".join(f"{a:.4g}..{b:.4g}" for a, b in zip(lo, hi, strict=True)) + "]"


def root_distances(mesh: Mesh, roots: np.ndarray) -> np.ndarray:
    """Distances from (at most :data:`FIT_ROOTS`, evenly picked) ``roots`` to the mesh surface.

    Parameters
    ----------
    mesh : Mesh
        The scalp, in the groom's frame.
    roots : ndarray
        ``(S, 3)`` guide roots.

    Returns
    -------
    ndarray
        Up to :data:`FIT_ROOTS` float64 distances.
    """
    from hairtool.guides.surface import closest_points

    r = np.asarray(roots, np.float64).reshape(-1, 3)
    if len(r) > FIT_ROOTS:
        r = r[np.linspace(0, len(r) - 1, FIT_ROOTS).round().astype(np.int64)]
    on, _ = closest_points(mesh, r)
    return np.linalg.norm(on - r, axis=1)


def check_fit(path: str | os.PathLike[str], mesh: Mesh, points: np.ndarray, roots: np.ndarray) -> None:
    """Refuse a scalp whose surface lies farther from the guide ``roots`` (median) than
    :data:`FAR_SHARE` of the size of the groom (``points``): one line with both boxes.

    Parameters
    ----------
    path : str or os.PathLike
        The scalp, named in the refusal.
    mesh : Mesh
        The scalp, in the groom's frame.
    points : ndarray
        ``(V, 3)`` the groom's points (its size).
    roots : ndarray
        ``(S, 3)`` its guide roots.

    Raises
    ------
    FormatError
        Where the scalp lies too far from the roots.
    """
    pts = np.asarray(points, np.float64).reshape(-1, 3)
    if len(pts) == 0 or len(mesh.faces) == 0:
        return
    size = float(np.linalg.norm(pts.max(axis=0) - pts.min(axis=0)))
    gap = float(np.median(root_distances(mesh, roots)))
    if gap > FAR_SHARE * size:
        raise FormatError(
            path,
            f"the scalp lies {gap:.4g} from the guide roots (median), more than {FAR_SHARE:.0%} of the "
            f"groom's size {size:.4g}: scalp box {_box(mesh.vertices.astype(np.float64))}, groom box "
            f"{_box(pts)}, in the groom's unit and up axis (an OBJ in another up axis: --scalp-up-axis)",
        )


def load_scalp(path: str | os.PathLike[str], groom, up_axis: str | None = None) -> Mesh:
    """:func:`read_scalp` in ``groom``'s frame, checked to lie where its roots are (:func:`check_fit`).

    Parameters
    ----------
    path : str or os.PathLike
        A USD stage or an OBJ.
    groom : Groom
        The guides whose frame and roots the scalp must match.
    up_axis : str, optional
        An OBJ's up axis, ``"y"`` or ``"z"`` (None: the groom's).

    Returns
    -------
    Mesh
        The scalp in the groom's frame.
    """
    mesh = read_scalp(path, groom.metadata, up_axis)
    check_fit(path, mesh, groom.points, groom.roots)
    return mesh
