"""Wavefront OBJ: strands as polylines (``l`` records) and head meshes (``f`` records) for display.

A groom is written as ``v`` records with ``%.9g`` (enough digits that every float32 reads back
bit-exact) and one ``l`` record per strand with 1-based indices. Reading takes every ``l``
record as one strand; ``read_mesh`` triangulates polygons (as fans) for drawing a head or scalp.
Indices may be negative (relative to the vertices read so far) and may carry ``/vt/vn`` parts.
Parsing splits lines once and converts whole columns with numpy; no per-vertex arithmetic in
Python.
"""

from __future__ import annotations

import itertools
import os
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from hairtool.errors import FormatError
from hairtool.groom import Animation, Groom
from hairtool.io.atomic import atomic_open
from hairtool.io.binary import float32_finite, require_strand_counts
from hairtool.metadata import Metadata


@dataclass(frozen=True)
class Mesh:
    """A triangle mesh: ``vertices`` float32 (n, 3), ``faces`` int32 (m, 3), ``normals`` float32 (n, 3).

    Normals are unit length; a vertex that no face touches has a zero normal. ``groups``: the
    triangles (int64 indices) of each named face set of the file (``g`` and ``o`` records),
    e.g. the scalp where hair grows.
    """

    vertices: np.ndarray
    faces: np.ndarray
    normals: np.ndarray
    groups: dict[str, np.ndarray] = field(default_factory=dict)


class _Records:
    """The ``v``, ``vn``, ``l`` and ``f`` records of an OBJ file, as split tokens."""

    def __init__(self, path: Path) -> None:
        # latin-1 never fails to decode; every token we parse is ASCII anyway.
        text = path.read_bytes().decode("latin-1")
        if not text.strip():
            raise FormatError(path, "the file is empty")
        self.path = path
        v: list[str] = []  # whole lines: split and converted together below
        vn: list[str] = []
        self.lines: list[tuple[int, list[str]]] = []  # (vertices so far, index tokens)
        self.faces: list[tuple[int, int, list[str]]] = []  # (vertices so far, normals so far, corners)
        self.face_sets: list[int] = []  # per face: its index in self.set_names
        self.set_names: list[tuple[str, ...]] = [()]  # the g/o names a face is in
        names: dict[str, tuple[str, ...]] = {"g": (), "o": ()}
        for number, line in enumerate(text.splitlines(), 1):
            if line.startswith("v "):
                v.append(line)
                continue
            parts = line.split()
            if not parts:
                continue
            key = parts[0]
            if key == "v":
                v.append(line)
            elif key == "vn":
                vn.append(line)
            elif key == "l":
                self.lines.append((len(v), parts[1:]))
            elif key == "f":
                if len(parts) < 4:
                    raise FormatError(path, f"line {number}: a face needs at least 3 corners")
                self.faces.append((len(v), len(vn), parts[1:]))
                self.face_sets.append(len(self.set_names) - 1)
            elif key in ("g", "o"):
                names[key] = tuple(parts[1:])
                self.set_names.append(names["o"] + names["g"])
        self.vertices = _floats(path, v, "v")
        self.vertex_normals = _floats(path, vn, "vn")


def _floats(path: Path, lines: list[str], key: str) -> np.ndarray:
    """x y z of ``v`` / ``vn`` lines as float64 (n, 3); extra columns (w, colours) are ignored."""
    n = len(lines)
    if n == 0:
        return np.zeros((0, 3), dtype=np.float64)
    tokens = " ".join(lines).split()
    try:
        if len(tokens) == 4 * n and tokens[::4].count(key) == n:  # fast path: exactly "key x y z"
            flat = [float(t) for t in tokens[1::4] + tokens[2::4] + tokens[3::4]]
            a = np.array(flat, dtype=np.float64).reshape(3, n).T.copy()
        else:
            rows = [ln.split() for ln in lines]
            if min(len(r) for r in rows) < 4:
                raise FormatError(path, f"a '{key}' record needs x y z")
            a = np.array([[float(t) for t in r[1:4]] for r in rows], dtype=np.float64)
    except ValueError:
        raise FormatError(path, f"a '{key}' record has a coordinate that is not a number") from None
    float32_finite(path, a, f"'{key}' coordinates")  # grooms and meshes are float32: cast, then check
    return a


def _indices(path: Path, tokens: list[str], known: np.ndarray, total: int, what: str) -> np.ndarray:
    """0-based indices from OBJ tokens: 1-based, or negative = relative to ``known`` read so far."""
    try:
        i = np.array([int(t) for t in tokens], dtype=np.int64)
    except (ValueError, OverflowError):
        raise FormatError(path, f"a {what} index is not a whole number") from None
    if np.any(i == 0):
        raise FormatError(path, f"{what} index 0 (OBJ indices start at 1)")
    idx = np.where(i > 0, i - 1, known + i)
    if idx.size and (idx.min() < 0 or idx.max() >= total):
        raise FormatError(path, f"a {what} index is out of range (the file has {total})")
    return idx


