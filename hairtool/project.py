"""A studio project in one file: the groom, its strokes, every setting and the animation.

The file (``.hairproj``) is a zip archive: ``manifest.json`` (format, version, engine
parameters, brush, display, key and other settings, and the list of array members) and one
``.npy`` member per array (rest groom, stroke log, the aligned state of the stroke snapshot,
the animation's frames, and for render hair the child definition: roots, guides and weights,
length scales and the frizz's recipe of :class:`~hairtool.guides.binding.ChildBinding`, never
the children's points, since they are rebuilt from the guides; for a dense groom bound to
guides, its points alone, the offsets that return it exactly being bound again on loading).
A zip keeps the manifest readable with any tool, the arrays exact (float32/float64 bit for
bit), lets a reader check every member's size and checksum before it trusts it, and loads
with ``allow_pickle=False``. The stroke log is stored as one column per sample field
(:mod:`hairtool.frozen.sample_columns`, from the descriptions of
:mod:`hairtool.frozen.sample_schema`).

Saving writes a temporary file beside the target and renames it, so an interrupted save never
harms the previous project. Loading checks everything and raises one
:class:`~hairtool.errors.FormatError` naming the file for a truncated, corrupt, foreign or
newer-version file.
"""

from __future__ import annotations

import dataclasses
import io
import json
import math
import os
import struct
import time
import zipfile
import zlib
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

import hairtool
from hairtool.errors import FormatError, GroomError, HairtoolError, ParameterError
from hairtool.frozen.brushes import BrushSample, check_eye, check_pressure, check_sample, check_view
from hairtool.frozen.pipeline import AlignSample, FrozenParams, FrozenPipeline, FrozenSnapshot
from hairtool.frozen.sample_columns import ColumnError, read_columns, write_columns
from hairtool.frozen.selection import SelectionSample, check_selection
from hairtool.frozen.strand_state import StrandState
from hairtool.groom import Animation, Groom
from hairtool.guides.binding import MAX_FRIZZ, ChildBinding, bind_exactly, curl
from hairtool.io import user_text
from hairtool.io.atomic import atomic_open
from hairtool.io.binary import float32_finite, require_finite, require_strand_counts
from hairtool.io.npz import read_npy_header
from hairtool.io.obj import Mesh
from hairtool.metadata import Metadata, from_record, to_record

FORMAT = "hairtool project"
FORMAT_VERSION = 3  # 2: brush strokes or render hair (children); 3: selection; 1 and 2 still read
READABLE_VERSIONS = (1, 2, 3)
SUFFIX = ".hairproj"
MANIFEST = "manifest.json"
MAX_MANIFEST_BYTES = 64 * 1024**2
#: Manifest strings that hold a whole file: the studio keeps a capture's BVH text there.
EMBEDDED_TEXTS = frozenset({"settings.capture.bvh"})
_MAX_DEFLATE_RATIO = 1100  # zlib never expands more than about 1032:1; more is a corrupt header
_ATTRIBUTES = ("thickness", "transparency", "colors")
_PARAM_FIELDS = tuple(f.name for f in dataclasses.fields(FrozenParams) if f.init)
_READ_ERRORS = (
    ValueError,
    OSError,
    EOFError,
    KeyError,
    TypeError,
    IndexError,
    zipfile.BadZipFile,
    zlib.error,
    struct.error,
    UnicodeDecodeError,
    NotImplementedError,
    RuntimeError,
    OverflowError,
    HairtoolError,
)


