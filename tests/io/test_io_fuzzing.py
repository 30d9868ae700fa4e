"""Random bytes and mutated valid files at every reader: a valid groom/animation or FormatError, nothing else.

Deterministic (derandomize=True); the example counts keep the whole module to a few seconds.
"""

from __future__ import annotations

import struct
import tempfile
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from hairtool.errors import FormatError
from hairtool.groom import Animation, Groom
from hairtool.io import read, usd, write

FUZZ = settings(
    derandomize=True,
    max_examples=150,
    deadline=None,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture],
    database=None,
)
_TMP = tempfile.TemporaryDirectory(prefix="hairtool-fuzz-")  # removed when the interpreter exits
WORK = Path(_TMP.name)


def _groom() -> Groom:
    rng = np.random.default_rng(7)
    counts = np.array([2, 5, 3, 4])
    v = int(counts.sum())
    return Groom(
        rng.standard_normal((v, 3)),
        counts,
        thickness=rng.uniform(0.1, 1, v),
        colors=rng.uniform(0, 1, (v, 3)),
    )


def _valid_bytes(ext: str) -> bytes:
    g = _groom()
    p = WORK / f"valid.{ext}"
    if ext == "tfx":  # read-only format: a small TressFX 4 file by hand
        xyzw = np.column_stack([g.points[:8], np.ones(8)]).astype("<f4")
        head = struct.pack("<f7I", 4.0, 2, 4, 160, 0, 0, 160 + 128, 160 + 136) + b"\0" * 128
        return head + xyzw.tobytes() + np.array([0.5, 0.6], "<f4").tobytes() + np.ones(32, "<f4").tobytes()
    if ext == "npz":
        write(p, Animation(np.stack([g.points, g.points * 2]), g.topology, 24, thickness=g.thickness))
    elif ext == "usda":
        usd.write(p, Animation(np.stack([g.points, g.points + 1]), g.topology, 24), time_codes=[0, 3])
    else:
        write(p, g)
    return p.read_bytes()


EXTENSIONS = ("hair", "tfx", "npz", "obj", "usda")
VALID = {ext: _valid_bytes(ext) for ext in EXTENSIONS}
PREFIXES = {
    "hair": b"HAIR",
    "tfx": struct.pack("<f", 4.0),
    "npz": b"PK\x03\x04",
    "obj": b"v 0 0 0\nv 1 1 1\nl ",
    "usda": b"#usda 1.0\n",
}


def _check(ext: str, data: bytes) -> None:
    p = WORK / f"case.{ext}"
    p.write_bytes(data)
    try:
        obj = read(p)
    except FormatError:
        return
    assert isinstance(obj, Groom | Animation)
    pts = obj.frames if isinstance(obj, Animation) else obj.points
    assert pts.dtype == np.float32 and np.all(np.isfinite(pts))


@st.composite
def _mutated(draw, ext: str) -> bytes:
    data = bytearray(VALID[ext])
    for _ in range(draw(st.integers(1, 3))):
        op = draw(st.sampled_from(["flip", "truncate", "field", "insert", "zero"]))
        n = len(data)
        if n == 0:
            break
        at = draw(st.integers(0, n - 1))
        if op == "flip":
            data[at] ^= 1 << draw(st.integers(0, 7))
        elif op == "truncate":
            del data[at:]
        elif op == "field" and n >= 4:
            at = min(at - at % 4, n - 4)
            value = draw(st.sampled_from([0, 1, 2, 0xFFFF, 2**31, 2**32 - 1])) | 0
            data[at : at + 4] = struct.pack("<I", value)
        elif op == "insert":
            data[at:at] = draw(st.binary(min_size=1, max_size=8))
        elif op == "zero":
            data[at : at + draw(st.integers(1, 16))] = b"\0" * min(16, n - at)
    return bytes(data)


@pytest.mark.parametrize("ext", EXTENSIONS)
def test_valid_seed_files_read(ext):
    p = WORK / f"seed.{ext}"
    p.write_bytes(VALID[ext])
    assert isinstance(read(p), Groom | Animation)


@pytest.mark.parametrize("ext", EXTENSIONS)
@FUZZ
@given(data=st.data())
def test_mutated_valid_files(ext, data):
    _check(ext, data.draw(_mutated(ext)))


@pytest.mark.parametrize("ext", EXTENSIONS)
@settings(FUZZ, max_examples=100)
@given(tail=st.binary(max_size=400), with_prefix=st.booleans())
def test_random_bytes(ext, tail, with_prefix):
    _check(ext, (PREFIXES[ext] if with_prefix else b"") + tail)
