"""Hostile USD at the reader (issue 17 §2): the only outcomes are a read whose values are finite or
one line of FormatError, exit status 2 from the CLI.

- values of the wrong type (a string, an unregistered type) where points, counts, widths or a
  transform op belong, hand-made and by swapping every declared type of a valid stage;
- a crate whose error is raised lazily, by ``Get()`` after the stage opened;
- mutated crates (bit flips, huge counts, truncations, duplicated chunks, zeroed runs), read in a
  child process whose address space is capped at 1.5 GB, so an allocation from a corrupt header
  cannot take the machine and a crash cannot take the test run.
"""

from __future__ import annotations

import json
import re
import struct
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from hairtool.cli import main
from hairtool.errors import FormatError
from hairtool.groom import Animation, Groom
from hairtool.io import read, write

from .hostile import USDA_CURVES

INTEROP = Path(__file__).resolve().parents[1] / "data" / "interop"

# The hostile module's two-curve stage, made cubic Catmull-Rom with a colour per curve, so every
# declaration the swaps below break is present in the valid file.
VALID_USDA = USDA_CURVES.replace(
    '        uniform token type = "linear"\n',
    '        uniform token type = "cubic"\n'
    '        uniform token basis = "catmullRom"\n'
    '        uniform token wrap = "pinned"\n',
).replace(
    '        float[] widths = [0.1, 0.2] (interpolation = "uniform")\n',
    '        float[] widths = [0.1, 0.2] (interpolation = "uniform")\n'
    '        color4f[] primvars:color = [(1, 0, 0, 1), (0, 1, 0, 1)] (interpolation = "uniform")\n',
)

# (what is declared wrongly, the text that replaces the valid declaration)
HOSTILE = [
    ("points as a string", ("point3f[] points = [", 'string points = "(0, 0, 0)"\n#')),
    ("points of an unregistered type", ("point3f[] points", "foo3f[] points")),
    ("points as numbers", ("point3f[] points = [", "float[] points = [1, 2, 3]\n#")),
    ("counts as a string", ("int[] curveVertexCounts = [4, 3]", 'string curveVertexCounts = "4 3"')),
    ("counts of an unregistered type", ("int[] curveVertexCounts", "count[] curveVertexCounts")),
    ("counts as floats", ("int[] curveVertexCounts", "float[] curveVertexCounts")),
    ("widths as strings", ("float[] widths = [0.1, 0.2]", 'string[] widths = ["a", "b"]')),
    ("widths of an unregistered type", ("float[] widths", "width[] widths")),
    ("translate as a string", ("double3 xformOp:translate = (0, 0, 1)", 'string xformOp:translate = "up"')),
    ("translate of an unregistered type", ("double3 xformOp:translate", "foo3 xformOp:translate")),
    ("translate as one number", ("double3 xformOp:translate = (0, 0, 1)", "double xformOp:translate = 1")),
    (
        "rotateZ as a vector",
        ("float xformOp:rotateZ.timeSamples = {1: 0, 2: 30}", "float3 xformOp:rotateZ = (0, 0, 1)"),
    ),
    ("curve type as a number", ('uniform token type = "cubic"', "uniform int type = 3")),
    ("an unknown transform op", ('["xformOp:translate", "xformOp:rotateZ"]', '["xformOp:banana"]')),
    ("an infinite rotation sample", ("{1: 0, 2: 30}", "{1: 0, 2: inf}")),
    ("metersPerUnit as a string", ("metersPerUnit = 1", 'metersPerUnit = "big"')),
    ("an unknown widths interpolation", ('(interpolation = "uniform")', '(interpolation = "banana")')),
    ("an unknown basis", ('uniform token basis = "catmullRom"', 'uniform token basis = "hermite2"')),
]