@dataclass(frozen=True, eq=False)
class Project:
    """Everything the studio needs to reopen a session.

    ``strokes`` and ``aligned`` are the frozen pipeline's stroke snapshot: the align log and the
    aligned points it produced (None: replay the log on load). ``brush``, ``display``,
    ``key_settings`` and ``settings`` are plain JSON objects the studio fills and reads back
    (the core only checks that they are JSON). ``animation_source`` says where the animation
    came from ("anime", "simulate", a file name …).
    """

    rest: Groom
    params: FrozenParams = field(default_factory=FrozenParams)
    strokes: tuple[AlignSample | BrushSample | SelectionSample, ...] = ()
    aligned: Groom | None = None
    brush: dict = field(default_factory=dict)
    display: dict = field(default_factory=dict)
    animation: Animation | None = None
    animation_source: str = ""
    key_settings: dict = field(default_factory=dict)
    settings: dict = field(default_factory=dict)
    groom_source: str | None = None
    children: ChildBinding | None = None  # render hair interpolated from ``rest`` (the guides)
    mesh: Mesh | None = None  # the head or scalp the groom sits on (part of the groom's document)

    @classmethod
    def from_pipeline(cls, pipeline: FrozenPipeline, **fields: Any) -> Project:
        """A project of the pipeline's rest groom, parameters and stroke snapshot.

        Parameters
        ----------
        pipeline : FrozenPipeline
            The groom being worked on.
        **fields : Any
            The project's other fields (settings, head mesh, capture...).

        Returns
        -------
        Project
            The project.
        """
        snap = pipeline.snapshot()
        # After a delete the stroked state has fewer strands than the rest groom: replayed on load.
        aligned = snap.aligned if snap.aligned.topology == pipeline.rest.topology else None
        return cls(rest=pipeline.rest, params=pipeline.params, strokes=snap.log, aligned=aligned, **fields)

    def stroke_snapshot(self, pipeline: FrozenPipeline) -> FrozenSnapshot:
        """The stroke snapshot to ``restore`` on a pipeline built from this project's rest and params.

        With ``aligned`` and only align strokes (which leave every strand's state as it was)
        the snapshot matches the pipeline's fresh frozen state, so no stroke is replayed;
        otherwise the log is replayed (it alone gives the per-strand state).

        Parameters
        ----------
        pipeline : FrozenPipeline
            A pipeline built from this project's rest and params.

        Returns
        -------
        FrozenSnapshot
            The snapshot to restore.
        """
        if self.aligned is None or not all(isinstance(s, AlignSample) for s in self.strokes):
            return FrozenSnapshot.replaying(self.strokes, pipeline.rest)
        current = pipeline.snapshot()
        state = StrandState.fresh(self.aligned.strand_count)
        return FrozenSnapshot(self.strokes, state, self.aligned, frozen_on=current.frozen_on)

    def pipeline(self) -> FrozenPipeline:
        """A pipeline in the saved state: rest, parameters and strokes."""
        p = FrozenPipeline(self.rest, self.params)
        p.restore(self.stroke_snapshot(p))
        return p


# -- writing ---------------------------------------------------------------------------------
def _params_json(params: FrozenParams, arrays: dict[str, np.ndarray]) -> dict:
    out: dict[str, Any] = {}
    for name in _PARAM_FIELDS:
        value = getattr(params, name)
        if name == "strand_variation" and np.ndim(value) != 0:
            arrays["params/strand_variation.npy"] = np.asarray(value, dtype=np.float64)
            value = {"array": "params/strand_variation.npy"}
        elif isinstance(value, (np.generic,)):
            value = value.item()
        out[name] = value
    return out


def _groom_arrays(prefix: str, obj: Groom | Animation, arrays: dict[str, np.ndarray]) -> dict:
    arrays[f"{prefix}/counts.npy"] = np.asarray(obj.counts, dtype=np.int64)
    if isinstance(obj, Animation):
        arrays[f"{prefix}/frames.npy"] = obj.frames
    else:
        arrays[f"{prefix}/points.npy"] = obj.points
    attrs = []
    for name in _ATTRIBUTES:
        value = getattr(obj, name)
        if value is not None:
            arrays[f"{prefix}/{name}.npy"] = value
            attrs.append(name)
    return {"attributes": attrs, "scene": to_record(obj.metadata)}


def _json_object(name: str, value: Any) -> dict:
    if not isinstance(value, Mapping):
        raise ParameterError(name, type(value).__name__, "a dict of plain JSON values")
    return dict(value)


