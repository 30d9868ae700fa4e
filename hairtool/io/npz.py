"""hairtool's own cache (``.npz``): a groom or an animation with its attributes, lossless.

Members (every one a plain, non-object array, so the file loads with ``allow_pickle=False``):
``format_version`` int64 scalar, ``kind`` ``"groom"`` or ``"animation"``, ``counts`` int64 (S,),
``points`` float32 (V, 3) for a groom or ``frames`` float32 (F, V, 3) for an animation, ``fps``
float64 scalar and ``time_codes`` float64 (F,) (animations: the source's time code of each frame;
caches written before it existed read as 0…F−1), and optional ``thickness`` (V,),
``transparency`` (V,), ``colors`` (V, 3) float32.
"""

from __future__ import annotations

import struct
import zipfile
import zlib
from pathlib import Path

import numpy as np

from hairtool.errors import FormatError
from hairtool.groom import Animation, Groom
from hairtool.io.atomic import atomic_open
from hairtool.io.binary import require_finite, require_strand_counts
from hairtool.metadata import Metadata

FORMAT_VERSION = 1
ATTRIBUTES = ("thickness", "transparency", "colors")
_KNOWN = {"format_version", "kind", "counts", "points", "frames", "fps", "time_codes", *ATTRIBUTES}
# zlib's deflate never expands data more than about 1032:1; a member claiming more is corrupt.
_MAX_DEFLATE_RATIO = 1100

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
    with atomic_open(path, "wb") as f:
        np.savez_compressed(f, **arrays)


def _check_members(path: Path, zf: zipfile.ZipFile, file_size: int) -> None:
    """Bound every member's claimed shape by the bytes that can really back it, before numpy allocates."""
    for info in zf.infolist():
        name = info.filename
        if not name.endswith(".npy") or name[:-4] not in _KNOWN:
            raise FormatError(path, f"unexpected member {name!r}")
        if info.compress_size > file_size:
            raise FormatError(path, f"member {name!r} claims more bytes than the file has")
        limit = (
            info.compress_size
            if info.compress_type == zipfile.ZIP_STORED
            else (_MAX_DEFLATE_RATIO * info.compress_size + 1024)
        )
        if info.file_size > limit:
            raise FormatError(path, f"member {name!r} claims an impossible size")
        with zf.open(info) as f:
            version = np.lib.format.read_magic(f)
            if version == (1, 0):
                shape, _fortran, dtype = np.lib.format.read_array_header_1_0(f)
            elif version in ((2, 0), (3, 0)):
                shape, _fortran, dtype = np.lib.format.read_array_header_2_0(f)
            else:
                raise FormatError(path, f"member {name!r} has .npy version {version}")
            header_len = f.tell()
        if dtype.hasobject:
            raise FormatError(path, f"member {name!r} holds Python objects")
        nbytes = int(np.prod(shape, dtype=object)) * dtype.itemsize
        if header_len + nbytes != info.file_size:
            raise FormatError(path, f"member {name!r}: shape {shape} does not match its stored size")


def _member(path: Path, z, name: str) -> np.ndarray:
    if name not in z.files:
        raise FormatError(path, f"missing {name!r}")
    return z[name]


def _scalar(path: Path, z, name: str, kind: str) -> object:
    a = _member(path, z, name)
    if a.shape != () or a.dtype.kind not in kind:
        raise FormatError(path, f"{name!r} must be a scalar of kind {kind!r}, got {a.dtype} {a.shape}")
    return a.item()


def _array(path: Path, z, name: str, ndim: int, kind: str) -> np.ndarray:
    a = _member(path, z, name)
    if a.ndim != ndim or a.dtype.kind not in kind:
        raise FormatError(
            path, f"{name!r} must be a {ndim}-D array of kind {kind!r}, got {a.dtype} {a.shape}"
        )
    return a


def _time_codes(path: Path, z, n_frames: int) -> Metadata | None:
    if "time_codes" not in z.files:
        return None
    t = _array(path, z, "time_codes", 1, "fiu").astype(np.float64)
    if t.shape != (n_frames,) or not np.all(np.isfinite(t)) or np.any(np.diff(t) <= 0):
        raise FormatError(path, f"'time_codes' must be {n_frames} finite, strictly increasing numbers")
    return Metadata(time_codes=tuple(t.tolist()))


def read(path: Path) -> Groom | Animation:
    size = path.stat().st_size
    if size == 0:
        raise FormatError(path, "the file is empty")
    try:
        with np.load(path, allow_pickle=False) as z:
            if not isinstance(z, np.lib.npyio.NpzFile):
                raise FormatError(path, "a single .npy array, not a hairtool .npz cache")
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
    counts = _array(path, z, "counts", 1, "iu").astype(np.int64)
    require_strand_counts(path, counts)
    v_count = int(counts.sum())
    attrs: dict[str, np.ndarray] = {}
    for name in ATTRIBUTES:
        if name in z.files:
            a = _array(path, z, name, 2 if name == "colors" else 1, "f")
            want = (v_count, 3) if name == "colors" else (v_count,)
            if a.shape != want:
                raise FormatError(path, f"{name!r} has shape {a.shape}, expected {want}")
            require_finite(path, a, name)
            attrs[name] = a
    if kind == "groom":
        points = _array(path, z, "points", 2, "f")
        if points.shape != (v_count, 3):
            raise FormatError(path, f"'points' has shape {points.shape}, expected {(v_count, 3)}")
        require_finite(path, points, "points")
        return Groom(points, counts, **attrs)
    if kind == "animation":
        frames = _array(path, z, "frames", 3, "f")
        if frames.shape[0] < 1 or frames.shape[1:] != (v_count, 3):
            raise FormatError(path, f"'frames' has shape {frames.shape}, expected (F>=1, {v_count}, 3)")
        require_finite(path, frames.reshape(-1, 3), "frames")
        fps = float(_scalar(path, z, "fps", "fiu"))
        if not (np.isfinite(fps) and fps > 0):
            raise FormatError(path, f"fps is {fps}; expected a positive number")
        return Animation(frames, counts, fps, **attrs, metadata=_time_codes(path, z, frames.shape[0]))
    raise FormatError(path, f"kind is {kind!r}; expected 'groom' or 'animation'")
