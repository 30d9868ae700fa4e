"""Hand-made hostile files, one per class of issue 17 (section 2), shared by the regression tests.

Each builder writes one small file that once escaped the readers' checks: a traceback, a wrong
result or an unbounded allocation.
"""

from __future__ import annotations

import io
import json
import struct
import zipfile
from pathlib import Path

import numpy as np

BEYOND_FLOAT32 = 1e39  # finite in float64, inf once cast to float32


def bvh_chain(depth: int, frames: int = 2, frames_field: str | None = None) -> str:
    """A chain of ``depth`` joints, each one level below the last, with one rotation channel each."""
    lines = ["HIERARCHY"]
    for j in range(depth):
        lines += [f"{'ROOT' if j == 0 else 'JOINT'} j{j}", "{", "OFFSET 0 1 0", "CHANNELS 1 Zrotation"]
    lines += ["End Site", "{", "OFFSET 0 1 0", "}"]
    lines += ["}"] * depth
    lines += ["MOTION", f"Frames: {frames if frames_field is None else frames_field}", "Frame Time: 0.04"]
    lines += [" ".join(str((f * 7 + j) % 30) for j in range(depth)) for f in range(frames)]
    return "\n".join(lines) + "\n"


def write_bvh_frames(path: Path, frames_field: str) -> Path:
    """A two-joint BVH with two frame lines whose ``Frames:`` reads ``frames_field``."""
    path.write_text(bvh_chain(2, 2, frames_field))
    return path


def write_bvh_deep(path: Path, depth: int = 1200) -> Path:
    path.write_text(bvh_chain(depth, frames=3))
    return path


def npz_bytes(**arrays: np.ndarray) -> bytes:
    buf = io.BytesIO()
    np.savez(buf, **arrays)
    return buf.getvalue()


def write_npz_beyond_float32(path: Path, member: str = "points") -> Path:
    """A hairtool cache whose float64 ``member`` holds 1e39: finite, but inf as float32."""
    counts = np.array([2, 3], dtype=np.int64)
    points = np.linspace(0.0, 1.0, 15).reshape(5, 3)
    thickness = np.full(5, 0.1)
    if member == "points":
        points[3, 1] = BEYOND_FLOAT32
    else:
        thickness[2] = BEYOND_FLOAT32
    path.write_bytes(
        npz_bytes(
            format_version=np.array(1, dtype=np.int64),
            kind=np.array("groom"),
            counts=counts,
            points=points,
            thickness=thickness,
        )
    )
    return path


def wrapping_counts(points: int) -> np.ndarray:
    """int64 strand counts, each at least 2, whose int64 sum wraps around to ``points``."""
    return np.array([2**62, 2**62, 2**62, 2**62, points], dtype=np.int64)


def write_npz_wrapping_counts(path: Path) -> Path:
    points = np.arange(30, dtype=np.float32).reshape(10, 3)
    path.write_bytes(
        npz_bytes(
            format_version=np.array(1, dtype=np.int64),
            kind=np.array("groom"),
            counts=wrapping_counts(10),
            points=points,
        )
    )
    return path


def write_hair_claiming_strands(path: Path, strands: int = 2**31) -> Path:
    """A ``.hair`` file without a segments array whose header claims ``strands`` strands of 2 points."""
    points = np.arange(12, dtype="<f4")
    head = struct.pack("<4sIIII", b"HAIR", strands, 4, 2, 1)  # arrays = points only, 1 segment each
    head += struct.pack("<5f", 1.0, 0.0, 1.0, 1.0, 1.0) + b"\0" * 88
    path.write_bytes(head + points.tobytes())
    return path


def npy_header(shape: tuple[int, ...], dtype: str = "<f8") -> bytes:
    """A version 1.0 ``.npy`` header claiming ``shape``."""
    text = f"{{'descr': '{dtype}', 'fortran_order': False, 'shape': {shape!r}, }}"
    text += " " * (-(len(text) + 11) % 64) + "\n"
    return b"\x93NUMPY\x01\x00" + struct.pack("<H", len(text)) + text.encode("latin-1")