def manifest_and_arrays(project: Project) -> tuple[dict, dict[str, np.ndarray]]:
    """The manifest (JSON-ready) and the arrays, by member name, that :func:`save` writes.

    Parameters
    ----------
    project : Project
        The project.

    Returns
    -------
    tuple of (dict, dict of str to ndarray)
        The manifest and the arrays.
    """
    arrays: dict[str, np.ndarray] = {}
    manifest: dict[str, Any] = {
        "format": FORMAT,
        "version": FORMAT_VERSION,
        "writer": f"hairtool {hairtool.__version__}",
        "saved": time.strftime("%Y-%m-%dT%H:%M:%S%z"),
        "groom": {
            "source": project.groom_source,
            **_groom_arrays("groom", project.rest, arrays),
        },
        "params": _params_json(project.params, arrays),
    }
    manifest["strokes"] = write_columns(project.strokes, arrays)  # (hairtool.frozen.sample_columns)
    manifest["strokes"]["aligned"] = project.aligned is not None
    if "brushes" not in manifest["strokes"]:
        manifest["version"] = 1  # align strokes only: readable by the hairtool before brushes
    elif "selection" not in manifest["strokes"] and "only_selected" not in manifest["strokes"]:
        manifest["version"] = 2  # readable by the hairtool before the selection
    if project.aligned is not None:
        if project.aligned.topology != project.rest.topology:
            raise GroomError("the aligned state must have the rest groom's strands")
        arrays["strokes/aligned.npy"] = project.aligned.points
    if project.animation is not None:
        info = _groom_arrays("animation", project.animation, arrays)
        manifest["animation"] = {"fps": project.animation.fps, "source": project.animation_source, **info}
    else:
        manifest["animation"] = None
    for name in ("brush", "display", "key_settings", "settings"):
        manifest[name] = _json_object(name, getattr(project, name))
    manifest["mesh"] = _mesh_arrays(project.mesh, arrays)
    manifest["children"] = _children_arrays(project, arrays)
    if manifest["children"] is not None:
        manifest["version"] = max(manifest["version"], 2)  # render hair an older hairtool would drop unseen
    manifest["arrays"] = sorted(arrays)
    return manifest, arrays


def _mesh_arrays(mesh: Mesh | None, arrays: dict[str, np.ndarray]) -> dict | None:
    """The head mesh: vertices, triangles, normals and one array of triangles per face set."""
    if mesh is None:
        return None
    arrays["mesh/vertices.npy"] = np.ascontiguousarray(mesh.vertices, np.float32)
    arrays["mesh/faces.npy"] = np.ascontiguousarray(mesh.faces, np.int32)
    arrays["mesh/normals.npy"] = np.ascontiguousarray(mesh.normals, np.float32)
    names = list(mesh.groups)
    for i, name in enumerate(names):
        arrays[f"mesh/group_{i}.npy"] = np.asarray(mesh.groups[name], np.int64)
    return {"groups": names}


# The child definition's arrays: (name, per vertex or per child, trailing shape, kinds, required).
_CHILD_ARRAYS = (
    ("counts", "child", (), "iu", True),
    ("roots", "child", (3,), "f", False),  # (a dense groom's: its strands' first points)
    ("guide_ids", "child", (-1,), "iu", True),
    ("weights", "child", (-1,), "f", True),
    ("scale", "child", (), "f", True),
    ("local", "vertex", (3,), "f", False),
    ("faces", "child", (), "iu", False),
    ("exact_points", "vertex", (3,), "f", False),
    ("exact_blend", "vertex", (3,), "f", False),
    ("frizz_phase", "child", (), "f", False),
    ("frizz_turns", "child", (), "f", False),
)


def _children_arrays(project: Project, arrays: dict[str, np.ndarray]) -> dict | None:
    b = project.children
    if b is None:
        return None
    if b.rest_guides.topology != project.rest.topology or not np.array_equal(
        b.rest_guides.points, project.rest.points
    ):
        raise GroomError("the children must be bound to the project's rest groom (their guides)")
    stored = []
    derived = ()  # arrays that follow from the others, made again on loading:
    if b.exact_points is not None:
        derived = ("roots", "local", "exact_blend")  # a dense groom's, from its points
    elif b.frizz_phase is not None:
        derived = ("local",)  # the frizz, from a few numbers per child
    for name, *_ in _CHILD_ARRAYS:
        value = getattr(b, name)
        if value is not None and name not in derived:
            if name in ("counts", "guide_ids", "faces"):
                value = _narrow(value)
            arrays[f"children/{name}.npy"] = np.ascontiguousarray(value)
            stored.append(name)
    info: dict[str, Any] = {"count": b.child_count, "arrays": stored}
    if b.frizz_phase is not None:
        info["frizz"] = b.frizz
    return info


