"""USC-HairSalon's ``.data`` strands (Hu et al. 2015's database of 343 hairstyles, and the
research code that reads it): little-endian ``i32 strand_count``, then per strand ``i32
point_count`` and that many points of ``f32 x, y, z``. Nothing else: no header, no up axis
(the database's heads are Y-up), no attributes.

Every count is checked against the bytes the file still holds before anything is allocated, so
a truncated file or a count of two billion is one clear error naming the file. A strand needs a
root and a tip: the database marks a bald scalp sample as a strand of one point, which most of
its files hold, so those strands are dropped and a :class:`~hairtool.errors.ReaderNote` says how
many (the CLI prints it as one warning line); a file of nothing else is refused.
"""

from __future__ import annotations

import struct
import warnings
from pathlib import Path

import numpy as np

from hairtool.errors import FormatError, ReaderNote
from hairtool.groom import Animation, Groom
from hairtool.io.atomic import atomic_open
from hairtool.io.binary import array_at, read_bytes, require_finite, require_strand_counts
from hairtool.metadata import Metadata

INT32_MAX = 2**31 - 1


def strand_counts(path: Path, data: bytes) -> np.ndarray:
    """``(S,)`` points per strand (a bald scalp sample's one included), walking the file's
    counts; each one is checked against what is left of the file before the next is read.

    Parameters
    ----------
    path : Path
        The file, named in a refusal.
    data : bytes
        Its contents.

    Returns
    -------
    ndarray
        ``(S,)`` int64.
    """
    (n,) = struct.unpack_from("<i", data, 0)
    if n <= 0:
        raise FormatError(path, f"the strand count is {n}; a .data file holds at least one strand")
    if 4 + 4 * n > len(data):  # every strand takes at least its own count
        raise FormatError(path, f"{n} strands need at least {4 + 4 * n} bytes but the file has {len(data)}")
    counts = np.empty(n, np.int64)
    offset = 4
    for s in range(n):
        if offset + 4 > len(data):
            raise FormatError(path, f"truncated: strand {s} of {n} has no point count (the file ends)")
        (c,) = struct.unpack_from("<i", data, offset)
        if c < 1:
            raise FormatError(path, f"strand {s} has {c} points; every strand needs at least 1")
        end = offset + 4 + 12 * c
        if end > len(data):
            raise FormatError(
                path, f"truncated: strand {s} claims {c} points ({12 * c} bytes) but the file ends first"
            )
        counts[s] = c
        offset = end
    if offset != len(data):
        raise FormatError(path, f"{len(data) - offset} unexpected bytes after the last strand")
    return counts


def read(path: Path) -> Groom:
    """Read a ``.data`` file (see the module docstring).

    Parameters
    ----------
    path : Path
        A ``.data`` file.

    Returns
    -------
    Groom
        Its strands of at least two points (the others dropped with a :class:`~hairtool.errors.ReaderNote`).
    """
    data = read_bytes(path, 4, "USC-HairSalon .data")
    counts = strand_counts(path, data)
    hair = counts >= 2
    bald = len(counts) - int(hair.sum())
    if bald == len(counts):
        raise FormatError(path, f"all {bald} strands have one point (bald scalp samples); no hair to read")
    # The points are interleaved with the counts: point g of strand s starts at float word
    # 1 + (s + 1) + 3·g (the strand count, the counts up to its own, the points before it).
    words = array_at(path, data, 0, "<f4", len(data) // 4, "points")
    strand = np.repeat(np.arange(len(counts), dtype=np.int64), counts)
    first = strand + 2 + 3 * np.arange(int(counts.sum()), dtype=np.int64)
    if bald:
        first = first[hair[strand]]
        counts = counts[hair]
    require_strand_counts(path, counts)
    points = words[first[:, None] + np.arange(3)]
    require_finite(path, points, "points")
    if bald:
        said = f"{path}: dropped {bald} of {bald + len(counts)} strands of one point (bald scalp samples)"
        warnings.warn(ReaderNote(said), stacklevel=2)
    return Groom(points, counts, metadata=Metadata())  # no scene: Y-up, centimetres, as .hair and .tfx


def write(path: Path, obj: Groom | Animation) -> None:
    """Write a groom (an animation's first frame) as ``.data``: its points only.

    Parameters
    ----------
    path : Path
        The file, written atomically.
    obj : Groom or Animation
        What to write.
    """
    groom = obj.rest if isinstance(obj, Animation) else obj
    if groom.strand_count > INT32_MAX:
        raise FormatError(path, "too many strands for the .data format's 32-bit count")
    counts = groom.counts.astype("<i4")
    pts = groom.points.astype("<f4")
    ends = np.cumsum(groom.counts)
    with atomic_open(path, "wb") as f:
        f.write(struct.pack("<i", groom.strand_count))
        start = 0
        for c, end in zip(counts, ends, strict=True):
            f.write(c.tobytes())
            f.write(pts[start:end].tobytes())
            start = int(end)
