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


def require_size(path: str | os.PathLike[str], data: bytes, min_size: int, what: str) -> None:
    """An empty file, or one shorter than its ``what`` header of ``min_size`` bytes, is a FormatError."""
    if not data:
        raise FormatError(path, "the file is empty")
    if len(data) < min_size:
        raise FormatError(path, f"the file has {len(data)} bytes, too short for a {what} header ({min_size})")


def read_bytes(path: Path, min_size: int, what: str, limit: int | None = None) -> bytes:
    """The whole file (its first ``limit`` bytes with ``limit``), checked by :func:`require_size`."""
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
    """A read-only ``(count,)`` view of ``dtype`` at byte ``offset``; the range must lie in the file."""
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
    """Non-finite values in a file are corruption, not data."""
    finite = np.isfinite(values)
    if not finite.all():
        flat = np.flatnonzero(~finite.reshape(len(values), -1).all(axis=1))
        raise FormatError(path, f"{what} has a non-finite value at index {int(flat[0])}")


def require_strand_counts(path: str | os.PathLike[str], counts: np.ndarray) -> None:
    """Every strand needs a root and a tip."""
    if counts.size == 0:
        raise FormatError(path, "the file holds no strands")
    short = np.flatnonzero(counts < 2)
    if short.size:
        s = int(short[0])
        raise FormatError(path, f"strand {s} has {int(counts[s])} points; every strand needs at least 2")