def _narrow(a: np.ndarray) -> np.ndarray:
    """Whole numbers ≥ 0 in the smallest unsigned type that holds them (read back as int64)."""
    top = int(a.max(initial=0))
    return a.astype(np.uint16 if top < 2**16 else np.uint32 if top < 2**32 else np.uint64)


def save(path: str | os.PathLike[str], project: Project, *, compress: bool = False) -> None:
    """Write ``project`` to ``path`` atomically (temporary file, then rename).

    ``compress``: deflate the arrays too. Off by default: float coordinates barely compress
    (8 % on a 2,000-strand groom with a 44-frame animation) while deflating made the save
    about 9× slower (1.4 s against 0.16 s). On any error the previous file is untouched.

    Parameters
    ----------
    path
        The ``.hairproj`` file to write.
    project
        The document: groom, strokes, settings, animation, render hair, head mesh, camera.
    compress
        Deflate the array members as well as the manifest.

    Raises
    ------
    FormatError
        The settings are not plain JSON, or the file cannot be written; the message names it.
    """
    manifest, arrays = manifest_and_arrays(project)
    text = _manifest_text(path, manifest)
    try:
        with atomic_open(path, "wb") as f:
            _write_archive(f, text, arrays, compress)
    except OSError as e:
        raise FormatError(path, f"cannot write: {e}") from None


def to_bytes(project: Project, *, compress: bool = False) -> bytes:
    """The archive :func:`save` writes, in memory (a round trip through :func:`from_bytes` runs
    the file's whole schema without the disk: the document's state-machine test checks every
    step so).

    Parameters
    ----------
    project
        The document.
    compress
        Deflate the array members as well as the manifest.

    Returns
    -------
    bytes
        The ``.hairproj`` file's bytes.

    Raises
    ------
    FormatError
        The settings are not plain JSON.
    """
    manifest, arrays = manifest_and_arrays(project)
    buffer = io.BytesIO()
    _write_archive(buffer, _manifest_text("<memory>", manifest), arrays, compress)
    return buffer.getvalue()


def _manifest_text(path: str | os.PathLike[str], manifest: dict) -> str:
    try:
        return json.dumps(manifest, indent=1, allow_nan=False)
    except (TypeError, ValueError) as e:
        raise FormatError(path, f"the settings are not plain JSON: {e}") from None


def _write_archive(f, text: str, arrays: dict[str, np.ndarray], compress: bool) -> None:
    """The zip archive into the open binary file ``f``: the manifest, then each array."""
    method = zipfile.ZIP_DEFLATED if compress else zipfile.ZIP_STORED
    with zipfile.ZipFile(f, "w", method, compresslevel=1) as zf:
        zf.writestr(MANIFEST, text, compress_type=zipfile.ZIP_DEFLATED)
        for name, array in arrays.items():
            info = zipfile.ZipInfo(name, date_time=time.localtime()[:6])
            info.compress_type = method
            with zf.open(info, "w", force_zip64=array.nbytes > 2**31) as member:
                np.lib.format.write_array(member, np.ascontiguousarray(array), allow_pickle=False)


