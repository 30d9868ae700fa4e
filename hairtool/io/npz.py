"""hairtool's own cache (``.npz``): a groom or an animation with its attributes, lossless.

Members (every one a plain, non-object array, so the file loads with ``allow_pickle=False``):
``format_version`` int64 scalar, ``kind`` ``"groom"`` or ``"animation"``, ``counts`` int64 (S,),
``points`` float32 (V, 3) for a groom or ``frames`` float32 (F, V, 3) for an animation, ``fps``
float64 scalar and ``time_codes`` float64 (F,) (animations: the source's time code of each frame;
caches written before it existed read as 0…F−1), optional ``thickness`` (V,),
``transparency`` (V,), ``colors`` (V, 3) float32, ``curves``, a unicode scalar holding the
source's curve prims as JSON (path, strands, basis, wrap, purpose and the attributes it lacks of
each, in strand order), so render hair and its guides (purpose ``guide``) stay apart through a
cache, and ``metadata``, a unicode scalar of JSON with the rest of the scene description
(``up_axis``, ``meters_per_unit``, ``time_codes_per_second``, ``start_time_code``,
``end_time_code``, ``color_primvar``, and ``xforms``, the static transforms of the prims and
their ancestors, when the source had any): USD → npz → USD gives back the same stage. Caches
without it read as Y-up centimetres.
"""

from __future__ import annotations

import ast
import functools
import io
import json
import os
import struct
import zipfile
import zlib
from pathlib import Path

import numpy as np

from hairtool import budget
from hairtool.errors import FormatError, ParameterError
from hairtool.groom import Animation, Groom
from hairtool.io.atomic import atomic_open
from hairtool.io.binary import float32_finite, require_strand_counts
from hairtool.metadata import CurvesPrim, Metadata

FORMAT_VERSION = 1
ATTRIBUTES = ("thickness", "transparency", "colors")
_KNOWN = {
    "format_version", "kind", "counts", "points", "frames", "fps", "time_codes", "curves", "metadata",
    *ATTRIBUTES,
}  # fmt: skip
_PRIM_FIELDS = ("path", "strands", "basis", "wrap", "purpose")  # each prim has these …
_PRIM_OPTIONAL = ("lacks",)  # … and may have these
_SCENE_FIELDS = (
    "up_axis", "meters_per_unit", "time_codes_per_second", "start_time_code", "end_time_code", "color_primvar"
)  # fmt: skip
_MAX_JSON = 1 << 20  # characters of a JSON member: far more than any scene needs
# zlib's deflate never expands data more than about 1032:1; a member claiming more is corrupt.
_MAX_DEFLATE_RATIO = 1100
_MAX_NPY_HEADER = 10_000  # numpy's own limit on a header's length (max_header_size)

_LOAD_ERRORS = (
    ValueError,
    OSError,
    EOFError,
    KeyError,
    zipfile.BadZipFile,
    zlib.error,
    struct.error,
    UnicodeDecodeError,
    NotImplementedError,
    RuntimeError,
)


def write(path: Path, obj: Groom | Animation) -> None:
    """Write a groom or an animation as hairtool's ``.npz`` cache (points, counts, attributes, record).

    Parameters
    ----------
    path : Path
        The file, written atomically.
    obj : Groom or Animation
        What to write.
    """
    arrays: dict[str, np.ndarray] = {
        "format_version": np.array(FORMAT_VERSION, dtype=np.int64),
        "counts": np.asarray(obj.counts, dtype=np.int64),
    }
    if isinstance(obj, Animation):
        arrays.update(kind=np.array("animation"), frames=obj.frames, fps=np.array(obj.fps, dtype=np.float64))
        arrays["time_codes"] = obj.time_codes
    else:
        arrays.update(kind=np.array("groom"), points=obj.points)
    for name, a in obj.attributes.items():
        if a is not None:
            arrays[name] = a
    prims = obj.metadata.for_strands(obj.strand_count).curves
    if prims:
        fields = _PRIM_FIELDS + _PRIM_OPTIONAL
        items = [
            {f: (list(v) if isinstance(v := getattr(c, f), tuple) else v) for f in fields} for c in prims
        ]
        arrays["curves"] = np.array(json.dumps(items))
    scene = {f: getattr(obj.metadata, f) for f in _SCENE_FIELDS}
    if obj.metadata.xforms:
        scene["xforms"] = [[path, list(m)] for path, m in obj.metadata.xforms]
    arrays["metadata"] = np.array(json.dumps(scene))
    with atomic_open(path, "wb") as f:
        np.savez_compressed(f, **arrays)


