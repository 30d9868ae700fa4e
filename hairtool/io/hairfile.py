"""Cem Yuksel's HAIR format (``.hair``): a 128-byte header, then optional flat arrays.

Header (little-endian): ``char[4] "HAIR"; u32 hair_count; u32 point_count; u32 arrays;
u32 default_segments; f32 default_thickness; f32 default_transparency; f32 default_color[3];
char info[88]``. ``arrays`` is a bit set (1 segments, 2 points, 4 thickness, 8 transparency,
16 colors) and the arrays follow in that order: segments u16 per strand (points = segments + 1),
points f32×3, thickness f32, transparency f32, colors f32×3 per point.

Decision: the header's default thickness / transparency / colour are *not* materialised as
attributes when their array is absent, so a groom read from such a file reports only what the
file really stores; :func:`read_header` gives the defaults and the info string to callers who
want them, and :func:`write` takes them back (``info=``, ``defaults=``).
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from hairtool.errors import FormatError
from hairtool.groom import Animation, Groom
from hairtool.io.atomic import atomic_open
from hairtool.io.binary import array_at, read_bytes, require_finite, require_strand_counts

MAGIC = b"HAIR"
HEADER_SIZE = 128
INFO_SIZE = 88

HAS_SEGMENTS = 1
HAS_POINTS = 2
HAS_THICKNESS = 4
HAS_TRANSPARENCY = 8
HAS_COLORS = 16
_ALL_FLAGS = HAS_SEGMENTS | HAS_POINTS | HAS_THICKNESS | HAS_TRANSPARENCY | HAS_COLORS

HEADER_DTYPE = np.dtype(
    [
        ("magic", "S4"),
        ("hair_count", "<u4"),
        ("point_count", "<u4"),
        ("arrays", "<u4"),
        ("default_segments", "<u4"),
        ("default_thickness", "<f4"),
        ("default_transparency", "<f4"),
        ("default_color", "<f4", (3,)),
        ("info", "S88"),
    ]
)
assert HEADER_DTYPE.itemsize == HEADER_SIZE

#: Written into the 88-byte info field when :func:`write` is given no ``info``.
DEFAULT_INFO = "written by hairtool"


@dataclass(frozen=True)
class HairDefaults:
    """The header values a reader uses for arrays the file omits."""

    thickness: float = 1.0
    transparency: float = 0.0
    color: tuple[float, float, float] = (1.0, 1.0, 1.0)


@dataclass(frozen=True)
class HairHeader:
    hair_count: int
    point_count: int
    arrays: int
    default_segments: int
    defaults: HairDefaults = field(default_factory=HairDefaults)
    info: str = ""


def _parse_header(path: Path, data: bytes) -> HairHeader:
    h = np.frombuffer(data, dtype=HEADER_DTYPE, count=1)[0]
    if bytes(h["magic"]) != MAGIC:
        raise FormatError(path, f"not a HAIR file (magic {bytes(data[:4])!r}, expected {MAGIC!r})")
    defaults = HairDefaults(
        float(h["default_thickness"]),
        float(h["default_transparency"]),
        tuple(float(c) for c in h["default_color"]),
    )
    # numpy's "S88" already stops at the first NUL.
    info = bytes(h["info"]).decode("utf-8", errors="replace")
    return HairHeader(
        int(h["hair_count"]),
        int(h["point_count"]),
        int(h["arrays"]),
        int(h["default_segments"]),
        defaults,
        info,
    )


def read_header(path: str | os.PathLike[str]) -> HairHeader:
    """The header alone: counts, array flags, defaults for absent arrays and the info string.

    Parameters
    ----------
    path : str or os.PathLike
        A HAIR file.

    Returns
    -------
    HairHeader
        The header.
    """
    p = Path(path)
    return _parse_header(p, read_bytes(p, HEADER_SIZE, "HAIR", limit=HEADER_SIZE))


def read(path: Path) -> Groom:
    """Read a HAIR file; every size is checked against the header before any array is read.

    Parameters
    ----------
    path : Path
        A HAIR file.

    Returns
    -------
    Groom
        The strands and the arrays it holds.
    """
    data = read_bytes(path, HEADER_SIZE, "HAIR")
    h = _parse_header(path, data)
    flags = h.arrays
    if flags & ~_ALL_FLAGS:
        raise FormatError(path, f"unknown array flags 0x{flags & ~_ALL_FLAGS:x} in the header")
    if not flags & HAS_POINTS:
        raise FormatError(path, "the file has no points array")
    s_count, v_count = h.hair_count, h.point_count
    if s_count == 0:
        raise FormatError(path, "the file holds no strands (hair_count is 0)")

    # Expected size from the header alone (Python ints), before touching any array.
    per_point = 12 + 4 * bool(flags & HAS_THICKNESS) + 4 * bool(flags & HAS_TRANSPARENCY)
    per_point += 12 * bool(flags & HAS_COLORS)
    seg_bytes = 2 * s_count if flags & HAS_SEGMENTS else 0
    expected = HEADER_SIZE + seg_bytes + per_point * v_count
    if len(data) < expected:
        raise FormatError(
            path,
            f"truncated: the header needs {expected} bytes ({s_count} strands, {v_count} points) "
            f"but the file has {len(data)}",
        )
    if len(data) > expected:
        raise FormatError(path, f"{len(data) - expected} unexpected bytes after the last array")

    offset = HEADER_SIZE
    if flags & HAS_SEGMENTS:
        counts = array_at(path, data, offset, "<u2", s_count, "segments").astype(np.int64) + 1
        offset += seg_bytes
    else:
        if h.default_segments < 1:
            raise FormatError(path, f"default_segments is {h.default_segments}; strands need at least 1")
        # The header alone fixes every count: check the total (Python ints) before allocating S counts.
        total = s_count * (h.default_segments + 1)
        if total != v_count:
            raise FormatError(
                path,
                f"{s_count} strands of {h.default_segments + 1} points add up to {total} points "
                f"but the header says {v_count}",
            )
        counts = np.full(s_count, h.default_segments + 1, dtype=np.int64)
    require_strand_counts(path, counts, v_count)

    points = array_at(path, data, offset, "<f4", 3 * v_count, "points").reshape(v_count, 3)
    offset += 12 * v_count
    require_finite(path, points, "points")
    attrs: dict[str, np.ndarray] = {}
    for flag, name, width in ((HAS_THICKNESS, "thickness", 1), (HAS_TRANSPARENCY, "transparency", 1)):
        if flags & flag:
            attrs[name] = array_at(path, data, offset, "<f4", v_count, name)
            offset += 4 * v_count * width
            require_finite(path, attrs[name], name)
    if flags & HAS_COLORS:
        attrs["colors"] = array_at(path, data, offset, "<f4", 3 * v_count, "colors").reshape(v_count, 3)
        require_finite(path, attrs["colors"], "colors")
    return Groom(points, counts, **attrs)


def _info_bytes(info: str) -> bytes:
    raw = info.encode("utf-8")[: INFO_SIZE - 1]
    # Do not cut a multi-byte character in half.
    return raw.decode("utf-8", errors="ignore").encode("utf-8")


def write(
    path: Path,
    obj: Groom | Animation,
    *,
    info: str | None = None,
    defaults: HairDefaults | None = None,
) -> None:
    """Write a groom (an animation's first frame); equal strand lengths omit the segments array.

    ``info``: at most 87 UTF-8 bytes are kept (the field is NUL-terminated); ``None`` writes
    :data:`DEFAULT_INFO`.

    Parameters
    ----------
    path : Path
        The file, written atomically.
    obj : Groom or Animation
        What to write.
    info : str, optional
        The header's info string.
    defaults : HairDefaults, optional
        Values written for arrays left out.
    """
    groom = obj.rest if isinstance(obj, Animation) else obj
    d = defaults or HairDefaults()
    counts = groom.counts
    if counts.max() - 1 > np.iinfo(np.uint16).max:
        raise FormatError(path, f"a strand has {int(counts.max())} points; HAIR allows at most 65536")
    if groom.vertex_count > np.iinfo(np.uint32).max or groom.strand_count > np.iinfo(np.uint32).max:
        raise FormatError(path, "too many points for the HAIR format's 32-bit counts")
    uniform = bool(np.all(counts == counts[0]))
    flags = HAS_POINTS | (0 if uniform else HAS_SEGMENTS)
    flags |= HAS_THICKNESS if groom.thickness is not None else 0
    flags |= HAS_TRANSPARENCY if groom.transparency is not None else 0
    flags |= HAS_COLORS if groom.colors is not None else 0

    header = np.zeros(1, dtype=HEADER_DTYPE)
    header["magic"] = MAGIC
    header["hair_count"] = groom.strand_count
    header["point_count"] = groom.vertex_count
    header["arrays"] = flags
    header["default_segments"] = int(counts[0]) - 1 if uniform else 0
    header["default_thickness"] = d.thickness
    header["default_transparency"] = d.transparency
    header["default_color"] = d.color
    header["info"] = _info_bytes(DEFAULT_INFO if info is None else info)

    with atomic_open(path, "wb") as f:
        f.write(header.tobytes())
        if not uniform:
            f.write((counts - 1).astype("<u2").tobytes())
        f.write(groom.points.astype("<f4").tobytes())
        for a in (groom.thickness, groom.transparency, groom.colors):
            if a is not None:
                f.write(a.astype("<f4").tobytes())