# -- reading ---------------------------------------------------------------------------------
class _Reader:
    """Checked access to the members of one project archive."""

    def __init__(self, path: Path, zf: zipfile.ZipFile, file_size: int) -> None:
        self.path, self.zf = path, zf
        infos = zf.infolist()
        names = [i.filename for i in infos]
        if len(set(names)) != len(names):
            raise FormatError(path, "the archive names a member twice")
        self.infos = {i.filename: i for i in infos}
        for info in infos:
            if info.compress_size > file_size:
                raise FormatError(path, f"member {info.filename!r} claims more bytes than the file has")
            limit = (
                info.compress_size
                if info.compress_type == zipfile.ZIP_STORED
                else _MAX_DEFLATE_RATIO * info.compress_size + 1024
            )
            if info.file_size > limit:
                raise FormatError(path, f"member {info.filename!r} claims an impossible size")

    def manifest(self) -> dict:
        info = self.infos.get(MANIFEST)
        if info is None:
            raise FormatError(self.path, "not a hairtool project (no manifest.json)")
        if info.file_size > MAX_MANIFEST_BYTES:
            raise FormatError(self.path, "manifest.json is too large")
        text = self.zf.read(MANIFEST).decode("utf-8")
        manifest = user_text.parse(
            self.path, text, "json", "a project's manifest.json", texts=EMBEDDED_TEXTS
        )  # all text limits
        if not isinstance(manifest, dict) or manifest.get("format") != FORMAT:
            raise FormatError(self.path, "not a hairtool project (manifest has no project format)")
        version = manifest.get("version")
        if version not in READABLE_VERSIONS:
            raise FormatError(
                self.path, f"project format version {version!r}; this hairtool reads versions 1, 2 and 3"
            )
        listed = manifest.get("arrays")
        if not isinstance(listed, list) or not all(isinstance(n, str) for n in listed):
            raise FormatError(self.path, "manifest.json has no list of arrays")
        extra = set(self.infos) - set(listed) - {MANIFEST}
        if extra:
            raise FormatError(self.path, f"unexpected member {sorted(extra)[0]!r}")
        self.listed = set(listed)
        return manifest

    def array(self, name: str, ndim: int, kinds: str) -> np.ndarray:
        if name not in self.listed or name not in self.infos:
            raise FormatError(self.path, f"missing member {name!r}")
        info = self.infos[name]
        with self.zf.open(info) as f:
            shape, fortran, dtype = read_npy_header(self.path, f, name)
            nbytes = math.prod(shape) * dtype.itemsize
            if f.tell() + nbytes != info.file_size:
                raise FormatError(self.path, f"member {name!r}: shape {shape} does not match its stored size")
            if len(shape) != ndim or dtype.kind not in kinds:
                raise FormatError(
                    self.path, f"member {name!r} must be {ndim}-D of kind {kinds!r}, got {dtype} {shape}"
                )
            data = f.read(nbytes)
            if len(data) != nbytes or f.read(1):  # the last read also checks the member's CRC
                raise FormatError(self.path, f"member {name!r} is truncated")
        order = "F" if fortran else "C"
        return np.frombuffer(data, dtype=dtype).reshape(shape, order=order)


def _section(path: Path, manifest: dict, name: str, kind: type) -> Any:
    value = manifest.get(name)
    if not isinstance(value, kind):
        raise FormatError(path, f"manifest.json: {name!r} must be a JSON {kind.__name__}")
    return value


def _read_groom(r: _Reader, prefix: str, info: dict, frames_fps: float | None = None) -> Groom | Animation:
    raw_counts = r.array(f"{prefix}/counts.npy", 1, "iu")
    v = require_strand_counts(r.path, raw_counts)  # bounded before the cast and the sum
    counts = raw_counts.astype(np.int64)
    attrs: dict[str, np.ndarray] = {}
    names = info.get("attributes", [])
    if not isinstance(names, list) or not set(names) <= set(_ATTRIBUTES):
        raise FormatError(r.path, f"manifest.json: bad attribute list for {prefix}")
    for name in names:
        a = r.array(f"{prefix}/{name}.npy", 2 if name == "colors" else 1, "f")
        want = (v, 3) if name == "colors" else (v,)
        if a.shape != want:
            raise FormatError(r.path, f"{prefix} {name} has shape {a.shape}, expected {want}")
        attrs[name] = float32_finite(r.path, a, f"{prefix} {name}")
    if frames_fps is None:
        meta = _read_scene(r, prefix, info, counts.size, None)
        points = r.array(f"{prefix}/points.npy", 2, "f")
        if points.shape != (v, 3):
            raise FormatError(r.path, f"{prefix} points have shape {points.shape}, expected {(v, 3)}")
        return Groom(float32_finite(r.path, points, f"{prefix} points"), counts, **attrs, metadata=meta)
    frames = r.array(f"{prefix}/frames.npy", 3, "f")
    if frames.shape[0] < 1 or frames.shape[1:] != (v, 3):
        raise FormatError(r.path, f"animation frames have shape {frames.shape}, expected (F≥1, {v}, 3)")
    meta = _read_scene(r, prefix, info, counts.size, frames.shape[0])
    frames = float32_finite(r.path, frames, "animation frames")
    return Animation(frames, counts, frames_fps, **attrs, metadata=meta)