#: A member's bytes are held about this many times while it is read: inflated, checked for
#: finite values, cast to the groom's float32.
_COPIES = 3


def _check_members(path: Path, zf: zipfile.ZipFile, file_size: int) -> None:
    """Bound every member's claimed shape by the bytes that can really back it, before numpy allocates."""
    for info in zf.infolist():
        name = info.filename
        if not name.endswith(".npy") or name[:-4] not in _KNOWN:
            raise FormatError(path, f"unexpected member {name!r}")
        _member_header(path, zf, info, file_size)


def _member_header(
    path: Path, zf: zipfile.ZipFile, info: zipfile.ZipInfo, file_size: int
) -> tuple[tuple[int, ...], np.dtype]:
    """The shape and dtype a ``.npy`` member claims, checked against the bytes stored for it."""
    name = info.filename
    if info.compress_size > file_size:
        raise FormatError(path, f"member {name!r} claims more bytes than the file has")
    limit = (
        info.compress_size
        if info.compress_type == zipfile.ZIP_STORED
        else (_MAX_DEFLATE_RATIO * info.compress_size + 1024)
    )
    if info.file_size > limit:
        raise FormatError(path, f"member {name!r} claims an impossible size")
    # Before it is inflated: a 778 KB file inflated 800 MB of frames, then peaked at 2.5 GB.
    budget.check_bytes(_COPIES * info.file_size, f"{path}: member {name!r} (inflated)")
    with zf.open(info) as f:
        shape, _fortran, dtype = read_npy_header(path, f, name)
        header_len = f.tell()
    nbytes = int(np.prod(shape, dtype=object)) * dtype.itemsize
    if header_len + nbytes != info.file_size:
        raise FormatError(path, f"member {name!r}: shape {shape} does not match its stored size")
    return shape, dtype


def read_npy_header(path: str | os.PathLike[str], f, name: str) -> tuple[tuple[int, ...], bool, np.dtype]:
    """``(shape, fortran_order, dtype)`` of the ``.npy`` member ``name`` open in ``f``, which is left
    at the first data byte; any corrupt header, or one holding Python objects, is a FormatError.

    The header's text is parsed here first: numpy falls back to a filter for Python 2 headers
    when its own parse fails, and that filter warns and lets ``tokenize.TokenError`` escape.

    Parameters
    ----------
    path : str or os.PathLike
        The archive, named in a refusal.
    f : file object
        The member, open at its start.
    name : str
        The member's name.

    Returns
    -------
    tuple of (tuple of int, bool, numpy.dtype)
        Its shape, whether it is Fortran-ordered, and its dtype.
    """
    magic = f.read(8)
    if len(magic) < 8 or magic[:6] != b"\x93NUMPY":
        raise FormatError(path, f"member {name!r} is not a .npy array")
    version = (magic[6], magic[7])
    if version not in ((1, 0), (2, 0), (3, 0)):
        raise FormatError(path, f"member {name!r} has .npy version {version}")
    size_bytes = f.read(2 if version == (1, 0) else 4)
    header_len = int.from_bytes(size_bytes, "little")
    if len(size_bytes) < (2 if version == (1, 0) else 4) or header_len > _MAX_NPY_HEADER:
        raise FormatError(path, f"member {name!r} has a corrupt .npy header")
    try:
        shape, fortran, dtype = _parsed_header(magic + size_bytes + f.read(header_len))
    except _CorruptHeader:
        raise FormatError(path, f"member {name!r} has a corrupt .npy header") from None
    if dtype.hasobject:
        raise FormatError(path, f"member {name!r} holds Python objects")
    return shape, fortran, dtype


class _CorruptHeader(Exception):
    """A header whose text is no Python literal (or not in its encoding)."""


@functools.lru_cache(maxsize=256)
def _parsed_header(head: bytes) -> tuple[tuple[int, ...], bool, np.dtype]:
    """``(shape, fortran_order, dtype)`` of a whole ``.npy`` header (magic to its last byte),
    parsed once per distinct header: a project's members and a state's saves repeat a few
    headers many times, and each parse is two ``literal_eval`` (ours first, then numpy's).
    Numpy's own errors pass through; a refused header is parsed again when met again."""
    version = (head[6], head[7])
    try:
        text = head[10 if version == (1, 0) else 12 :].decode("utf-8" if version == (3, 0) else "latin-1")
        ast.literal_eval(text)
    except (SyntaxError, ValueError, UnicodeDecodeError, MemoryError, RecursionError):
        raise _CorruptHeader from None
    f = io.BytesIO(head)
    if np.lib.format.read_magic(f) == (1, 0):
        return np.lib.format.read_array_header_1_0(f)
    return np.lib.format.read_array_header_2_0(f)


