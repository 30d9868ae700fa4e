"""Bounded reading of binary files: every array is checked against the file size before it is touched.

Readers take the whole file as ``bytes`` and cut typed views out of it with :func:`array_at`; a
header that claims more data than the file holds raises :class:`FormatError` before anything is
allocated, so a corrupt count of 2^31 strands costs nothing.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from hairtool.errors import FormatError
from hairtool.groom import MAX_STRAND_VERTICES


def require_size(path: str | os.PathLike[str], data: bytes, min_size: int, what: str) -> None:
    """An empty file, or one shorter than its ``what`` header of ``min_size`` bytes, is a FormatError.

    Parameters
    ----------
    path : str or os.PathLike
        The file, named in a refusal.
    data : bytes
        Its contents.
    min_size : int
        The header's size.
    what : str
        The header's name.
    """
    if not data:
        raise FormatError(path, "the file is empty")
    if len(data) < min_size:
        raise FormatError(path, f"the file has {len(data)} bytes, too short for a {what} header ({min_size})")


def read_bytes(path: Path, min_size: int, what: str, limit: int | None = None) -> bytes:
    """The whole file (its first ``limit`` bytes with ``limit``), checked by :func:`require_size`.

    Parameters
    ----------
    path : Path
        The file.
    min_size : int
        The header's size.
    what : str
        The header's name.
    limit : int, optional
        Read at most this many bytes.

    Returns
    -------
    bytes
        The contents.
    """
    if limit is None:
        data = path.read_bytes()
    else:
        with open(path, "rb") as f:
            data = f.read(limit)
    require_size(path, data, min_size, what)
    return data


def array_at(
    path: str | os.PathLike[str],
    data: bytes,
    offset: int,
    dtype: str,
    count: int,
    what: str,
) -> np.ndarray:
    """A read-only ``(count,)`` view of ``dtype`` at byte ``offset``; the range must lie in the file.

    Parameters
    ----------
    path : str or os.PathLike
        The file, named in a refusal.
    data : bytes
        Its contents.
    offset : int
        Where the array starts.
    dtype : str
        Its numpy dtype.
    count : int
        Its length.
    what : str
        Its name in a refusal.

    Returns
    -------
    ndarray
        ``(count,)``, read-only.
    """
    item = np.dtype(dtype).itemsize
    offset, count = int(offset), int(count)  # Python ints: products of header fields cannot overflow
    if count < 0 or offset < 0:
        raise FormatError(path, f"{what}: negative offset or count")
    end = offset + count * item
    if end > len(data):
        raise FormatError(
            path,
            f"{what} needs bytes {offset}..{end} but the file has only {len(data)} bytes (truncated?)",
        )
    return np.frombuffer(data, dtype=dtype, count=count, offset=offset)


def require_finite(path: str | os.PathLike[str], values: np.ndarray, what: str) -> None:
    """Non-finite values in a file are corruption, not data.

    Parameters
    ----------
    path : str or os.PathLike
        The file, named in a refusal.
    values : ndarray
        Values read from it.
    what : str
        Their name in a refusal.
    """
    finite = np.isfinite(values)
    if not finite.all():
        flat = np.flatnonzero(~finite.reshape(len(values), -1).all(axis=1))
        raise FormatError(path, f"{what} has a non-finite value at index {int(flat[0])}")


def float32_finite(path: str | os.PathLike[str], values: np.ndarray, what: str) -> np.ndarray:
    """``values`` as float32, checked *after* the cast: a float64 of 1e39 is finite, its float32 is not.

    Parameters
    ----------
    path : str or os.PathLike
        The file, named in a refusal.
    values : ndarray
        Values read from it.
    what : str
        Their name in a refusal.

    Returns
    -------
    ndarray
        float32.
    """
    if values.dtype.kind not in "fiu":
        raise FormatError(path, f"{what} must hold numbers, not {values.dtype}")
    with np.errstate(over="ignore", invalid="ignore"):
        out = values.astype(np.float32, copy=False)
    if not np.all(np.isfinite(out)):
        big = np.isfinite(values) if values.dtype.kind == "f" else np.ones(values.shape, bool)
        bad = ~np.isfinite(out)
        index = int(np.flatnonzero(bad.reshape(len(out), -1).any(axis=1))[0])
        if np.any(big & bad):
            raise FormatError(path, f"{what} has a value at index {index} beyond float32's range (±3.4e38)")
        raise FormatError(path, f"{what} has a non-finite value at index {index}")
    return out


def require_strand_counts(
    path: str | os.PathLike[str], counts: np.ndarray, points: int | None = None
) -> int:
    """Every strand needs a root and a tip, and at most ``points`` (the points the file's header
    gives, else :data:`~hairtool.groom.MAX_STRAND_VERTICES`); returns the total, exact, which
    must equal ``points`` when given.

    Bounding each count first keeps the int64 sum from wrapping around: counts of 2^62 whose sum
    wraps to the number of points in the file would otherwise pass the size checks.

    Parameters
    ----------
    path : str or os.PathLike
        The file, named in a refusal.
    counts : ndarray
        Each strand's vertex count.
    points : int, optional
        The points the header gives.

    Returns
    -------
    int
        The total.
    """
    counts = np.asarray(counts)
    if counts.size == 0:
        raise FormatError(path, "the file holds no strands")
    if counts.size >= 2**32:
        raise FormatError(path, f"{counts.size} strands; hairtool reads at most 2^32 - 1")
    short = np.flatnonzero(counts < 2)
    if short.size:
        s = int(short[0])
        raise FormatError(path, f"strand {s} has {int(counts[s])} points; every strand needs at least 2")
    limit = MAX_STRAND_VERTICES if points is None else min(int(points), MAX_STRAND_VERTICES)
    long = np.flatnonzero(counts > limit)
    if long.size:
        s = int(long[0])
        if limit < MAX_STRAND_VERTICES:
            raise FormatError(path, f"strand {s} claims {int(counts[s])} points; the file holds {points}")
        raise FormatError(
            path, f"strand {s} claims {int(counts[s])} points; hairtool reads at most {limit} per strand"
        )
    # Each count <= 2^31 - 1 and fewer than 2^32 strands: the int64 sum cannot wrap.
    total = int(counts.sum(dtype=np.int64))
    if points is not None and total != points:
        raise FormatError(path, f"the strands add up to {total} points but the header says {points}")
    return total