def _read_scene(r: _Reader, prefix: str, info: dict, strand_count: int, frames: int | None) -> Metadata:
    """The groom's scene description (Y-up centimetres for a project saved before it was kept)."""
    if "scene" not in info:
        return Metadata()
    try:
        meta = from_record(info["scene"])
    except (ParameterError, TypeError, ValueError, OverflowError) as e:
        raise FormatError(r.path, f"manifest.json: {prefix} scene: {e}") from None
    held = sum(c.strands for c in meta.curves)
    if meta.curves and held != strand_count:
        raise FormatError(
            r.path, f"manifest.json: {prefix} scene prims hold {held} strands, not {strand_count}"
        )
    codes = meta.time_codes
    if codes is not None and (frames is None or len(codes) != frames):
        raise FormatError(
            r.path, f"manifest.json: {prefix} scene has {len(codes)} time codes for {frames} frames"
        )
    return meta


def _read_params(r: _Reader, raw: dict) -> FrozenParams:
    unknown = set(raw) - set(_PARAM_FIELDS)
    if unknown:
        raise FormatError(r.path, f"unknown engine parameter {sorted(unknown)[0]!r}")
    values = dict(raw)
    for name, value in values.items():  # numbers, flags and names, as save() writes them
        if not (value is None or isinstance(value, bool | int | float | str)) and name != "strand_variation":
            raise FormatError(r.path, f"engine parameter {name!r} is a JSON {type(value).__name__}")
    sv = values.get("strand_variation")
    if isinstance(sv, dict):
        values["strand_variation"] = r.array(sv.get("array", ""), 1, "f").astype(np.float64)
    elif isinstance(sv, bool) or not isinstance(sv, int | float | None):
        raise FormatError(r.path, 'strand_variation must be a number or {"array": member}')
    try:
        return FrozenParams(**values).validate()
    except (HairtoolError, TypeError, ValueError) as e:
        raise FormatError(r.path, f"engine parameters: {e}") from None


def _read_strokes(r: _Reader, info: dict, rest: Groom) -> tuple[tuple, Groom | None]:
    try:
        samples = read_columns(info, r.array)
    except ColumnError as e:
        raise FormatError(r.path, str(e)) from None
    strokes = []
    for k, s in enumerate(samples):
        try:
            if isinstance(s, BrushSample):
                s = check_sample(s)
            elif isinstance(s, SelectionSample):
                s = check_selection(s)
            else:
                s = s._replace(
                    view=check_view(s.view), pressure=check_pressure(s.pressure), eye=check_eye(s.eye)
                )
        except HairtoolError as e:
            raise FormatError(r.path, f"stroke {k}: {e}") from None
        strokes.append(s)
    strokes = tuple(strokes)
    aligned = None
    if info.get("aligned"):
        pts = r.array("strokes/aligned.npy", 2, "f")
        if pts.shape != rest.points.shape:
            raise FormatError(r.path, f"aligned points have shape {pts.shape}, expected {rest.points.shape}")
        aligned = rest.with_points(float32_finite(r.path, pts, "aligned points"))
    return strokes, aligned