def _member(path: Path, z, name: str) -> np.ndarray:
    if name not in z.files:
        raise FormatError(path, f"missing {name!r}")
    return z[name]


def _scalar(path: Path, z, name: str, kind: str) -> object:
    a = _member(path, z, name)
    if a.shape != () or a.dtype.kind not in kind:
        raise FormatError(path, f"{name!r} must be a scalar of kind {kind!r}, got {a.dtype} {a.shape}")
    if a.dtype.kind == "U" and a.dtype.itemsize:
        # Code points past U+10FFFF (or surrogates) make a str that breaks whoever reads it.
        codes = np.ascontiguousarray(a.astype(a.dtype.newbyteorder("="))).reshape(1).view(np.uint32)
        if codes.max() > 0x10FFFF or np.any((codes >= 0xD800) & (codes <= 0xDFFF)):
            raise FormatError(path, f"{name!r} holds characters that are not text")
    return a.item()


def _array(path: Path, z, name: str, ndim: int, kind: str) -> np.ndarray:
    a = _member(path, z, name)
    if a.ndim != ndim or a.dtype.kind not in kind:
        raise FormatError(
            path, f"{name!r} must be a {ndim}-D array of kind {kind!r}, got {a.dtype} {a.shape}"
        )
    return a


def _time_codes(path: Path, z, n_frames: int) -> tuple[float, ...] | None:
    if "time_codes" not in z.files:
        return None
    t = _array(path, z, "time_codes", 1, "fiu").astype(np.float64)
    if t.shape != (n_frames,) or not np.all(np.isfinite(t)) or np.any(np.diff(t) <= 0):
        raise FormatError(path, f"'time_codes' must be {n_frames} finite, strictly increasing numbers")
    return tuple(t.tolist())


def _json(path: Path, z, name: str):
    """A JSON member, bounded in size and nesting before it is parsed."""
    text = _scalar(path, z, name, "U")
    if len(text) > _MAX_JSON:
        raise FormatError(path, f"{name!r} holds {len(text)} characters; at most {_MAX_JSON}")
    depth = 0
    for ch in text:  # a flat record: nothing nests deeper than a list in an object in a list
        depth += ch in "[{"
        depth -= ch in "]}"
        if depth > 4:
            raise FormatError(path, f"{name!r} nests deeper than a scene record does")
    try:
        return json.loads(text)
    except (ValueError, RecursionError) as e:
        raise FormatError(path, f"{name!r} is not JSON: {e}") from None


def _curves(path: Path, z, strand_count: int) -> tuple[CurvesPrim, ...]:
    if "curves" not in z.files:
        return ()
    items = _json(path, z, "curves")
    try:
        if not isinstance(items, list) or not items:
            raise ValueError("not a list of prims")
        prims = []
        for item in items:
            if not isinstance(item, dict) or not set(_PRIM_FIELDS) <= set(item) <= set(
                _PRIM_FIELDS + _PRIM_OPTIONAL
            ):
                raise ValueError(f"each prim has exactly {', '.join(_PRIM_FIELDS)} (and optionally lacks)")
            if "lacks" in item and not isinstance(item["lacks"], list):
                raise ValueError("lacks is a list of attribute names")
            prims.append(CurvesPrim(**{k: (tuple(v) if k == "lacks" else v) for k, v in item.items()}))
    except (ValueError, TypeError, ParameterError) as e:
        raise FormatError(path, f"'curves' is not a list of curve prims: {e}") from None
    if sum(c.strands for c in prims) != strand_count:
        raise FormatError(path, f"'curves' hold {sum(c.strands for c in prims)} strands, not {strand_count}")
    return tuple(prims)


