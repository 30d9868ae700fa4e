"""Typed arrays out of a glTF document's accessors, checked against the buffers they point into.

Every index and byte range is checked before a byte is read, so a hostile or truncated file
gives one :class:`~hairtool.errors.FormatError` line instead of an exception from deep inside.
"""

from __future__ import annotations

import base64
import os
from pathlib import Path

import numpy as np
from pygltflib import GLTF2

from hairtool.character.glb import COMPONENT_DTYPE, TYPE_WIDTH
from hairtool.errors import FormatError

MAX_BUFFER_BYTES = 2**31


def buffers(path: str, gltf: GLTF2, glb_binary: bytes | None) -> list[bytes]:
    """The bytes of every buffer: the GLB's BIN chunk, a base64 data URI, or a file beside ``path``.

    Parameters
    ----------
    path : str
        The file, for relative URIs and refusals.
    gltf : GLTF2
        The document.
    glb_binary : bytes or None
        The GLB's BIN chunk.

    Returns
    -------
    list of bytes
        One per buffer.
    """
    out = []
    for i, b in enumerate(gltf.buffers or []):
        uri = b.uri
        if uri is None:
            if glb_binary is None or i != 0:
                raise FormatError(path, f"buffer {i} has no uri and there is no GLB binary chunk for it")
            data = glb_binary
        elif uri.startswith("data:"):
            head, _, payload = uri.partition(",")
            if not head.endswith(";base64"):
                raise FormatError(path, f"buffer {i}: only base64 data URIs are read")
            try:
                data = base64.b64decode(payload, validate=True)
            except ValueError:
                raise FormatError(path, f"buffer {i}: its data URI is not valid base64") from None
        else:
            folder = Path(path).resolve().parent
            target = (folder / uri).resolve()
            if folder not in target.parents or not target.is_file():
                raise FormatError(path, f"buffer {i}: {uri!r} is not a file beside it")
            if os.path.getsize(target) > MAX_BUFFER_BYTES:
                raise FormatError(path, f"buffer {i}: {uri!r} is larger than {MAX_BUFFER_BYTES} bytes")
            data = target.read_bytes()
        if b.byteLength is None or not isinstance(b.byteLength, int) or len(data) < b.byteLength:
            raise FormatError(path, f"buffer {i} is shorter than its byteLength {b.byteLength}")
        out.append(data)
    return out


def _index(path: str, what: str, value: object, count: int) -> int:
    if not isinstance(value, int) or isinstance(value, bool) or not 0 <= value < count:
        raise FormatError(path, f"{what} {value!r} is not an index below {count}")
    return value


def read(path: str, gltf: GLTF2, data: list[bytes], index: object, what: str) -> np.ndarray:
    """``(count, width)`` (``(count,)`` for scalars) array of accessor ``index``; ``what`` names its use.

    Parameters
    ----------
    path : str
        The file, named in a refusal.
    gltf : GLTF2
        The document.
    data : list of bytes
        Its buffers.
    index : object
        The accessor's index, as the document gives it.
    what : str
        Its use, named in a refusal.

    Returns
    -------
    ndarray
        The accessor's values.
    """
    accessors = gltf.accessors or []
    a = accessors[_index(path, f"{what}: accessor", index, len(accessors))]
    if a.sparse is not None:
        raise FormatError(path, f"{what}: sparse accessors are not read")
    if a.componentType not in COMPONENT_DTYPE or a.type not in TYPE_WIDTH:
        raise FormatError(
            path, f"{what}: accessor {index} has an unknown type {a.type!r}/{a.componentType!r}"
        )
    if not isinstance(a.count, int) or a.count < 0:
        raise FormatError(path, f"{what}: accessor {index} has a bad count {a.count!r}")
    dtype = np.dtype(COMPONENT_DTYPE[a.componentType]).newbyteorder("<")
    width = TYPE_WIDTH[a.type]
    if a.bufferView is None:
        return np.zeros((a.count, width) if width > 1 else a.count, dtype=dtype.newbyteorder("="))
    views = gltf.bufferViews or []
    v = views[_index(path, f"{what}: bufferView", a.bufferView, len(views))]
    buf = data[_index(path, f"{what}: buffer", v.buffer, len(data))]
    item = dtype.itemsize * width
    stride = v.byteStride or item
    start = (v.byteOffset or 0) + (a.byteOffset or 0)
    need = start + (a.count - 1) * stride + item if a.count else start
    end = (v.byteOffset or 0) + (v.byteLength or 0)
    if stride < item or start < 0 or need > end or end > len(buf):
        raise FormatError(path, f"{what}: accessor {index} reaches past its bufferView or buffer")
    if a.count == 0:
        return np.zeros((0, width) if width > 1 else 0, dtype=dtype.newbyteorder("="))
    raw = np.ndarray(
        (a.count, width), dtype=dtype, buffer=buf, offset=start, strides=(stride, dtype.itemsize)
    )
    out = raw.astype(dtype.newbyteorder("="))
    if a.normalized and a.componentType != 5126:
        out = out.astype(np.float64) / np.iinfo(dtype).max
    return out if width > 1 else out[:, 0]