def _read_mesh(r: _Reader, info: Any) -> Mesh | None:
    """The head mesh, its faces checked against its vertices."""
    if info is None:
        return None
    names = info.get("groups") if isinstance(info, dict) else None
    if not isinstance(names, list) or not all(isinstance(n, str) for n in names):
        raise FormatError(r.path, "manifest.json: bad 'mesh' section")
    vertices = float32_finite(r.path, r.array("mesh/vertices.npy", 2, "f"), "mesh vertices")
    faces = r.array("mesh/faces.npy", 2, "iu")
    normals = float32_finite(r.path, r.array("mesh/normals.npy", 2, "f"), "mesh normals")
    n = len(vertices)
    if vertices.shape[1:] != (3,) or normals.shape != vertices.shape or faces.shape[1:] != (3,):
        raise FormatError(r.path, "the mesh arrays must be (n, 3) vertices and normals and (m, 3) faces")
    if n > np.iinfo(np.int32).max or (faces.size and (faces.min() < 0 or faces.max() >= n)):
        raise FormatError(r.path, f"a mesh face names a vertex outside [0, {n})")
    groups = {}
    for i, name in enumerate(names):
        ids = r.array(f"mesh/group_{i}.npy", 1, "iu").astype(np.int64)
        if ids.size and (ids.min() < 0 or ids.max() >= len(faces)):
            raise FormatError(r.path, f"mesh face set {name!r} names a triangle outside [0, {len(faces)})")
        groups[name] = ids
    return Mesh(vertices, faces.astype(np.int32), normals, groups)


def _read_children(r: _Reader, info: Any, rest: Groom) -> ChildBinding | None:
    """The child definition, every array checked against the others and the guides."""
    if info is None:
        return None
    stored = info.get("arrays") if isinstance(info, dict) else None
    if not isinstance(stored, list) or not set(stored) <= {a[0] for a in _CHILD_ARRAYS}:
        raise FormatError(r.path, "manifest.json: bad 'children' section")
    raw_counts = r.array("children/counts.npy", 1, "iu")
    v = require_strand_counts(r.path, raw_counts)
    n = len(raw_counts)
    values: dict[str, np.ndarray | None] = {"counts": raw_counts.astype(np.int64)}
    k = None
    for name, per, tail, kinds, required in _CHILD_ARRAYS[1:]:
        if name not in stored:
            if required:
                raise FormatError(r.path, f"missing member 'children/{name}.npy'")
            values[name] = None
            continue
        a = r.array(f"children/{name}.npy", 1 + len(tail), kinds)
        if tail == (-1,):
            k = a.shape[1] if k is None else k
            tail = (k,)
        want = ((n if per == "child" else v), *tail)
        if a.shape != want or (tail and tail[0] == 0):
            raise FormatError(r.path, f"children {name} has shape {a.shape}, expected {want}")
        if kinds == "f":
            require_finite(r.path, a, f"children {name}")
        values[name] = a
    ids = values["guide_ids"]
    if ids.size and (ids.min() < 0 or ids.max() >= rest.strand_count):
        raise FormatError(r.path, f"a child names a guide outside [0, {rest.strand_count})")
    faces = values["faces"]
    if values["roots"] is None:
        if values["exact_points"] is None:
            raise FormatError(r.path, "missing member 'children/roots.npy'")
        starts = np.concatenate([[0], np.cumsum(values["counts"])[:-1]])
        values["roots"] = values["exact_points"][starts]  # a dense groom's strands start at its roots
    b = ChildBinding(
        rest,
        values["counts"],
        values["roots"].astype(np.float64),
        ids.astype(np.int64),
        values["weights"].astype(np.float64),
        values["scale"].astype(np.float64),
        None if values["local"] is None else values["local"].astype(np.float32),
        None if faces is None else faces.astype(np.int64),
        None if values["exact_points"] is None else values["exact_points"].astype(np.float32),
        None if values["exact_blend"] is None else values["exact_blend"].astype(np.float64),
    )
    if b.exact_points is not None and (b.local is None or b.exact_blend is None):
        bind_exactly(b, b.exact_points)  # a dense groom's points: its offsets follow from them
    elif b.local is None and values["frizz_phase"] is not None:
        _curl_again(r, info, b, values)
    return b