def _scene(path: Path, z, strand_count: int) -> Metadata:
    """The cache's scene description (defaults for a cache written before it was kept)."""
    curves = _curves(path, z, strand_count)
    if "metadata" not in z.files:
        return Metadata(curves=curves)
    record = _json(path, z, "metadata")
    try:
        if not isinstance(record, dict) or not set(_SCENE_FIELDS) <= set(record) <= {
            *_SCENE_FIELDS,
            "xforms",
        }:
            raise ValueError(f"it has exactly {', '.join(_SCENE_FIELDS)} (and optionally xforms)")
        record = dict(record)
        xforms = record.pop("xforms", [])
        if not isinstance(xforms, list) or not all(
            isinstance(x, list) and len(x) == 2 and isinstance(x[1], list) and len(x[1]) == 16 for x in xforms
        ):
            raise ValueError("xforms is a list of [prim path, 16 numbers]")
        if any(isinstance(v, bool) or not isinstance(v, (int, float)) for x in xforms for v in x[1]):
            raise ValueError("a transform holds numbers")
        for key in ("meters_per_unit", "time_codes_per_second", "start_time_code", "end_time_code"):
            v = record[key]
            if v is not None and (isinstance(v, bool) or not isinstance(v, (int, float))):
                raise ValueError(f"{key} is a number or null")
        for key in ("up_axis", "color_primvar"):
            if not isinstance(record[key], str):
                raise ValueError(f"{key} is a string")
        return Metadata(**record, curves=curves, xforms=tuple((x[0], tuple(x[1])) for x in xforms))
    except (ValueError, TypeError, OverflowError, ParameterError) as e:
        raise FormatError(path, f"'metadata' is not a scene description: {e}") from None


def _load_zip(path: Path, fh, single_npy: str):
    """numpy's lazy view of the zip archive open in ``fh``; anything else is refused before
    numpy reads it (a lone ``.npy`` would be read whole, whatever size its header claims)."""
    magic = fh.read(4)
    fh.seek(0)
    if magic.startswith(b"\x93NUM"):
        raise FormatError(path, single_npy)
    if magic not in (b"PK\x03\x04", b"PK\x05\x06"):
        raise FormatError(path, "not an .npz file (not a zip archive)")
    return np.load(fh, allow_pickle=False)


def read(path: Path) -> Groom | Animation:
    """Read hairtool's ``.npz`` cache, every member's size checked against the bytes stored and
    the budget before it is inflated.

    Parameters
    ----------
    path : Path
        The file.

    Returns
    -------
    Groom or Animation
        An Animation where the file holds frames.
    """
    size = path.stat().st_size
    if size == 0:
        raise FormatError(path, "the file is empty")
    try:
        # numpy leaves a file it opened itself open when the zip is corrupt: open it here.
        with open(path, "rb") as fh:
            z = _load_zip(path, fh, "a single .npy array, not a hairtool .npz cache")
            with z:
                _check_members(path, z.zip, size)
                return _build(path, z)
    except FormatError:
        raise
    except _LOAD_ERRORS as e:
        raise FormatError(path, f"not a readable .npz cache ({type(e).__name__}: {e})") from None


def _build(path: Path, z) -> Groom | Animation:
    version = _scalar(path, z, "format_version", "iu")
    if version != FORMAT_VERSION:
        raise FormatError(path, f"cache format version {version}; this hairtool reads {FORMAT_VERSION}")
    kind = _scalar(path, z, "kind", "U")
    raw_counts = _array(path, z, "counts", 1, "iu")
    v_count = require_strand_counts(path, raw_counts)  # bounded before the cast and the sum
    counts = raw_counts.astype(np.int64)
    attrs: dict[str, np.ndarray] = {}
    for name in ATTRIBUTES:
        if name in z.files:
            a = _array(path, z, name, 2 if name == "colors" else 1, "f")
            want = (v_count, 3) if name == "colors" else (v_count,)
            if a.shape != want:
                raise FormatError(path, f"{name!r} has shape {a.shape}, expected {want}")
            attrs[name] = float32_finite(path, a, name)
    if kind == "groom":
        points = _array(path, z, "points", 2, "f")
        if points.shape != (v_count, 3):
            raise FormatError(path, f"'points' has shape {points.shape}, expected {(v_count, 3)}")
        meta = _scene(path, z, counts.size)
        return Groom(float32_finite(path, points, "points"), counts, **attrs, metadata=meta)
    if kind == "animation":
        frames = _array(path, z, "frames", 3, "f")
        if frames.shape[0] < 1 or frames.shape[1:] != (v_count, 3):
            raise FormatError(path, f"'frames' has shape {frames.shape}, expected (F>=1, {v_count}, 3)")
        frames = float32_finite(path, frames, "frames")
        fps = float(_scalar(path, z, "fps", "fiu"))
        if not (np.isfinite(fps) and fps > 0):
            raise FormatError(path, f"fps is {fps}; expected a positive number")
        time_codes = _time_codes(path, z, frames.shape[0])
        meta = _scene(path, z, counts.size)
        if time_codes is not None:
            meta = meta.with_(time_codes=time_codes)
        return Animation(frames, counts, fps, **attrs, metadata=meta)
    raise FormatError(path, f"kind is {kind!r}; expected 'groom' or 'animation'")


