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

Arrays live outside the sections, in the value region: FIELDS holds, after its count and its
compressed token indices (a u64 size, then the bytes), a u64 size and an LZ4 block (behind a
one-byte chunk count) of one 64-bit value representation per field. A representation whose
bit 63 is set and bit 62 clear is an array stored at the byte its low 48 bits give, of the
element type in bits 48-55; there the array starts with its element count (u64 from crate
0.7, u32 before, after a u32 shape before 0.5), and usd-core sizes the array from that count
before it reads a value. A count is refused when its elements cannot fit in the bytes left
after it: raw, each element takes its size on disk; compressed (bit 61, integers from 0.5,
floating point from 0.6, 16 elements or more) each takes at least 2 bits before LZ4, so 1,020
per byte. Vectors of paths, tokens, doubles (the sample times), layer offsets and strings are
read the same way, a u64 count first; a time samples value leads, by two relative jumps, to its
times and to the representations of its values, which are checked in turn. A 28 KB crate
declaring 400 million curve counts cost usd-core 1.7 to 5.1 GB before.
"""

from __future__ import annotations

import struct
from pathlib import Path

from hairtool import budget
from hairtool.errors import FormatError

MAGIC = b"PXR-USDC"
_LZ4_RATIO = 255
_INTS_PER_BYTE = 4 * _LZ4_RATIO
_KNOWN = {b"TOKENS", b"STRINGS", b"FIELDS", b"FIELDSETS", b"PATHS", b"SPECS"}
_IS_ARRAY, _IS_INLINED, _IS_COMPRESSED = 1 << 63, 1 << 62, 1 << 61
_PAYLOAD = (1 << 48) - 1
_MIN_COMPRESSED = 16  # shorter arrays are stored raw even when marked compressed
#: Bytes on disk of one element of each array type (crateDataTypes.h's enumerants): strings,
#: tokens and asset paths as u32 indices into their tables.
_DISK_BYTES = {
    1: 1, 2: 1, 3: 4, 4: 4, 5: 8, 6: 8, 7: 2, 8: 4, 9: 8, 10: 4, 11: 4, 12: 4,
    13: 32, 14: 72, 15: 128, 16: 32, 17: 16, 18: 8, 19: 16, 20: 8, 21: 4, 22: 8,
    23: 24, 24: 12, 25: 6, 26: 12, 27: 32, 28: 16, 29: 8, 30: 16, 56: 8,
}  # fmt: skip
#: Bytes in memory of one element where usd-core holds more than the disk does (a TfToken or
#: an SdfAssetPath index becomes a pointer-sized handle, a string a std::string).
_MEMORY_BYTES = {**_DISK_BYTES, 10: 32, 11: 8, 12: 64}
_INTS, _FLOATS = {3, 4, 5, 6}, {7, 8, 9}
#: Values held as a std::vector (not VtArray), read as a u64 count and its elements: (bytes on
#: disk, bytes in memory) of one element of paths, tokens, doubles, layer offsets, strings.
_VECTOR_BYTES = {40: (4, 8), 41: (4, 8), 48: (8, 8), 49: (16, 16), 50: (4, 32)}
_TIME_SAMPLES = 46


def _u64(data: bytes, at: int) -> int:
    return struct.unpack_from("<Q", data, at)[0]


def check(path: Path) -> None:
    """Raise FormatError if the crate's table of contents or section counts cannot be true.

    Parameters
    ----------
    path : Path
        A ``.usdc`` file.
    """
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
            if name == b"FIELDS":
                f.seek(start)
                version = (head[8], head[9])
                _check_arrays(path, f, _value_reps(path, f.read(length)), size, version)


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


def _value_reps(path: Path, section: bytes) -> list[int]:
    """The FIELDS section's value representations (its count is already checked)."""
    count = _u64(section, 0)
    at = 8
    if count == 0:
        return []
    for what in ("token indices", "value table"):
        if at + 8 > len(section):
            raise FormatError(path, f"crate section FIELDS ends before its {what}")
        n = _u64(section, at)
        if n > len(section) - at - 8:
            raise FormatError(path, f"crate section FIELDS claims a {what} of {n} bytes; it holds fewer")
        at += 8 + n
    table = _fast_decompress(path, section[at - n : at], 8 * count)
    if len(table) != 8 * count:
        raise FormatError(path, f"crate section FIELDS holds {len(table) // 8} values for its {count} fields")
    return list(struct.unpack(f"<{count}Q", table))


def _check_arrays(path: Path, f, reps: list[int], size: int, version: tuple[int, int]) -> None:
    """Every array's and vector's element count against the bytes after it, the time samples'
    value representations included (see the module docstring)."""
    todo, seen = list(reps), set()
    while todo:
        rep = todo.pop()
        kind, at = (rep >> 48) & 0xFF, rep & _PAYLOAD
        if rep & _IS_INLINED or at == 0 or rep in seen:
            continue
        seen.add(rep)
        if rep & _IS_ARRAY and kind in _DISK_BYTES:
            head = 4 if version < (0, 5) else 0
            _check_count(path, f, rep, at + head, 8 if version >= (0, 7) else 4, size, version)
        elif not rep & _IS_ARRAY and kind in _VECTOR_BYTES:
            _check_count(path, f, rep, at, 8, size, version)
        elif not rep & _IS_ARRAY and kind == _TIME_SAMPLES:
            todo += _time_sample_reps(path, f, at, size)