def _curl_again(r: _Reader, info: dict, b: ChildBinding, values: dict) -> None:
    """The children's frizz offsets from its recipe (amplitude, and each child's phase and turns)."""
    frizz = info.get("frizz")
    if isinstance(frizz, bool) or not isinstance(frizz, (int, float)) or not 0 < frizz <= MAX_FRIZZ:
        raise FormatError(r.path, f"manifest.json: children 'frizz' must be a number in (0, {MAX_FRIZZ}]")
    if values["frizz_turns"] is None:
        raise FormatError(r.path, "missing member 'children/frizz_turns.npy'")
    if b.child_count and np.any(b.counts != b.counts[0]):
        raise FormatError(r.path, "frizzed children must have one vertex count")
    b.frizz = float(frizz)
    b.frizz_phase = values["frizz_phase"].astype(np.float64)
    b.frizz_turns = values["frizz_turns"].astype(np.float64)
    curl(b)


def _build(r: _Reader) -> Project:
    manifest = r.manifest()
    path = r.path
    groom_info = _section(path, manifest, "groom", dict)
    rest = _read_groom(r, "groom", groom_info)
    source = groom_info.get("source")
    params = _read_params(r, _section(path, manifest, "params", dict))
    sv = params.strand_variation
    if np.ndim(sv) != 0 and np.shape(sv) != (rest.strand_count,):
        raise FormatError(path, f"strand_variation has {np.size(sv)} values for {rest.strand_count} strands")
    strokes, aligned = _read_strokes(r, _section(path, manifest, "strokes", dict), rest)
    animation, anim_source = None, ""
    anim_info = manifest.get("animation")
    if anim_info is not None:
        if not isinstance(anim_info, dict):
            raise FormatError(path, "manifest.json: 'animation' must be an object or null")
        fps = anim_info.get("fps")
        if not isinstance(fps, (int, float)) or isinstance(fps, bool) or not (math.isfinite(fps) and fps > 0):
            raise FormatError(path, f"animation fps is {fps!r}; expected a positive number")
        animation = _read_groom(r, "animation", anim_info, float(fps))
        anim_source = str(anim_info.get("source") or "")
    return Project(
        rest=rest,
        params=params,
        strokes=strokes,
        aligned=aligned,
        brush=_section(path, manifest, "brush", dict),
        display=_section(path, manifest, "display", dict),
        animation=animation,
        animation_source=anim_source,
        key_settings=_section(path, manifest, "key_settings", dict),
        settings=_section(path, manifest, "settings", dict),
        groom_source=source if isinstance(source, str) else None,
        children=_read_children(r, manifest.get("children"), rest),
        mesh=_read_mesh(r, manifest.get("mesh")),
    )


def load(path: str | os.PathLike[str]) -> Project:
    """Read a project; :class:`FormatError` naming the file for anything but a valid project.

    Parameters
    ----------
    path
        A ``.hairproj`` file of version 1 to 3.

    Returns
    -------
    Project
        The document as it was saved; render hair is bound again from its definition.

    Raises
    ------
    FormatError
        The file is missing, truncated, corrupt, foreign or of a newer version; every member's
        size and checksum is checked before it is trusted.
    """
    p = Path(path)
    if not p.is_file():
        raise FormatError(path, "no such file" if not p.exists() else "not a regular file")
    return from_bytes(user_text.read_bytes(path, "a hairtool project", max_bytes=None), path)


def from_bytes(data: bytes, where: str | os.PathLike[str]) -> Project:
    """:func:`load` of a file's bytes held in memory (from :func:`to_bytes`, or read elsewhere).

    Parameters
    ----------
    data
        The ``.hairproj`` file's bytes.
    where
        The file or place they come from, named in a refusal.

    Returns
    -------
    Project
        The document as it was saved; render hair is bound again from its definition.

    Raises
    ------
    FormatError
        The bytes are not a valid project (as :func:`load`); the message names ``where``.
    """
    path, p = where, Path(where)
    if not data:
        raise FormatError(path, "the file is empty")
    if not zipfile.is_zipfile(io.BytesIO(data)):
        raise FormatError(path, "not a hairtool project (not a zip archive; truncated?)")
    try:
        with zipfile.ZipFile(io.BytesIO(data)) as zf:
            return _build(_Reader(p, zf, len(data)))
    except FormatError:
        raise
    except _READ_ERRORS as e:
        raise FormatError(path, f"not a readable project ({type(e).__name__}: {e})") from None
    except MemoryError:
        raise FormatError(path, "too large to read into memory") from None