# -- raw feature arrays (``hairtool keys IN.npz`` with an array X) ----------------------------
FEATURE_MEMBER = "X"
_FLOAT32_MAX = float(np.finfo(np.float32).max)


def _zip_names(path: Path) -> list[str]:
    try:
        with zipfile.ZipFile(path) as zf:
            return zf.namelist()
    except _LOAD_ERRORS as e:
        raise FormatError(path, f"not a readable .npz file ({type(e).__name__}: {e})") from None


def holds_feature_array(path: str | os.PathLike[str]) -> bool:
    """Whether an ``.npz`` holds a raw feature array ``X`` rather than a hairtool cache (False for
    anything that is not a zip archive: :func:`read` says what is wrong with it).

    Parameters
    ----------
    path : str or os.PathLike
        The file.

    Returns
    -------
    bool
        True where it holds ``X``.
    """
    p = Path(path)
    try:
        if not zipfile.is_zipfile(p):
            return False
    except OSError as e:
        raise FormatError(p, f"cannot read: {e}") from None
    names = _zip_names(p)
    return f"{FEATURE_MEMBER}.npy" in names and "kind.npy" not in names


def read_feature_array(path: str | os.PathLike[str]) -> np.ndarray:
    """The array ``X`` of an ``.npz`` as ``(frames, dims)`` float64, every frame a feature vector.

    Checked like a cache: the size its header claims against the bytes stored (before numpy
    allocates), a numeric dtype, the cast to float64 *then* finiteness and float32's range, at
    least 2 frames and 1 dimension. A 1-D ``X`` is one value per frame (one column). Other
    members are ignored.

    Parameters
    ----------
    path : str or os.PathLike
        The file.

    Returns
    -------
    ndarray
        ``(frames, dims)`` float64.
    """
    p = Path(path)
    size = p.stat().st_size
    if size == 0:
        raise FormatError(p, "the file is empty")
    member = f"{FEATURE_MEMBER}.npy"
    try:
        with open(p, "rb") as fh:
            z = _load_zip(p, fh, "a single .npy array; features are read from an .npz holding X")
            with z:
                if member not in z.zip.namelist():
                    raise FormatError(p, f"no array {FEATURE_MEMBER!r} in the file")
                shape, dtype = _member_header(p, z.zip, z.zip.getinfo(member), size)
                if dtype.kind not in "fiu":
                    raise FormatError(p, f"{FEATURE_MEMBER!r} must hold numbers, not {dtype}")
                if len(shape) not in (1, 2):
                    raise FormatError(p, f"{FEATURE_MEMBER!r} has shape {shape}; expected (frames, dims)")
                x = z[FEATURE_MEMBER]
    except FormatError:
        raise
    except _LOAD_ERRORS as e:
        raise FormatError(p, f"not a readable .npz file ({type(e).__name__}: {e})") from None
    if x.ndim == 1:
        x = x[:, None]
    if x.shape[0] < 2:
        raise FormatError(p, f"{FEATURE_MEMBER!r} has {x.shape[0]} frame(s); keyframes need at least 2")
    if x.shape[1] < 1:
        raise FormatError(p, f"{FEATURE_MEMBER!r} has no dimensions; expected (frames, dims >= 1)")
    with np.errstate(over="ignore", invalid="ignore"):
        out = np.ascontiguousarray(x, dtype=np.float64)  # cast, then check: a longdouble may overflow
    finite = np.isfinite(out).all(axis=1)
    if not finite.all():
        raise FormatError(p, f"{FEATURE_MEMBER!r} has a non-finite value in frame {int(np.argmin(finite))}")
    # As for every coordinate hairtool reads: beyond float32's range is corruption (and the key
    # solver's squared differences would overflow float64 from about 1.3e154 on).
    small = (np.abs(out) <= _FLOAT32_MAX).all(axis=1)
    if not small.all():
        frame = int(np.argmin(small))
        raise FormatError(p, f"{FEATURE_MEMBER!r} has a value beyond ±3.4e38 in frame {frame}")
    return out