def _one_line_error(path, capsys) -> str:
    """``hairtool info`` on ``path`` exits 2 with one line on stderr, naming the file."""
    capsys.readouterr()
    assert main(["info", str(path)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and str(path) in err, err
    return err


def test_the_valid_stage_reads(tmp_path):
    p = tmp_path / "valid.usda"
    p.write_text(VALID_USDA)
    a = read(p)
    assert isinstance(a, Animation) and a.n_frames == 2 and list(a.time_codes) == [1, 2]
    assert a.metadata.curves[0].basis == "catmullRom" and a.colors is not None


@pytest.mark.parametrize(("case", "swap"), HOSTILE, ids=[c for c, _ in HOSTILE])
def test_a_value_of_the_wrong_type_is_one_line(tmp_path, capsys, case, swap):
    old, new = swap
    assert old in VALID_USDA
    p = tmp_path / "hostile.usda"
    p.write_text(VALID_USDA.replace(old, new, 1))
    with pytest.raises(FormatError):
        read(p)
    _one_line_error(p, capsys)


TYPES = [
    "string",
    "token",
    "foo",
    "float",
    "int",
    "int[]",
    "float[]",
    "float3",
    "double3[]",
    "matrix4d",
    "bool[]",
]


def test_every_declared_type_swapped_for_another(tmp_path):
    """Each typed declaration of the valid stage with each other type name: a valid read or a FormatError."""
    decl = re.compile(r"^(\s*(?:uniform )?)(\S+)( \S+ = )", re.M)
    sites = list(decl.finditer(VALID_USDA))
    assert len(sites) >= 9
    outcomes = {"read": 0, "refused": 0}
    for m in sites:
        for t in TYPES:
            if t == m.group(2):
                continue
            text = VALID_USDA[: m.start(2)] + t + VALID_USDA[m.end(2) :]
            p = tmp_path / "swap.usda"
            p.write_text(text)
            try:
                obj = read(p)
            except FormatError as e:
                assert "\n" not in str(e)
                outcomes["refused"] += 1
                continue
            pts = obj.frames if isinstance(obj, Animation) else obj.points
            assert np.all(np.isfinite(pts))
            outcomes["read"] += 1
    assert outcomes["refused"] > outcomes["read"] > 0


def _points_count_offset(data: bytes, points: np.ndarray) -> int:
    """Where a crate stores the element count of ``points`` (the 8 bytes before its raw floats)."""
    at = data.find(points.tobytes())
    assert at >= 8, "usd-core stored the points in a way this test does not know"
    assert struct.unpack_from("<Q", data, at - 8)[0] == len(points)
    return at - 8


@pytest.mark.parametrize("count", [2**31, 2**40, 2**62])
def test_a_crate_whose_error_comes_lazily_from_get(tmp_path, capsys, count):
    from pxr import Usd

    rng = np.random.default_rng(3)
    g = Groom(rng.standard_normal((40, 3)), [10, 10, 20])
    p = tmp_path / "lazy.usdc"
    write(p, g)
    data = bytearray(p.read_bytes())
    at = _points_count_offset(bytes(data), g.points)
    struct.pack_into("<Q", data, at, count)
    p.write_bytes(bytes(data))
    assert Usd.Stage.Open(str(p)) is not None  # the stage opens: usd-core's error comes inside Get()
    with pytest.raises(FormatError, match=f"a crate array at byte {at} claims {count} values"):
        read(p)  # refused from the count before usd-core sizes the array
    _one_line_error(p, capsys)


@pytest.mark.parametrize("which", ["a frame's points", "the sample times"])
def test_a_time_sampled_array_claiming_2_to_the_40_values_is_refused_first(tmp_path, which):
    """Time samples lead by relative jumps to their times and to each frame's value: those counts
    are checked too, before usd-core sizes them."""
    rng = np.random.default_rng(5)
    frames = rng.standard_normal((3, 12, 3)).astype(np.float32)
    p = tmp_path / "anim.usdc"
    write(p, Animation(frames, np.array([4, 8]), 24))
    data = bytearray(p.read_bytes())
    if which == "the sample times":
        times = np.array(sorted(_sample_times(p)), "<f8")
        at = bytes(data).find(struct.pack("<Q", len(times)) + times.tobytes())
    else:
        at = _points_count_offset(bytes(data), frames[2])
    assert at > 0
    struct.pack_into("<Q", data, at, 2**40)
    p.write_bytes(bytes(data))
    with pytest.raises(FormatError, match=f"a crate array at byte {at} claims {2**40} values"):
        read(p)


def _sample_times(path) -> list[float]:
    from pxr import Usd, UsdGeom

    stage = Usd.Stage.Open(str(path))
    curves = next(p for p in stage.Traverse() if p.IsA(UsdGeom.BasisCurves))
    return UsdGeom.BasisCurves(curves).GetPointsAttr().GetTimeSamples()


def _sections(data: bytes) -> dict[str, tuple[int, int]]:
    toc = struct.unpack_from("<Q", data, 16)[0]
    n = struct.unpack_from("<Q", data, toc)[0]
    out = {}
    for i in range(n):
        name, start, size = struct.unpack_from("<16sqq", data, toc + 8 + 32 * i)
        out[name.rstrip(b"\0").decode()] = (start, size)
    return out


@pytest.mark.parametrize("section", ["TOKENS", "STRINGS", "FIELDS", "FIELDSETS", "PATHS", "SPECS"])
def test_a_crate_section_claiming_2_to_the_28_entries_is_refused_before_usd_core_sizes_it(
    tmp_path, capsys, section
):
    """usd-core allocates from these counts first (2.2 GB for TOKENS, 4.3 GB for FIELDS)."""
    p = tmp_path / "seed.usdc"
    _seed_crate(p)
    data = bytearray(p.read_bytes())
    start, _size = _sections(bytes(data))[section]
    struct.pack_into("<Q", data, start, 2**28)
    p.write_bytes(bytes(data))
    with pytest.raises(FormatError, match=f"crate section {section} claims 268435456 entries"):
        read(p)
    _one_line_error(p, capsys)


def test_a_crate_table_of_contents_outside_the_file_is_refused(tmp_path):
    p = tmp_path / "seed.usdc"
    _seed_crate(p)
    data = bytearray(p.read_bytes())
    toc = struct.unpack_from("<Q", data, 16)[0]
    struct.pack_into("<Q", data, toc, 2**40)
    p.write_bytes(bytes(data))
    with pytest.raises(FormatError, match="claims 1099511627776 sections"):
        read(p)
    struct.pack_into("<Q", data, 16, len(data) + 5)
    p.write_bytes(bytes(data))
    with pytest.raises(FormatError, match="lies outside the file"):
        read(p)


def test_real_crates_pass_the_count_checks(tmp_path):
    from hairtool.io import usdc_check

    for name in ("b_xform.usdc", "b_xformanim.usdc", "b_gnanim.usdc"):
        usdc_check.check(INTEROP / name)
    write(tmp_path / "big.usdc", Groom(np.zeros((200_000, 3)) + np.arange(3), np.full(1000, 200)))
    usdc_check.check(tmp_path / "big.usdc")


def _lz4_literals(data: bytes) -> bytes:
    """``data`` as one LZ4 block of literals only (lengths of 15 and more go on in bytes)."""
    n = len(data)
    if n < 15:
        return bytes([n << 4]) + data
    rest, tail = n - 15, b""
    while rest >= 255:
        tail += b"\xff"
        rest -= 255
    return b"\xf0" + tail + bytes([rest]) + data


@settings(max_examples=200, deadline=None)
@given(data=st.binary(max_size=600), repeat=st.integers(1, 300), back=st.integers(1, 8))
def test_the_value_tables_lz4_blocks_decode(data, repeat, back):
    """Literals, then a match of ``back`` bytes repeated (overlapping when shorter than the match)."""
    from hairtool.io.usdc_check import _lz4_block

    assert _lz4_block(Path("f"), _lz4_literals(data), len(data)) == data
    head = bytes(range(1, back + 1))
    m = repeat + 4
    token = (back << 4) | min(m - 4, 15)
    ext = b""
    if m - 4 >= 15:
        rest = m - 4 - 15
        ext = b"\xff" * (rest // 255) + bytes([rest % 255])
    block = bytes([token]) + head + back.to_bytes(2, "little") + ext
    want = head + (head * (m // back + 1))[:m]
    assert _lz4_block(Path("f"), block, len(want)) == want
    with pytest.raises(FormatError, match="LZ4"):
        _lz4_block(Path("f"), block, len(want) - 1)  # never past the table it fills


@settings(max_examples=200, deadline=None)
@given(block=st.binary(max_size=200), limit=st.integers(0, 4096))
def test_any_bytes_as_a_value_table_are_decoded_or_refused(block, limit):
    from hairtool.io.usdc_check import _lz4_block

    try:
        out = _lz4_block(Path("f"), block, limit)
    except FormatError as e:
        assert "LZ4" in str(e)
    else:
        assert len(out) <= limit


# -- mutated crates in a memory-capped child -----------------------------------------------
CHILD = textwrap.dedent(
    """
    import json, random, resource, sys, time
    from pathlib import Path

    cap = int(sys.argv[4])
    resource.setrlimit(resource.RLIMIT_AS, (cap, cap))
    import numpy as np
    from hairtool.errors import FormatError
    from hairtool.groom import Animation
    from hairtool.io import read

    seed_path, work, n = Path(sys.argv[1]), Path(sys.argv[2]), int(sys.argv[3])
    base = seed_path.read_bytes()
    rng = random.Random(17)
    HUGE = [0, 1, 0xFFFF, 2**31, 2**32 - 1, 2**40, 2**63 - 1]
    for i in range(n):
        d = bytearray(base)
        for _ in range(rng.randint(1, 3)):
            op = rng.choice(["flip", "field32", "field64", "truncate", "duplicate", "zero"])
            at = rng.randrange(len(d))
            if op == "flip":
                d[at] ^= 1 << rng.randrange(8)
            elif op == "field32":
                d[at:at + 4] = (rng.choice(HUGE) % 2**32).to_bytes(4, "little")
            elif op == "field64":
                d[at:at + 8] = rng.choice(HUGE).to_bytes(8, "little")
            elif op == "truncate":
                del d[max(at, 1):]
            elif op == "duplicate":
                size = rng.randint(8, 256)
                d[at:at] = d[rng.randrange(len(d)):][:size]
            else:
                d[at:at + rng.randint(1, 64)] = bytes(min(64, len(d) - at))
        p = work / f"case{i % 2}.usdc"
        p.write_bytes(bytes(d))
        t = time.perf_counter()
        try:
            obj = read(p)
            pts = obj.frames if isinstance(obj, Animation) else obj.points
            outcome = "read" if np.all(np.isfinite(pts)) else "non-finite"
            message = ""
        except FormatError as e:
            outcome, message = "refused", str(e)
        except BaseException as e:
            outcome, message = "escaped", f"{type(e).__name__}: {e}"
        rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
        print(json.dumps({"case": i, "outcome": outcome, "message": message,
                          "seconds": time.perf_counter() - t, "max_rss_kb": rss}), flush=True)
    """
)
MEMORY_CAP = 1536 << 20


def _seed_crate(path) -> None:
    """A crate with what readers meet in the wild: a turning parent, cubic curves, widths, colour."""
    from pxr import Sdf, Usd

    layer = Sdf.Layer.CreateAnonymous(".usda")
    layer.ImportFromString(VALID_USDA)
    stage = Usd.Stage.Open(layer)
    stage.Export(str(path))


@pytest.mark.slow(seconds=3)
def test_mutated_crates_in_a_memory_capped_child(tmp_path):
    seed = tmp_path / "seed.usdc"
    _seed_crate(seed)
    assert isinstance(read(seed), Animation)
    proc = subprocess.run(
        [sys.executable, "-c", CHILD, str(seed), str(tmp_path), "120", str(MEMORY_CAP)],
        capture_output=True,
        timeout=120,
    )
    # A crash report on stderr may quote the corrupt bytes: decode leniently.
    out, err = (b.decode("utf-8", "replace") for b in (proc.stdout, proc.stderr))
    results = [json.loads(line) for line in out.splitlines() if line.startswith("{")]
    last = results[-1]["case"] if results else None
    assert proc.returncode == 0, f"the child died after case {last}: {err[-2000:]}"
    assert err == "", err[:2000]  # usd-core's warnings ("Invalid prim name") are the reader's to fold
    assert len(results) == 120
    escaped = [r for r in results if r["outcome"] in ("escaped", "non-finite")]
    assert not escaped, escaped[:3]
    assert all("\n" not in r["message"] for r in results)
    kinds = {r["outcome"] for r in results}
    assert kinds == {"read", "refused"}  # the mutations reach both outcomes