def write_npz_huge_feature_header(path: Path, values: int = 10**12) -> Path:
    """An ``.npz`` with a raw array ``X`` whose header claims ``values`` float64s (the data is 80 bytes)."""
    member = npy_header((values // 1000, 1000)) + np.zeros(10).tobytes()
    with zipfile.ZipFile(path, "w", zipfile.ZIP_STORED) as zf:
        zf.writestr("X.npy", member)
    return path


def write_project_beyond_float32(path: Path, member: str = "groom/points.npy") -> Path:
    """A valid project (groom with thickness, an animation), re-written with ``member`` as float64
    holding 1e39."""
    from hairtool.groom import Animation, Groom
    from hairtool.project import MANIFEST, Project, manifest_and_arrays

    g = Groom(np.linspace(0.0, 1.0, 15).reshape(5, 3), [2, 3], thickness=np.full(5, 0.1))
    anim = Animation(np.stack([g.points, g.points + 1]), g.topology, 24.0)
    manifest, arrays = manifest_and_arrays(Project(rest=g, animation=anim))
    bad = arrays[member].astype(np.float64)
    bad.reshape(-1)[1] = BEYOND_FLOAT32
    arrays[member] = bad
    _write_project(path, manifest, arrays, MANIFEST)
    return path


def write_project_wrapping_counts(path: Path) -> Path:
    from hairtool.groom import Groom
    from hairtool.project import MANIFEST, Project, manifest_and_arrays

    g = Groom(np.linspace(0.0, 1.0, 30).reshape(10, 3), [4, 6])
    manifest, arrays = manifest_and_arrays(Project(rest=g))
    arrays["groom/counts.npy"] = wrapping_counts(10)
    _write_project(path, manifest, arrays, MANIFEST)
    return path


def _write_project(path: Path, manifest: dict, arrays: dict[str, np.ndarray], manifest_name: str) -> None:
    with zipfile.ZipFile(path, "w", zipfile.ZIP_STORED) as zf:
        zf.writestr(manifest_name, json.dumps(manifest))
        for name, a in arrays.items():
            buf = io.BytesIO()
            np.lib.format.write_array(buf, a, allow_pickle=False)
            zf.writestr(name, buf.getvalue())


def write_obj_beyond_float32(path: Path) -> Path:
    path.write_text(f"v 0 0 0\nv 1 {BEYOND_FLOAT32!r} 0\nv 2 2 2\nl 1 2 3\n")
    return path


def write_bvh_wide(path: Path, joints: int = 20_000, frames: int = 5_000) -> Path:
    """A root with one channel and ``joints`` - 1 children without channels: a 600 KB file whose
    forward kinematics would hold frames × joints poses (11 GB of float64)."""
    lines = ["HIERARCHY", "ROOT r", "{", "OFFSET 0 0 0", "CHANNELS 1 Zrotation"]
    for j in range(1, joints):
        lines += [f"JOINT j{j}", "{", "OFFSET 0 1 0", "}"]
    lines += ["}", "MOTION", f"Frames: {frames}", "Frame Time: 0.04"] + ["0"] * frames
    path.write_text("\n".join(lines) + "\n")
    return path


# -- issue 27: jobs files, stroke logs and project manifests ------------------------------------
def write_jobs_nested(path: Path, depth: int = 100_000) -> Path:
    """A jobs file whose "jobs" list is nested ``depth`` deep (JSON or TOML by the suffix)."""
    nested = "[" * depth + "]" * depth
    path.write_text('{"jobs": ' + nested + "}" if path.suffix == ".json" else f"jobs = {nested}\n")
    return path


def write_jobs_huge_int(path: Path, digits: int = 5000) -> Path:
    """One job whose argument is an integer of ``digits`` digits (JSON or TOML by the suffix)."""
    number = "9" * digits
    if path.suffix == ".json":
        path.write_text('{"jobs": [{"command": "info", "args": [' + number + "]}]}")
    else:
        path.write_text(f'[[jobs]]\ncommand = "info"\nargs = [{number}]\n')
    return path


def write_jobs_glob(path: Path, pattern: str) -> Path:
    path.write_text(json.dumps({"jobs": [{"glob": pattern, "command": "info", "args": ["{path}"]}]}))
    return path


def stroke(radius: object = 0.5, falloff: object = "smooth") -> dict:
    """One comb stroke of one sample, in a log's JSON form."""
    sample = {"cursor": [0, 0, 0], "direction": [0.1, 0, 0], "radius": radius, "strength": 0.5}
    return {"brush": "comb", "falloff": falloff, "samples": [sample]}


def write_strokes(path: Path, *strokes: dict) -> Path:
    path.write_text(json.dumps(list(strokes)))
    return path


def write_strokes_nested(path: Path, depth: int = 100_000) -> Path:
    path.write_text("[" * depth + "]" * depth)
    return path


def write_project_manifest(path: Path, change) -> Path:
    """A valid project whose manifest ``change(manifest)`` edits (its text, when it returns a str)."""
    from hairtool.groom import Animation, Groom
    from hairtool.project import MANIFEST, Project, manifest_and_arrays

    g = Groom(np.linspace(0.0, 1.0, 30).reshape(10, 3), [4, 6])
    anim = Animation(np.stack([g.points, g.points + 1]), g.topology, 24.0)
    manifest, arrays = manifest_and_arrays(Project(rest=g, animation=anim))
    text = change(manifest)
    with zipfile.ZipFile(path, "w", zipfile.ZIP_STORED) as zf:
        zf.writestr(MANIFEST, text if isinstance(text, str) else json.dumps(manifest))
        for name, a in arrays.items():
            buf = io.BytesIO()
            np.lib.format.write_array(buf, a, allow_pickle=False)
            zf.writestr(name, buf.getvalue())
    return path



# -- issue 27: USD files usd-core warns about, and one of 10^7 widths ---------------------------
USDA_CURVES = """#usda 1.0
(
    upAxis = "Z"
    metersPerUnit = 1
)
def Xform "Head"
{
    double3 xformOp:translate = (0, 0, 1)
    float xformOp:rotateZ.timeSamples = {1: 0, 2: 30}
    uniform token[] xformOpOrder = ["xformOp:translate", "xformOp:rotateZ"]
    def BasisCurves "Hair"
    {
        uniform token type = "linear"
        int[] curveVertexCounts = [4, 3]
        point3f[] points = [(0, 0, 0), (0, 0, 1), (0, 0, 2), (0, 0, 3), (1, 0, 0), (1, 0, 1), (1, 0, 2)]
        float[] widths = [0.1, 0.2] (interpolation = "uniform")
    }
}
"""


def write_usda(path: Path, old: str = "", new: str = "") -> Path:
    """:data:`USDA_CURVES` with ``old`` replaced by ``new`` (once)."""
    assert old in USDA_CURVES
    path.write_text(USDA_CURVES.replace(old, new, 1))
    return path


def write_usda_widths(path: Path, count: int = 10**7) -> Path:
    """Two curves of seven points and ``count`` uniform widths: 20 MB of text for 10^7."""
    widths = "[" + ",".join(["1"] * count) + "]"
    return write_usda(path, "[0.1, 0.2]", widths)


def write_usdc_bad_prim_name(path: Path) -> Path:
    """A crate whose token for the prim name "Head" reads ";-) ", which usd-core warns about."""
    from pxr import Sdf, Usd

    layer = Sdf.Layer.CreateAnonymous(".usda")
    layer.ImportFromString(USDA_CURVES)
    Usd.Stage.Open(layer).Export(str(path))
    data = path.read_bytes()
    assert data.count(b"Head\0") == 1, "usd-core stored the tokens in a way this builder does not know"
    path.write_bytes(data.replace(b"Head\0", b";-) \0"))
    return path


def write_usdc_array_count(path: Path, which: str, count: int = 2**34) -> Path:
    """A crate whose ``which`` array ("points": stored raw; "counts": 100 ints, stored
    compressed) claims ``count`` elements in its u64 length prefix."""
    from pxr import Sdf, Usd

    n = 100
    text = USDA_CURVES.replace("[4, 3]", "[" + ", ".join(["2"] * n) + "]")
    text = text.replace("[0.1, 0.2]", "[" + ", ".join(["0.1"] * n) + "]")
    start = text.index("point3f[] points = [")
    points = ", ".join(f"({i}.5, 0, 0)" for i in range(2 * n))
    text = text[:start] + f"point3f[] points = [{points}" + text[text.index("]\n", start) :]
    layer = Sdf.Layer.CreateAnonymous(".usda")
    layer.ImportFromString(text)
    Usd.Stage.Open(layer).Export(str(path))
    data = bytearray(path.read_bytes())
    prefix = struct.pack("<Q", 2 * n) + struct.pack("<f", 0.5) if which == "points" else struct.pack("<Q", n)
    at = data.find(prefix)
    assert at >= 0 and (which == "points" or data.find(prefix, at + 1) >= 0), "crate layout not as expected"
    data[at : at + 8] = struct.pack("<Q", count)
    path.write_bytes(bytes(data))
    return path
