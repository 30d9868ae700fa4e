"""The GLB container (glTF 2.0 binary): a JSON chunk and one BIN chunk, packed and unpacked.

Writing keeps the JSON's key order and the binary bytes as given, so a file rebuilt from the
same description is the same file, and an export can append to a character's buffer while its
own bytes stay where they were.
"""

from __future__ import annotations

import json
import struct

import numpy as np

from hairtool.errors import FormatError

MAGIC = b"glTF"
JSON_CHUNK = 0x4E4F534A
BIN_CHUNK = 0x004E4942
MAX_BYTES = 2**31  # a character file; larger is refused as hostile or broken

# glTF accessor component types and element widths
FLOAT, UNSIGNED_SHORT, UNSIGNED_INT, UNSIGNED_BYTE = 5126, 5123, 5125, 5121
COMPONENT_DTYPE = {
    5120: np.int8,
    5121: np.uint8,
    5122: np.int16,
    5123: np.uint16,
    5125: np.uint32,
    5126: np.float32,
}
TYPE_WIDTH = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4, "MAT2": 4, "MAT3": 9, "MAT4": 16}


def _pad(data: bytes, fill: bytes) -> bytes:
    return data + fill * (-len(data) % 4)


def pack(document: dict, binary: bytes) -> bytes:
    """A GLB file: ``document`` as compact JSON (padded with spaces), ``binary`` (padded with zeros).

    Parameters
    ----------
    document : dict
        The glTF JSON.
    binary : bytes
        The BIN chunk.

    Returns
    -------
    bytes
        The GLB file.
    """
    text = _pad(json.dumps(document, separators=(",", ":")).encode("utf-8"), b" ")
    chunks = struct.pack("<II", len(text), JSON_CHUNK) + text
    if binary:
        data = _pad(binary, b"\0")
        chunks += struct.pack("<II", len(data), BIN_CHUNK) + data
    return MAGIC + struct.pack("<II", 2, 12 + len(chunks)) + chunks


def unpack(path: str, data: bytes) -> tuple[dict, bytes]:
    """The JSON document and BIN chunk of GLB ``data``; a :class:`FormatError` naming ``path`` if broken.

    Parameters
    ----------
    path : str
        The file, named in a refusal.
    data : bytes
        Its contents.

    Returns
    -------
    tuple of (dict, bytes)
        The JSON and the BIN chunk.
    """
    if len(data) < 20 or data[:4] != MAGIC:
        raise FormatError(path, "not a GLB file (no 'glTF' header)")
    version, length = struct.unpack_from("<II", data, 4)
    if version != 2:
        raise FormatError(path, f"GLB version {version}; only glTF 2.0 is read")
    if length != len(data) or length > MAX_BYTES:
        raise FormatError(path, f"the header says {length} bytes but the file has {len(data)} (truncated?)")
    size, kind = struct.unpack_from("<II", data, 12)
    if kind != JSON_CHUNK or 20 + size > length:
        raise FormatError(path, "the first chunk is not a complete JSON chunk")
    try:
        document = json.loads(data[20 : 20 + size].decode("utf-8"))
    except (UnicodeDecodeError, ValueError) as e:
        raise FormatError(path, f"its JSON chunk does not parse ({e.__class__.__name__})") from None
    if not isinstance(document, dict):
        raise FormatError(path, "its JSON chunk is not an object")
    binary = b""
    at = 20 + size
    if at + 8 <= length:
        bsize, bkind = struct.unpack_from("<II", data, at)
        if bkind != BIN_CHUNK or at + 8 + bsize > length:
            raise FormatError(path, "the second chunk is not a complete BIN chunk")
        binary = data[at + 8 : at + 8 + bsize]
    return document, binary


class BufferWriter:
    """Appends typed arrays to one binary buffer and records their bufferViews and accessors.

    ``offset`` lets an export continue a character's own buffer: its bytes stay untouched and
    the new views start after them.
    """

    def __init__(self, document: dict, offset: int = 0) -> None:
        """Append buffer views and accessors to ``document`` for bytes collected here.

        Parameters
        ----------
        document : dict
            The glTF JSON, changed in place.
        offset : int, default 0
            Where the new bytes start in the buffer.
        """
        self.document = document
        self.chunks: list[bytes] = []
        self.length = offset
        self.views = 0  # bufferViews this writer added

    def add(self, values: np.ndarray, kind: str, *, target: int | None = None, bounds: bool = False) -> int:
        """Accessor index of ``values`` (float32, uint16, uint32 or uint8 rows of ``kind`` width).

        Parameters
        ----------
        values : ndarray
            Rows of ``kind`` width.
        kind : str
            The accessor type, a key of :data:`TYPE_WIDTH` (``SCALAR``, ``VEC3``, ``MAT4``…).
        target : int, optional
            The buffer view's target.
        bounds : bool, default False
            Write min and max.

        Returns
        -------
        int
            The accessor's index.
        """
        arr = np.ascontiguousarray(values)
        component = {
            np.dtype(np.float32): FLOAT,
            np.dtype(np.uint16): UNSIGNED_SHORT,
            np.dtype(np.uint32): UNSIGNED_INT,
            np.dtype(np.uint8): UNSIGNED_BYTE,
        }[arr.dtype]
        data = arr.astype(arr.dtype.newbyteorder("<")).tobytes()
        pad = -self.length % 4
        self.chunks.append(b"\0" * pad)
        self.length += pad
        view = {"buffer": 0, "byteOffset": self.length, "byteLength": len(data)}
        if target is not None:
            view["target"] = target
        self.chunks.append(data)
        self.length += len(data)
        views = self.document.setdefault("bufferViews", [])
        views.append(view)
        self.views += 1
        rows = arr.reshape(len(arr), -1)
        accessor = {"bufferView": len(views) - 1, "componentType": component, "count": len(arr), "type": kind}
        if bounds:
            accessor["min"] = [float(v) for v in rows.min(axis=0)]
            accessor["max"] = [float(v) for v in rows.max(axis=0)]
        accessors = self.document.setdefault("accessors", [])
        accessors.append(accessor)
        return len(accessors) - 1

    def bytes(self) -> bytes:
        return b"".join(self.chunks)
