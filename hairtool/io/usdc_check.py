"""A crate file's (``.usdc``) structural counts checked against its size before usd-core reads it.

usd-core sizes its tables from the counts in a crate's sections and allocates before it finds
they are false: a TOKENS section claiming 2^28 tokens costs 2.2 GB and 2 s, a FIELDS section
claiming 2^28 fields 4.3 GB and 4 s, before the one-line error. The layout read here (crate
version 0.4 and later, little-endian):

- bootstrap: ``b"PXR-USDC"``, an 8-byte version, the u64 offset of the table of contents;
- table of contents: u64 section count, then per section a 16-byte name, i64 start, i64 size;
- every section (TOKENS, STRINGS, FIELDS, FIELDSETS, PATHS, SPECS) begins with the u64 count
  of what it holds; TOKENS then gives the u64 uncompressed and compressed sizes of its text,
  STRINGS holds one u32 per string.

Counts are bounded by what the section's bytes can decode to: LZ4 expands data at most 255
times, and the integer coding of FIELDS, FIELDSETS, PATHS and SPECS spends at least 2 bits per
integer, so no true count exceeds 1,020 per byte of its section.
"""

from __future__ import annotations

import struct
from pathlib import Path

from hairtool.errors import FormatError

MAGIC = b"PXR-USDC"
_LZ4_RATIO = 255
_INTS_PER_BYTE = 4 * _LZ4_RATIO
_KNOWN = {b"TOKENS", b"STRINGS", b"FIELDS", b"FIELDSETS", b"PATHS", b"SPECS"}


def _u64(data: bytes, at: int) -> int:
    return struct.unpack_from("<Q", data, at)[0]


def check(path: Path) -> None:
    """Raise FormatError if the crate's table of contents or section counts cannot be true."""
    with open(path, "rb") as f:
        head = f.read(24)
        if len(head) < 24 or head[:8] != MAGIC:
            return  # not a crate (or too short for one): usd-core's own checks answer
        if (head[8], head[9]) < (0, 4):
            return  # an early crate with another section layout
        size = f.seek(0, 2)
        toc = _u64(head, 16)
        if not 24 <= toc <= size - 8:
            raise FormatError(
                path, f"crate table of contents at byte {toc} lies outside the file ({size} bytes)"
            )
        f.seek(toc)
        n = _u64(f.read(8), 0)
        if n > (size - toc - 8) // 32:
            raise FormatError(
                path, f"crate table of contents claims {n} sections; the file has room for fewer"
            )
        table = f.read(32 * n)
        for i in range(n):
            name, start, length = struct.unpack_from("<16sqq", table, 32 * i)
            name = name.rstrip(b"\0")
            if start < 0 or length < 0 or start + length > size:
                raise FormatError(path, f"crate section {name!r} lies outside the file")
            if name in _KNOWN:
                f.seek(start)
                _check_section(path, name.decode(), f.read(min(length, 24)), length)


def _check_section(path: Path, name: str, head: bytes, length: int) -> None:
    if len(head) < 8:
        raise FormatError(path, f"crate section {name} is too short to hold its count")
    count = _u64(head, 0)
    if name == "STRINGS":
        bound = (length - 8) // 4
    elif name == "TOKENS":
        if len(head) < 24:
            raise FormatError(path, "crate section TOKENS is too short for its sizes")
        uncompressed, compressed = _u64(head, 8), _u64(head, 16)
        if compressed > length - 24 or uncompressed > _LZ4_RATIO * compressed + 64:
            raise FormatError(path, "crate section TOKENS claims more text than it holds")
        bound = uncompressed  # every token ends in a null byte
    else:
        bound = _INTS_PER_BYTE * length
    if count > bound:
        raise FormatError(
            path, f"crate section {name} claims {count} entries; its {length} bytes hold at most {bound}"
        )
