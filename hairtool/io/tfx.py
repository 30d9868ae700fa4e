"""AMD TressFX ``.tfx`` (read only), versions 3 and 4; every strand has the same vertex count.

Telling the versions apart: byte 0 is a float32 version, 3.0 or 4.0 in the real files (AMD's
viewers and exporters write exactly these). We accept any version in [3, 5) and branch on its
integer part, then check the chosen layout against the file size, so a wrong guess is a clear
FormatError rather than garbage:

- TressFX 4: ``f32 version; u32 numHairStrands, numVerticesPerStrand, offsetVertexPosition,
  offsetStrandUV, offsetVertexUV, offsetStrandThickness, offsetVertexColor; u32 reserved[32]``
  (160 bytes). Positions are float4 per vertex (w = 0 pinned, 1 free); thickness is one f32
  per strand, colour a float4 (RGBA) per vertex; offset 0 means absent.
- TressFX 3: ``f32 version; u32 numGuideStrands, numVerticesPerStrand, numFollowStrandsPerGuide;
  i32 bothEndsImmovable; u32 reserved1[31]; u32 verticesOffset, …`` with the offsets from byte
  144. Positions are float3 per vertex at verticesOffset. (Its other arrays — thickness
  coefficients, rest lengths, … — are simulation data and are not read.)
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from hairtool.errors import FormatError
from hairtool.groom import Groom
from hairtool.io.binary import array_at, read_bytes, require_finite, require_size
from hairtool.metadata import Metadata

V4_HEADER_SIZE = 160
V3_OFFSETS_AT = 144
V3_HEADER_SIZE = 148  # up to and including verticesOffset
MAX_VERTICES_PER_STRAND = 64


def _version(path: Path, data: bytes) -> int:
    version = float(np.frombuffer(data, "<f4", count=1)[0])
    if not (np.isfinite(version) and 3.0 <= version < 5.0):
        raise FormatError(path, f"not a TressFX 3 or 4 file (version field reads {version!r})")
    return int(version)


def _sizes(path: Path, strands: int, per_strand: int) -> tuple[int, int]:
    if strands == 0:
        raise FormatError(path, "the file holds no strands")
    if not 2 <= per_strand <= MAX_VERTICES_PER_STRAND:
        raise FormatError(
            path, f"{per_strand} vertices per strand; TressFX allows 2..{MAX_VERTICES_PER_STRAND}"
        )
    return strands, per_strand


def _optional(path: Path, data: bytes, offset: int, dtype: str, count: int) -> np.ndarray | None:
    """An optional array: used when its offset is non-zero, in range and its values are finite."""
    if offset == 0:
        return None
    try:
        a = array_at(path, data, offset, dtype, count, "optional array")
    except FormatError:
        return None
    return a if np.all(np.isfinite(a)) else None


def _read_v4(path: Path, data: bytes) -> Groom:
    require_size(path, data, V4_HEADER_SIZE, "TressFX 4")
    h = [int(x) for x in np.frombuffer(data, "<u4", count=7, offset=4)]
    strands, per_strand = _sizes(path, h[0], h[1])
    off_pos, _off_suv, _off_vuv, off_thick, off_color = h[2:7]
    if off_pos < V4_HEADER_SIZE:
        raise FormatError(
            path, f"vertex positions at byte {off_pos}, inside the {V4_HEADER_SIZE}-byte header"
        )
    v = strands * per_strand
    xyzw = array_at(path, data, off_pos, "<f4", 4 * v, "vertex positions").reshape(v, 4)
    points = xyzw[:, :3]
    require_finite(path, points, "vertex positions")
    attrs: dict[str, np.ndarray] = {}
    thick = _optional(path, data, off_thick, "<f4", strands)
    if thick is not None:
        attrs["thickness"] = np.repeat(thick, per_strand)
    color = _optional(path, data, off_color, "<f4", 4 * v)
    if color is not None:
        attrs["colors"] = color.reshape(v, 4)[:, :3]
    return Groom(points, np.full(strands, per_strand, dtype=np.int64), **attrs)


def _read_v3(path: Path, data: bytes) -> Groom:
    require_size(path, data, V3_HEADER_SIZE, "TressFX 3")
    strands_raw, per_strand_raw = (int(x) for x in np.frombuffer(data, "<u4", count=2, offset=4))
    strands, per_strand = _sizes(path, strands_raw, per_strand_raw)
    off_pos = int(np.frombuffer(data, "<u4", count=1, offset=V3_OFFSETS_AT)[0])
    if off_pos < V3_HEADER_SIZE:
        raise FormatError(path, f"vertex positions at byte {off_pos}, inside the header")
    v = strands * per_strand
    points = array_at(path, data, off_pos, "<f4", 3 * v, "vertex positions").reshape(v, 3)
    require_finite(path, points, "vertex positions")
    return Groom(points, np.full(strands, per_strand, dtype=np.int64), metadata=Metadata())  # Y-up cm


def read(path: Path) -> Groom:
    """Read the guide strands of a TressFX 3 or 4 file (follow strands are generated at runtime).

    Parameters
    ----------
    path : Path
        A ``.tfx`` file.

    Returns
    -------
    Groom
        Its guide strands.
    """
    data = read_bytes(path, 12, "TressFX")
    return _read_v4(path, data) if _version(path, data) == 4 else _read_v3(path, data)