def read(path: Path) -> Groom:
    """Every ``l`` record is one strand (at least 2 points).

    Parameters
    ----------
    path : Path
        An OBJ of polylines.

    Returns
    -------
    Groom
        One strand per ``l`` record.
    """
    rec = _Records(path)
    if not rec.lines:
        hint = " (it holds faces: a mesh, see read_mesh)" if rec.faces else ""
        raise FormatError(path, f"no polylines ('l' records){hint}")
    counts = np.array([len(t) for _, t in rec.lines], dtype=np.int64)
    require_strand_counts(path, counts)
    tokens = [t.split("/", 1)[0] for _, ts in rec.lines for t in ts]
    known = np.repeat(np.array([k for k, _ in rec.lines], dtype=np.int64), counts)
    idx = _indices(path, tokens, known, len(rec.vertices), "vertex")
    return Groom(rec.vertices[idx].astype(np.float32), counts, metadata=Metadata())  # no scene in OBJ


def read_mesh(path: str | os.PathLike[str]) -> Mesh:
    """A head or scalp mesh for display: polygons fan-triangulated, normals per vertex.

    Normals come from the file's ``vn`` records (averaged per vertex) when every face corner
    names one; otherwise they are computed, area-weighted, from the triangles.

    Parameters
    ----------
    path
        A Wavefront OBJ file with ``f`` records (``g``/``o`` names become face sets).

    Returns
    -------
    Mesh
        float32 vertices ``(n, 3)``, int32 triangles ``(m, 3)``, float32 unit normals ``(n, 3)``
        and the face sets, each an array of triangle indices.

    Raises
    ------
    FormatError
        The file is missing, has no faces, or a face names a vertex or normal it lacks.
    """
    p = Path(path)
    if not p.is_file():
        raise FormatError(p, "no such file")
    rec = _Records(p)
    if not rec.faces:
        raise FormatError(p, "no faces ('f' records)")
    if len(rec.vertices) > np.iinfo(np.int32).max:
        raise FormatError(p, "too many vertices for int32 face indices")
    corners = [c.split("/") for _, _, cs in rec.faces for c in cs]
    sizes = np.array([len(cs) for _, _, cs in rec.faces], dtype=np.int64)
    known_v = np.repeat(np.array([k for k, _, _ in rec.faces], dtype=np.int64), sizes)
    vid = _indices(p, [c[0] for c in corners], known_v, len(rec.vertices), "vertex")
    # Fan triangulation: corners (0, j, j+1) of each polygon, j = 1 .. k−2.
    start = np.cumsum(sizes) - sizes
    n_tri = sizes - 2
    first = np.repeat(start, n_tri)
    j = np.arange(int(n_tri.sum()), dtype=np.int64) - np.repeat(np.cumsum(n_tri) - n_tri, n_tri) + 1
    tri_corners = np.stack([first, first + j, first + j + 1], axis=1)
    faces = vid[tri_corners]
    vertices = rec.vertices

    has_normals = len(rec.vertex_normals) > 0 and all(len(c) >= 3 and c[2] for c in corners)
    if has_normals:
        known_n = np.repeat(np.array([k for _, k, _ in rec.faces], dtype=np.int64), sizes)
        nid = _indices(p, [c[2] for c in corners], known_n, len(rec.vertex_normals), "normal")
        summed = _scatter_sum(vid, rec.vertex_normals[nid], len(vertices))
    else:
        a, b, c = (vertices[faces[:, k]] for k in range(3))
        face_normals = np.cross(b - a, c - a)  # length = twice the area: area weighting for free
        summed = _scatter_sum(faces.reshape(-1), np.repeat(face_normals, 3, axis=0), len(vertices))
    length = np.linalg.norm(summed, axis=1, keepdims=True)
    normals = np.divide(summed, length, out=np.zeros_like(summed), where=length > 0)
    tri_sets = np.repeat(np.array(rec.face_sets, np.int64), n_tri)
    groups: dict[str, list[int]] = {}
    for k in np.unique(tri_sets):
        for name in rec.set_names[k]:
            groups.setdefault(name, []).extend(np.flatnonzero(tri_sets == k).tolist())
    sets = {name: np.unique(np.array(ids, np.int64)) for name, ids in groups.items()}
    return Mesh(vertices.astype(np.float32), faces.astype(np.int32), normals.astype(np.float32), sets)


def _scatter_sum(index: np.ndarray, values: np.ndarray, n: int) -> np.ndarray:
    """Sum rows of ``values`` into ``n`` bins (float64)."""
    return np.stack([np.bincount(index, weights=values[:, k], minlength=n) for k in range(3)], axis=1)


def write(path: Path, obj: Groom | Animation) -> None:
    """Vertices with ``%.9g`` (float32 round-trips exactly), then one ``l`` record per strand.

    Parameters
    ----------
    path : Path
        The file, written atomically.
    obj : Groom or Animation
        What to write (an animation's rest pose, :attr:`Animation.rest`).
    """
    groom = obj.rest if isinstance(obj, Animation) else obj
    v = groom.vertex_count
    numbers = [str(i) for i in range(1, v + 1)]
    off = groom.offsets.tolist()
    with atomic_open(path, "w", encoding="ascii", newline="\n") as f:
        f.write(f"# hairtool groom: {groom.strand_count} strands, {v} vertices\n")
        f.write(("v %.9g %.9g %.9g\n" * v) % tuple(groom.points.ravel().tolist()))
        f.write("".join(f"l {' '.join(numbers[a:b])}\n" for a, b in itertools.pairwise(off)))
