"""Random bytes and mutated valid files at every reader: a valid groom/animation or FormatError, nothing else.

Deterministic: hypothesis with derandomize=True for the in-process cases, fixed seeds for the
capped children of ``fuzz_harness.py`` (issue 17's mutation classes, every reader).
"""

from __future__ import annotations

import json
import struct
import subprocess
import sys
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


# -- every reader, every mutation class, under a memory cap ---------------------------------------
# tests/io/fuzz_harness.py mutates real and hand-made seed files (bit flips, overwrites,
# truncations, huge header counts, duplicated chunks, token swaps; zip members one by one with
# valid checksums; documents by their structure: deep nesting, huge integers, wrong types,
# ragged lists, control characters, absurd numbers; degenerate and non-finite head meshes; FIFOs
# and devices as .usda layers) and reads each mutant in a child process whose address space is capped at its
# size after imports plus 1 GiB, with fd 2 watched (nothing may print beside the CLI's line).
# The children run side by side; the counts keep the whole
# set near 30 s of wall time on two cores. Rerun one reader by hand with
# ``python tests/io/fuzz_harness.py READER --count N`` (``--only I`` for one mutant).
HARNESS = Path(__file__).with_name("fuzz_harness.py")
MUTANTS = {
    "hair": 1200,
    "tfx": 1200,
    "npz": 1000,
    "obj": 1000,
    "mesh": 800,
    "bvh": 700,
    "project": 1500,
    "keys": 1000,
    "features": 1000,
    "usda": 600,  # usd-core parses slowly; its binary crates have tests/io/test_usd_fuzzing.py
    "strokes": 700,  # these four and project: half of the mutants by their JSON/TOML structure
    "jobs": 700,
    "jobs-toml": 700,
    "edits": 700,
}


@pytest.fixture(scope="module")
def fuzz_reports() -> dict[str, dict]:
    """Start one capped child per reader at once; their JSON reports by reader."""
    children = {
        name: subprocess.Popen(
            [sys.executable, str(HARNESS), name, "--count", str(count), "--seed", "17"],
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
        )
        for name, count in MUTANTS.items()
    }
    reports = {}
    for name, child in children.items():
        try:
            out, err = child.communicate(timeout=240)
        except subprocess.TimeoutExpired:
            child.kill()
            out, err = child.communicate()
            reports[name] = {"hang": True, "stderr": err.decode(errors="replace")[-2000:]}
            continue
        try:
            reports[name] = json.loads(out.decode().strip().splitlines()[-1])
        except (IndexError, ValueError):
            reports[name] = {"crash": child.returncode, "stderr": err.decode(errors="replace")[-2000:]}
    return reports


@pytest.mark.slow(seconds=3)
@pytest.mark.parametrize("reader", sorted(MUTANTS))
def test_every_mutant_is_read_finite_or_refused_in_one_line(fuzz_reports, reader):
    report = fuzz_reports[reader]
    assert "failures" in report, report  # no hang, no crash of the child
    assert report["failures"] == [], "\n".join(json.dumps(f) for f in report["failures"][:10])
    assert report["read"] + report["refused"] == MUTANTS[reader]
    assert report["refused"] > 0 and report["read"] > 0  # the mutants reach both outcomes
    assert min(report["classes"].values()) >= 50, report["classes"]  # every mutation class, often
    assert report["max_rss_mb"] < report["cap_mb"] < 4096