def _read_at(path: Path, f, at: int, n: int, size: int) -> bytes:
    if at < 0 or at + n > size:
        raise FormatError(path, f"a crate value at byte {at} lies outside the file ({size} bytes)")
    f.seek(at)
    return f.read(n)


def _time_sample_reps(path: Path, f, at: int, size: int) -> list[int]:
    """The representations of a time samples value: a jump (i64, from where it is read) to its
    times' representation, then a jump to the u64 count of its values' representations."""
    (jump,) = struct.unpack("<q", _read_at(path, f, at, 8, size))
    times = at + jump
    (times_rep,) = struct.unpack("<Q", _read_at(path, f, times, 8, size))
    (jump,) = struct.unpack("<q", _read_at(path, f, times + 8, 8, size))
    values = times + 8 + jump
    (n,) = struct.unpack("<Q", _read_at(path, f, values, 8, size))
    left = size - values - 8
    if n > left // 8:
        raise FormatError(path, f"crate time samples at byte {at} claim {n} values; {left} bytes hold fewer")
    return [times_rep, *struct.unpack(f"<{n}Q", _read_at(path, f, values + 8, 8 * n, size))]


def _check_count(path: Path, f, rep: int, at: int, width: int, size: int, version: tuple[int, int]) -> None:
    kind = (rep >> 48) & 0xFF
    n = int.from_bytes(_read_at(path, f, at, width, size), "little")
    left = size - (at + width)
    compressed = (
        rep & _IS_ARRAY
        and rep & _IS_COMPRESSED
        and n >= _MIN_COMPRESSED
        and ((kind in _INTS and version >= (0, 5)) or (kind in _FLOATS and version >= (0, 6)))
    )
    disk, memory = (_DISK_BYTES[kind], _MEMORY_BYTES[kind]) if rep & _IS_ARRAY else _VECTOR_BYTES[kind]
    bound = _INTS_PER_BYTE * left if compressed else left // disk
    if n > bound:
        why = f"the {left} bytes after it hold at most {bound}"
        raise FormatError(path, f"a crate array at byte {at} claims {n} values; {why}")
    budget.check_bytes(n * memory, f"{path}: a crate array of {n} values")


def _fast_decompress(path: Path, data: bytes, limit: int) -> bytes:
    """usd-core's chunked LZ4 (TfFastCompression): a signed chunk count byte, 0 for one block
    filling the rest, else that many blocks each behind its i32 size; at most ``limit`` bytes."""
    if not data:
        raise FormatError(path, "crate section FIELDS has an empty value table")
    chunks = int.from_bytes(data[:1], "little", signed=True)
    if chunks == 0:
        return _lz4_block(path, data[1:], limit)
    out, at = bytearray(), 1
    for _ in range(max(chunks, 0)):
        (n,) = struct.unpack_from("<i", data, at) if at + 4 <= len(data) else (-1,)
        if n < 0 or at + 4 + n > len(data):
            raise FormatError(path, "crate section FIELDS has a value table chunk outside it")
        out += _lz4_block(path, data[at + 4 : at + 4 + n], limit - len(out))
        at += 4 + n
    return bytes(out)


def _lz4_block(path: Path, src: bytes, limit: int) -> bytes:
    """One LZ4 block: sequences of a token (literal length, match length), the literals, and a
    2-byte back offset; lengths of 15 go on in bytes of 255. Never more than ``limit`` bytes."""
    out = bytearray()
    i, end = 0, len(src)

    def length(start: int, i: int) -> tuple[int, int]:
        n = start
        if start == 15:
            while True:
                if i >= end:
                    raise FormatError(path, "crate value table: an LZ4 length runs past its block")
                b = src[i]
                i += 1
                n += b
                if b != 255:
                    break
        return n, i

    while i < end:
        token = src[i]
        n, i = length(token >> 4, i + 1)
        if i + n > end or len(out) + n > limit:
            raise FormatError(path, "crate value table: LZ4 literals run past the block or the table")
        out += src[i : i + n]
        i += n
        if i == end:
            break  # the last sequence has literals only
        if i + 2 > end:
            raise FormatError(path, "crate value table: an LZ4 match offset runs past its block")
        back = src[i] | src[i + 1] << 8
        m, i = length(token & 15, i + 2)
        m += 4
        if back == 0 or back > len(out) or len(out) + m > limit:
            raise FormatError(path, "crate value table: an LZ4 match reaches outside the table")
        start = len(out) - back
        if back >= m:
            out += out[start : start + m]
        else:  # the match overlaps what it writes: its pattern of ``back`` bytes repeats
            pattern = bytes(out[start:])
            out += (pattern * (m // back + 1))[:m]
    return bytes(out)
