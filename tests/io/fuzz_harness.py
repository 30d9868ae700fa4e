"""Seeded mutation fuzzing of every reader, meant to run in a child process under a memory cap.

    python tests/io/fuzz_harness.py READER [--count N] [--seed S] [--only I]

prints one JSON object: how many mutants were read, refused and failed, and for each failure
the mutant's index (rerun it alone with ``--only``), its mutations and what escaped. The only
acceptable outcomes are a read whose values are finite and consistent, or one
:class:`~hairtool.errors.HairtoolError` on one line (a FormatError naming the file). Anything
else fails: another exception, any warning (an overflow in a cast, numpy's notes), a message
of several lines, or an allocation the cap refused (a MemoryError anywhere in the error's chain: the
address space is capped at what the process uses after its imports plus 1 GiB).

Mutations, 1 to 3 per mutant, each from its own ``default_rng([seed, index])``: bit flips,
overwrites, truncations (and cut-out spans), huge or edge header counts (binary words, or
numeric tokens in text), duplicated chunks and token swaps (two words of text, two 4-byte
words of binary). Zip formats (.npz, projects) are also mutated member by member and zipped
again with valid checksums, so mutations reach the readers' own checks rather than zip's CRC:
a ``.npy`` member's header tokens (shapes, dtypes) or its data (counts, coordinates); members
are duplicated, dropped and swapped there too.

Documents (stroke logs, IK edit files, jobs files in JSON and TOML, a project's manifest) are
also mutated by their structure, half of their mutants: a value is parsed out and replaced by
itself nested 65 to 100,000 levels deep (in lists, objects, or in TOML a dotted key), by an
integer of 20 to 5,000 digits (in TOML also hex, octal and binary), by a value of another type,
by an absurd number (radii and spacings of 1e200 or 5e-324), a name or string gets a control
character, or a list is made ragged (an element dropped, added, turned into a scalar or a list)
or 5,000 long. Head meshes also get degenerate faces (``f 1 1 4``, three points on a line) and
non-finite vertices, and each good read is projected onto; ``.usda`` stages also get sublayers,
references and payloads that are a FIFO, a device or a folder (issue 45). Whatever a reader (or
usd-core beneath it) prints on fd 2 is a failure too: the CLI's one line is the only line.

The CI run is bounded (tests/io/test_io_fuzzing.py: about 30 s on two cores). The longer run
that goes with a change to a reader, 20 times the mutants under other seeds::

    for r in edits jobs jobs-toml mesh strokes usda project bvh; do
        python tests/io/fuzz_harness.py $r --count 10000 --seed 45 & done; wait
"""

from __future__ import annotations

import argparse
import atexit
import contextlib
import io
import json
import math
import os
import re
import resource
import struct
import sys
import tempfile
import tomllib
import traceback
import warnings
import zipfile
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

TEST_DATA = Path(__file__).resolve().parents[1] / "data"

EDGE_INTS = (0, 1, 2, 3, 0xFFFF, 0x10000, 2**28, 2**31 - 1, 2**31, 2**32 - 1, 2**62, 2**63 - 1, 2**64 - 1)
EDGE_TOKENS = (
    b"0", b"-1", b"1", b"2", b"65536", b"2147483648", b"4294967296", b"4611686018427387904",
    b"9223372036854775807", b"18446744073709551616", b"1" + b"0" * 40, b"9" * 5000, b"1e39",
    b"-3.5e38", b"1e308", b"1e400", b"-1e400", b"nan", b"NaN", b"inf", b"-inf", b"0.5", b"1e-320",
)  # fmt: skip
HEADER_BYTES = 256  # half the positions fall here, where counts and offsets live


# -- mutations ---------------------------------------------------------------------------------
def _pos(rng: np.random.Generator, n: int) -> int:
    if n <= 1:
        return 0
    if rng.random() < 0.5:
        return int(rng.integers(0, min(n, HEADER_BYTES)))
    return int(rng.integers(0, n))


def _flip(rng, data: bytearray, text: bool) -> str:
    for _ in range(int(rng.integers(1, 9))):
        data[_pos(rng, len(data))] ^= 1 << int(rng.integers(0, 8))
    return "flip"


def _overwrite(rng, data: bytearray, text: bool) -> str:
    at, k = _pos(rng, len(data)), int(rng.integers(1, 17))
    data[at : at + k] = rng.bytes(k)
    return "overwrite"


def _truncate(rng, data: bytearray, text: bool) -> str:
    at = _pos(rng, len(data))
    if rng.random() < 0.5:
        del data[at:]
        return "truncate"
    del data[at : at + int(rng.integers(1, 65))]
    return "cut"


_NUMBER = re.compile(rb"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?")
_WORD = re.compile(rb"\S+")


def _huge(rng, data: bytearray, text: bool) -> str:
    if text:
        numbers = list(_NUMBER.finditer(data))
        if numbers:
            m = numbers[int(rng.integers(0, len(numbers)))]
            data[m.start() : m.end()] = EDGE_TOKENS[int(rng.integers(0, len(EDGE_TOKENS)))]
            return "huge-token"
    value = EDGE_INTS[int(rng.integers(0, len(EDGE_INTS)))]
    width = 8 if value >= 2**32 or rng.random() < 0.25 else 4
    at = _pos(rng, len(data)) // 4 * 4
    data[at : at + width] = (value % 2 ** (8 * width)).to_bytes(width, "little")
    return f"huge-{width * 8}"


def _duplicate(rng, data: bytearray, text: bool) -> str:
    n = len(data)
    if n == 0:
        return "duplicate-none"
    a = _pos(rng, n)
    k = int(rng.integers(1, max(2, min(n - a, 64 if rng.random() < 0.7 else n // 4 + 2))))
    chunk = bytes(data[a : a + k])
    at = a + k if rng.random() < 0.5 else int(rng.integers(0, n + 1))
    data[at:at] = chunk
    return "duplicate"


def _swap(rng, data: bytearray, text: bool) -> str:
    if text:
        words = list(_WORD.finditer(data))
        if len(words) >= 2:
            i, j = sorted(int(x) for x in rng.choice(len(words), 2, replace=False))
            a, b = words[i], words[j]
            data[:] = data[: a.start()] + b.group() + data[a.end() : b.start()] + a.group() + data[b.end() :]
            return "swap-words"
    if len(data) >= 8:
        i, j = (_pos(rng, len(data) - 3) for _ in range(2))
        wi, wj = bytes(data[i : i + 4]), bytes(data[j : j + 4])
        data[i : i + 4], data[j : j + 4] = wj, wi
    return "swap-4"


OPS = (_flip, _overwrite, _truncate, _huge, _duplicate, _swap)


def mutate_bytes(rng: np.random.Generator, data: bytes, text: bool) -> tuple[bytes, list[str]]:
    out = bytearray(data)
    names = []
    for _ in range(int(rng.integers(1, 4))):
        if not out:
            break
        names.append(OPS[int(rng.integers(0, len(OPS)))](rng, out, text))
    return bytes(out), names


def _mutate_member(rng: np.random.Generator, content: bytes) -> tuple[bytes, list[str]]:
    """A ``.npy`` member: its header as text (shape and dtype tokens: huge counts, swaps) or its
    data as bytes (counts and coordinates); anything else (the manifest) as text."""
    if content.startswith(b"\x93NUMPY") and len(content) >= 10:
        size = 2 if content[6] == 1 else 4
        end = 8 + size + int.from_bytes(content[8 : 8 + size], "little")
        head, data = content[:end], content[end:]
        r = rng.random()
        if r < 0.3:
            head = bytearray(head)
            return bytes(head) + data, [_huge(rng, head, True)]
        if r < 0.4:
            head = bytearray(head)
            return bytes(head) + data, [_swap(rng, head, True)]
        if r < 0.5:
            return mutate_bytes(rng, content, text=True)
        new, ops = mutate_bytes(rng, data, text=False)
        return head + new, ops
    return mutate_bytes(rng, content, text=True)


def _members(data: bytes) -> list[tuple[str, int, bytes]]:
    with zipfile.ZipFile(io.BytesIO(data)) as zf:
        return [(i.filename, i.compress_type, zf.read(i)) for i in zf.infolist()]


def _zip(members: list[tuple[str, int, bytes]]) -> bytes:
    buf = io.BytesIO()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # "Duplicate name" is the point
        with zipfile.ZipFile(buf, "w") as zf:
            for name, kind, content in members:
                zf.writestr(zipfile.ZipInfo(name, (2020, 1, 1, 0, 0, 0)), content, compress_type=kind)
    return buf.getvalue()


def mutate_zip(rng: np.random.Generator, data: bytes) -> tuple[bytes, list[str]]:
    """Mutate inside the members (the .npy headers as text, so shapes get huge) and zip again."""
    members = _members(data)
    names: list[str] = []
    for _ in range(int(rng.integers(1, 3))):
        k = int(rng.integers(0, len(members)))
        name, kind, content = members[k]
        r = rng.random()
        if r < 0.1 and len(members) > 1:
            members.pop(k)
            names.append(f"drop {name}")
        elif r < 0.2:
            members.insert(int(rng.integers(0, len(members) + 1)), (name, kind, content))
            names.append(f"duplicate {name}")
        elif r < 0.3 and len(members) > 1:
            j = int(rng.integers(0, len(members)))
            members[k], members[j] = (name, kind, members[j][2]), (members[j][0], members[j][1], content)
            names.append(f"swap {name} {members[k][0]}")
        else:
            new, ops = _mutate_member(rng, content)
            members[k] = (name, kind, new)
            names.append(f"{name}: {'+'.join(ops)}")
    return _zip(members), names


# -- structure-aware mutations of documents ------------------------------------------------------
STRUCTURE_CLASSES = (
    "deep nesting", "huge integer", "wrong type", "ragged array", "control character", "absurd number",
)  # fmt: skip
NESTING = (65, 1000, 100_000)
HUGE_INTEGERS = ("1" + "0" * 19, "18446744073709551616", "9" * 41, "1" + "0" * 400, "-" + "9" * 5000)
#: TOML integers in other bases: Python reads any length in base 16, 8 or 2 (issue 45).
HUGE_BASED = ("0x" + "f" * 4301, "0o" + "7" * 60, "0b" + "1" * 200, "0x" + "dead_beef_" * 10 + "1")
#: Numbers in range for the parser, absurd for the method: brush radii, spacings, targets (issue 45).
ABSURD_NUMBERS = (1e200, -1e200, 1e6, 1e-200, 5e-324, 1.7976931348623157e308, 0.001, 0.0)
#: Characters that split a one-line message or drive a terminal.
CONTROL = ("\n", "\r", "\x1b[2J", "\x00", "\x7f", "\x85", "\u009b", "\t")
OTHER_TYPES = ("text", True, None, {}, [], 3.5, -0.0, [1, "a"], {"x": {"y": []}}, float("inf"))


def _nodes(tree) -> list[tuple[tuple, object]]:
    """Every (path, value) of a parsed document, without recursion."""
    out, stack = [], [((), tree)]
    while stack:
        path, v = stack.pop()
        out.append((path, v))
        if isinstance(v, dict):
            stack.extend(((*path, k), c) for k, c in v.items())
        elif isinstance(v, list):
            stack.extend(((*path, i), c) for i, c in enumerate(v))
    return out


def _put(tree, path: tuple, value):
    if not path:
        return value
    parent = tree
    for k in path[:-1]:
        parent = parent[k]
    parent[path[-1]] = value
    return tree


def _toml_value(v) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if v is None:
        return "1979-05-27T07:32:00Z"  # TOML has no null: a datetime, another wrong type
    if isinstance(v, float):
        return "nan" if v != v else "inf" if v == math.inf else "-inf" if v == -math.inf else repr(v)
    if isinstance(v, int):
        return str(v)
    if isinstance(v, str):
        return json.dumps(v)  # a JSON string is a TOML basic string
    if isinstance(v, list):
        return "[" + ", ".join(_toml_value(x) for x in v) + "]"
    return "{" + ", ".join(f"{json.dumps(str(k))} = {_toml_value(x)}" for k, x in v.items()) + "}"


def _dump(tree, toml: bool) -> str:
    if not toml:
        return json.dumps(tree)
    table = tree if isinstance(tree, dict) else {"value": tree}
    return "".join(f"{json.dumps(str(k))} = {_toml_value(v)}\n" for k, v in table.items())


def _nested(rng, inner: str, depth: int, toml: bool) -> tuple[str, str]:
    r = rng.random()
    if toml and r < 0.3:  # an inline table of one dotted key: tomllib nests a table per part
        return "{" + ".".join(["a"] * depth) + " = " + inner + "}", f"nest-key-{depth}"
    if r < 0.6:
        return "[" * depth + inner + "]" * depth, f"nest-list-{depth}"
    key = "a = " if toml else '"a": '
    return ("{" + key) * depth + inner + "}" * depth, f"nest-object-{depth}"


def mutate_document(rng: np.random.Generator, data: bytes, toml: bool) -> tuple[bytes, list[str]]:
    """1 or 2 structure mutations of a JSON or TOML document (module docstring)."""
    tree = tomllib.loads(data.decode()) if toml else json.loads(data)
    raw: dict[str, str] = {}  # placeholder string -> the text it stands for
    ops = []
    for k in range(int(rng.integers(1, 3))):
        nodes = _nodes(tree)
        kind = int(rng.integers(0, 6))
        if kind == 0:  # deep nesting of a value
            path, value = nodes[int(rng.integers(0, len(nodes)))]
            hole = f"\x00hole{k}\x00"
            depth = NESTING[int(rng.integers(0, len(NESTING)))]
            raw[hole], op = _nested(rng, _dump(value, False) if not toml else _toml_value(value), depth, toml)
            tree = _put(tree, path, hole)
        elif kind == 1:  # an integer of many digits, where a number is if there is one
            numbers = [n for n in nodes if isinstance(n[1], int | float) and not isinstance(n[1], bool)]
            path, _ = (numbers or nodes)[int(rng.integers(0, len(numbers or nodes)))]
            hole = f"\x00hole{k}\x00"
            based = toml and rng.random() < 0.4
            pool = HUGE_BASED if based else HUGE_INTEGERS
            raw[hole] = pool[int(rng.integers(0, len(pool)))]
            op = f"bigint-{len(raw[hole].lstrip('-'))}"
            tree = _put(tree, path, hole)
        elif kind == 2:  # a value of another type
            path, _ = nodes[int(rng.integers(0, len(nodes)))]
            other = OTHER_TYPES[int(rng.integers(0, len(OTHER_TYPES)))]
            tree = _put(tree, path, json.loads(json.dumps(other)))
            op = f"type-{type(other).__name__}"
        elif kind == 4:  # a control character in a name (a key) or a string
            strings = [n for n in nodes if isinstance(n[1], str)]
            keyed = [n for n in nodes if isinstance(n[1], dict) and n[1]]
            char = CONTROL[int(rng.integers(0, len(CONTROL)))]
            if keyed and (not strings or rng.random() < 0.4):
                path, value = keyed[int(rng.integers(0, len(keyed)))]
                key = list(value)[int(rng.integers(0, len(value)))]
                cut = int(rng.integers(0, len(str(key)) + 1))
                value[str(key)[:cut] + char + str(key)[cut:]] = value.pop(key)
            elif strings:
                path, value = strings[int(rng.integers(0, len(strings)))]
                cut = int(rng.integers(0, len(value) + 1))
                tree = _put(tree, path, value[:cut] + char + value[cut:])
            op = "control-" + repr(char)[1:-1]
        elif kind == 5:  # an absurd number where a number is
            numbers = [n for n in nodes if isinstance(n[1], int | float) and not isinstance(n[1], bool)]
            if not numbers:
                ops.append("absurd-none")
                continue
            path, _ = numbers[int(rng.integers(0, len(numbers)))]
            value = ABSURD_NUMBERS[int(rng.integers(0, len(ABSURD_NUMBERS)))]
            tree = _put(tree, path, value)
            op = f"absurd-{value:g}"
        else:  # a ragged (or a very long) list
            lists = [n for n in nodes if isinstance(n[1], list) and n[1]]
            if not lists:
                ops.append("ragged-none")
                continue
            inner = [n for n in lists if any(isinstance(x, list) for x in n[1])]
            path, value = (inner or lists)[int(rng.integers(0, len(inner or lists)))]
            i = int(rng.integers(0, len(value)))
            r = rng.random()
            if isinstance(value[i], list) and r < 0.3 and value[i]:
                value[i].pop()
                op = "ragged-short"
            elif isinstance(value[i], list) and r < 0.6:
                value[i].append(value[i][-1] if value[i] else 0)
                op = "ragged-long"
            elif r < 0.8:
                value[i] = [value[i]] if not isinstance(value[i], list) else 0.5
                op = "ragged-mixed"
            else:
                value.extend([value[i]] * 5000)
                op = "ragged-5000"
        ops.append(op)
    text = _dump(tree, toml)
    for hole, replacement in raw.items():
        text = text.replace(json.dumps(hole), replacement, 1)
    return text.encode(), ops


def mutate_manifest(rng: np.random.Generator, data: bytes) -> tuple[bytes, list[str]]:
    """A project's manifest.json mutated by its structure, the archive zipped again."""
    members = _members(data)
    k = next(i for i, m in enumerate(members) if m[0] == "manifest.json")
    name, kind, content = members[k]
    new, ops = mutate_document(rng, content, toml=False)
    members[k] = (name, kind, new)
    return _zip(members), [f"{name}: {'+'.join(ops)}"]


# -- geometry and layers: what real heads and pipelines hold (issue 45) ---------------------------
_FACE = re.compile(rb"(?m)^f[ \t]+(\S+)[ \t]+(\S+)[ \t]+(\S+)")
_VERTEX = re.compile(rb"(?m)^v[ \t]+\S+[ \t]+\S+[ \t]+\S+")


def mutate_geometry(rng: np.random.Generator, data: bytes) -> tuple[bytes, list[str]]:
    """A degenerate face (a corner repeated, as ``f 1 1 4`` in real heads, or three vertices on
    a line), or a vertex made non-finite."""
    out = bytearray(data)
    faces = list(_FACE.finditer(out))
    r = rng.random()
    if faces and r < 0.7:
        m = faces[int(rng.integers(0, len(faces)))]
        a, b, c = m.group(1), m.group(2), m.group(3)
        choice = int(rng.integers(0, 3))
        line = (b"f %s %s %s" % (a, a, c), b"f %s %s %s" % (a, b, b), b"f %s %s %s" % (c, b, c))[choice]
        out[m.start() : m.end()] = line
        return bytes(out), ["degenerate-face"]
    if r < 0.85:
        out += b"\nv 0 0 0\nv 1 1 1\nv 2 2 2\nf -3 -2 -1\n"  # three points on a line
        return bytes(out), ["degenerate-line"]
    vertices = list(_VERTEX.finditer(out))
    if vertices:
        m = vertices[int(rng.integers(0, len(vertices)))]
        bad = (b"nan", b"inf", b"-inf", b"1e39")[int(rng.integers(0, 4))]
        out[m.start() : m.end()] = b"v 0 %s 0" % bad
    return bytes(out), ["degenerate-nonfinite"]


#: Where ``special`` layers point: set up by :func:`run` in its working folder.
SPECIAL_TARGETS = ["/dev/zero", "/dev/null", "/dev/urandom", "fifo.usda", "folder.usda"]


def mutate_layers(rng: np.random.Generator, data: bytes) -> tuple[bytes, list[str]]:
    """A sublayer, reference or payload that is a FIFO, a device or a folder (usd-core blocked
    forever on a FIFO)."""
    target = SPECIAL_TARGETS[int(rng.integers(0, len(SPECIAL_TARGETS)))].encode()
    r = rng.random()
    head = data.find(b"(\n")
    if r < 0.5 and head >= 0:
        out = data[: head + 2] + b"    subLayers = [@" + target + b"@]\n" + data[head + 2 :]
        return out, ["special-sublayer"]
    arc = b"references" if r < 0.8 else b"payload"
    out = data + b'\ndef Xform "extra" (\n    ' + arc + b" = @" + target + b"@\n)\n{\n}\n"
    return out, [f"special-{arc.decode()}"]


# -- the readers and what a good read looks like -------------------------------------------------
def _finite(*arrays) -> None:
    for a in arrays:
        if a is not None:
            assert np.all(np.isfinite(a)), "a read value is not finite"


def _check_groom(obj) -> None:
    from hairtool.groom import Animation, Groom

    assert isinstance(obj, Groom | Animation), type(obj)
    pts = obj.frames if isinstance(obj, Animation) else obj.points
    assert pts.dtype == np.float32 and pts.shape[-2] == int(obj.counts.sum()) == obj.vertex_count
    assert obj.counts.min() >= 2
    _finite(pts, *obj.attributes.values())


def _check_mesh(mesh) -> None:
    assert mesh.faces.min() >= 0 and mesh.faces.max() < len(mesh.vertices)
    _finite(mesh.vertices, mesh.normals)
    from hairtool.errors import HairtoolError
    from hairtool.guides.surface import MeshSurface

    try:  # a head the brushes slide on: projecting onto it never divides by a degenerate face
        surface = MeshSurface(mesh)
    except HairtoolError:
        return
    lo, hi = mesh.vertices.min(axis=0), mesh.vertices.max(axis=0)
    pts = np.random.default_rng(0).uniform(lo - 1, hi + 1, (64, 3))
    q, n = surface.project(pts)
    _finite(q, n)


def _check_motion(m) -> None:
    _finite(m.values, m.offsets, m.end_offsets, m.joint_positions(end_sites=True))
    assert math.isfinite(m.fps) and m.fps > 0


def _check_project(p) -> None:
    _check_groom(p.rest)
    if p.animation is not None:
        _check_groom(p.animation)
    if p.aligned is not None:
        _check_groom(p.aligned)
    for s in p.strokes:
        _finite(np.array([*s.cursor, s.radius, s.intensity]))


def _check_keys(record) -> None:
    assert isinstance(record, dict) and record["frames"] >= 1 and math.isfinite(record["fps"])


def _check_features(x) -> None:
    assert x.dtype == np.float64 and x.ndim == 2 and x.shape[0] >= 2
    _finite(x)


def _read_any(path: Path):
    from hairtool.io import read

    return read(path)


def _read_mesh(path: Path):
    from hairtool.io.obj import read_mesh

    return read_mesh(path)


def _read_bvh(path: Path):
    from hairtool.mocap.bvh import read_bvh

    return read_bvh(path)


def _read_project(path: Path):
    from hairtool.project import load

    return load(path)


def _read_keys(path: Path):
    from hairtool.keys.export import read_keys_json

    return read_keys_json(path)


def _read_features(path: Path):
    from hairtool.io.npz import read_feature_array

    return read_feature_array(path)


def _read_strokes(path: Path):
    from hairtool.frozen.strokes import read_strokes

    return read_strokes(path)


def _check_strokes(strokes) -> None:
    from hairtool.frozen.strokes import Stroke

    assert isinstance(strokes, list) and all(isinstance(s, Stroke) for s in strokes)
    for s in strokes:
        for sample in s.pipeline_samples(0.0):
            _finite(np.array([*sample.cursor, sample.radius]))


def _chain_motion():
    from hairtool.mocap.bvh import read_bvh

    with tempfile.TemporaryDirectory() as tmp:
        p = Path(tmp) / "chain.bvh"
        p.write_bytes(_seed_bvh(Path(tmp))[0])
        return read_bvh(p)


_MOTION: list = []


def _read_edits(path: Path):
    """An IK edit file read against the chain capture (its IK solves: the reproducer tests)."""
    from hairtool.mocap.pose_edit import read_edits

    if not _MOTION:
        _MOTION.append(_chain_motion())
    return read_edits(path, _MOTION[0])


def _check_edits(reports) -> None:
    assert isinstance(reports, list)


def _seed_edits(work: Path) -> list[bytes]:
    reach = [{"frame": 2, "joint": "knee", "target": [0.5, 2.5, 0.5], "chain": 1}]
    far = {"edits": [{"frame": 0, "joint": "knee", "target": [0, 40, 0], "chain": 1},
                     {"frame": 2, "joint": "knee", "target": [0.0, -3.0, 0.0], "chain": 1}]}  # fmt: skip
    return [json.dumps(reach).encode(), json.dumps(far, indent=1).encode()]


def _read_jobs(path: Path):
    from hairtool.farm.jobs import load_jobs

    return load_jobs(path)


def _check_jobs(jobs) -> None:
    from hairtool.farm.jobs import Job

    assert jobs and all(isinstance(j, Job) for j in jobs)
    assert all(isinstance(a, str) for j in jobs for a in j.argv)


@dataclass(frozen=True)
class Reader:
    ext: str
    seeds: Callable[[Path], list[bytes]]
    read: Callable[[Path], object]
    check: Callable[[object], None]
    text: bool = False
    zipped: bool = False
    structured: bool = False  # a JSON or TOML document (a zip's manifest.json): structure mutations too
    #: a mutation of its own, a quarter of the mutants: degenerate geometry, special layers
    special: Callable[[np.random.Generator, bytes], tuple[bytes, list[str]]] | None = None


def _small_groom(seed: int = 7, uniform: bool = False):
    from hairtool.groom import Groom

    rng = np.random.default_rng(seed)
    counts = np.full(4, 3) if uniform else np.array([2, 5, 3, 4])
    v = int(counts.sum())
    return Groom(
        rng.standard_normal((v, 3)),
        counts,
        thickness=rng.uniform(0.1, 1, v),
        transparency=rng.uniform(0, 1, v),
        colors=rng.uniform(0, 1, (v, 3)),
    )


def _seed_hair(work: Path) -> list[bytes]:
    from hairtool.io import hairfile

    out = []
    for i, g in enumerate((_small_groom(), _small_groom(uniform=True), _small_groom().subset([1]))):
        hairfile.write(work / f"s{i}.hair", g, info="fuzz seed")
        out.append((work / f"s{i}.hair").read_bytes())
    return out


def _seed_tfx(work: Path) -> list[bytes]:
    g = _small_groom(uniform=True)
    xyzw = np.column_stack([g.points, np.ones(len(g.points))]).astype("<f4")
    v4 = struct.pack("<f7I", 4.0, 4, 3, 160, 0, 0, 160 + 192, 160 + 208) + b"\0" * 128
    v4 += xyzw.tobytes() + np.full(4, 0.5, "<f4").tobytes() + np.ones(48, "<f4").tobytes()
    v3 = struct.pack("<f3Ii", 3.0, 4, 3, 0, 0) + b"\0" * 124 + struct.pack("<I", 148)
    v3 += g.points.astype("<f4").tobytes()
    out = [v4, v3]
    real = TEST_DATA / "grooms" / "ponytail_tail.tfx"
    if real.is_file():
        out.append(real.read_bytes())
    return out


def _seed_npz(work: Path) -> list[bytes]:
    from hairtool.groom import Animation
    from hairtool.io import npz

    g = _small_groom()
    anim = Animation(np.stack([g.points, g.points * 2]), g.topology, 24.0, thickness=g.thickness)
    npz.write(work / "g.npz", g)
    npz.write(work / "a.npz", anim)
    stored = io.BytesIO()  # as np.savez writes it: members stored, not deflated
    np.savez(
        stored, format_version=np.array(1), kind=np.array("groom"), counts=g.counts, points=g.points
    )
    return [(work / "g.npz").read_bytes(), (work / "a.npz").read_bytes(), stored.getvalue()]


def _seed_obj(work: Path) -> list[bytes]:
    from hairtool.io import obj

    obj.write(work / "g.obj", _small_groom())
    relative = b"v 0 0 0\nv 1 0 0\nv 1 1 0\nl -3 -2 -1\nv 2 2 2\nl 1/1 4 -1\n"
    return [(work / "g.obj").read_bytes(), relative]


MESH = b"""# a unit square and a triangle
v 0 0 0
v 1 0 0
v 1 1 0
v 0 1 0
vn 0 0 1
vn 0 0 -1
f 1//1 2//1 3//1 4//1
v 0 0 1
f -1 1 2
f 5/1 3/2 4/3
"""


def _seed_mesh(work: Path) -> list[bytes]:
    return [MESH]


def _seed_bvh(work: Path) -> list[bytes]:
    chain = (
        "HIERARCHY\nROOT hips\n{\n  OFFSET 0 0 0\n"
        "  CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation\n"
        "  JOINT knee\n  {\n    OFFSET 0 2 0\n    CHANNELS 3 Zrotation Xrotation Yrotation\n"
        "    End Site\n    {\n      OFFSET 0 1 0\n    }\n  }\n}\n"
        "MOTION\nFrames: 3\nFrame Time: 0.04\n0 0 0 0 0 0 0 0 0\n1 2 3 90 0 0 0 0 0\n0 0 0 90 0 0 -90 0 0\n"
    )
    out = [chain.encode()]
    real = TEST_DATA / "motion" / "freebvh.bvh"
    if real.is_file():
        out.append(real.read_bytes())
    return out


def _seed_project(work: Path) -> list[bytes]:
    from hairtool import project
    from hairtool.frozen.pipeline import AlignSample
    from hairtool.groom import Animation

    g = _small_groom()
    anim = Animation(np.stack([g.points, g.points + 1]), g.topology, 12.0)
    strokes = (
        AlignSample((0.0, 1.0, 0.0), 0.5, 0.7, "paper"),
        AlignSample((1.0, 0.0, 0.0), 0.4, 0.2, "paper"),
    )
    proj = project.Project(
        rest=g, strokes=strokes, aligned=g, animation=anim, animation_source="fuzz", brush={"radius": 0.5}
    )
    project.save(work / "p.hairproj", proj)
    project.save(work / "z.hairproj", project.Project(rest=g), compress=True)
    return [(work / "p.hairproj").read_bytes(), (work / "z.hairproj").read_bytes()]


def _seed_keys(work: Path) -> list[bytes]:
    from hairtool.keys.export import keys_record, write_keys_json

    solve = {"frames": 30, "fps": 24.0, "keys": [0, 7, 19, 29], "cost": 1.5, "params": {"tau": 0.1}}
    record = keys_record(solve)
    write_keys_json(work / "k.json", record)
    return [(work / "k.json").read_bytes()]


def _seed_features(work: Path) -> list[bytes]:
    x = np.cumsum(np.random.default_rng(3).normal(size=(12, 3)), axis=0)
    a, b = io.BytesIO(), io.BytesIO()
    np.savez(a, X=x)
    np.savez_compressed(b, X=x.astype(np.float32), labels=np.arange(12))
    return [a.getvalue(), b.getvalue()]


def _seed_usda(work: Path) -> list[bytes]:
    from hairtool.groom import Animation
    from hairtool.io import usd

    g = _small_groom()
    anim = Animation(np.stack([g.points, g.points + 1]), g.topology, 24)
    usd.write(work / "a.usda", anim, time_codes=[0, 3])
    usd.write(work / "g.usda", g)
    return [(work / "a.usda").read_bytes(), (work / "g.usda").read_bytes()]


def _seed_strokes(work: Path) -> list[bytes]:
    from hairtool.frozen.strokes import Stroke, StrokeSample, write_strokes

    a = StrokeSample((0.1, 1.0, 0.2), 0.8, 0.6, (0.05, 0.0, 0.0), (0.0, -0.3, -1.0))
    b = StrokeSample((0.0, 0.5, 0.1), 0.4, -0.5)
    strokes = [
        Stroke("comb", (a, a), falloff=((0.0, 1.0), (0.4, 0.7), (1.0, 0.0)), symmetry="x", mirror_x=0.0),
        Stroke("align", (a,), params={"mode": "preserve-length"}),
        Stroke("length", (b,), falloff="linear"),
        Stroke("mask", (b, a), falloff="constant"),
    ]
    write_strokes(work / "s.json", strokes)
    wrapped = {"strokes": [strokes[0].to_dict()], "note": "fields a reader does not know"}
    return [(work / "s.json").read_bytes(), json.dumps(wrapped).encode()]


def _shots(work: Path) -> None:
    (work / "shots").mkdir(exist_ok=True)
    for name in ("a.npz", "b.npz"):
        (work / "shots" / name).write_bytes(b"")  # a glob only asks that they are files


JOBS = {
    "jobs": [
        {"command": "info", "args": ["shots/a.npz", "--json"]},
        {"command": "keys", "args": ["shots/b.npz", "--keys", 4, "--out", "k.json"]},
        {"glob": "shots/*.npz", "command": "convert", "args": ["{path}", "out/{stem}.usda"]},
    ]
}


def _seed_jobs(work: Path) -> list[bytes]:
    _shots(work)
    single = {"glob": "shots/*.npz", "command": "info", "args": ["{path}"]}
    return [json.dumps(JOBS, indent=1).encode(), json.dumps(single).encode()]


def _seed_jobs_toml(work: Path) -> list[bytes]:
    _shots(work)
    tables = """# one job written out, one per matching file
[[jobs]]
command = "keys"
args = ["shots/b.npz", "--keys", 4, "--out", "k.json"]

[[jobs]]
glob = 'shots/*.npz'
command = "convert"
args = ["{path}", "out/{stem}.usda"]
"""
    return [tables.encode(), _dump(JOBS, toml=True).encode()]


READERS: dict[str, Reader] = {
    "hair": Reader("hair", _seed_hair, _read_any, _check_groom),
    "tfx": Reader("tfx", _seed_tfx, _read_any, _check_groom),
    "npz": Reader("npz", _seed_npz, _read_any, _check_groom, zipped=True),
    "obj": Reader("obj", _seed_obj, _read_any, _check_groom, text=True),
    "mesh": Reader("obj", _seed_mesh, _read_mesh, _check_mesh, text=True, special=mutate_geometry),
    "bvh": Reader("bvh", _seed_bvh, _read_bvh, _check_motion, text=True),
    "project": Reader("hairproj", _seed_project, _read_project, _check_project, zipped=True, structured=True),
    "keys": Reader("json", _seed_keys, _read_keys, _check_keys, text=True),
    "features": Reader("npz", _seed_features, _read_features, _check_features, zipped=True),
    "usda": Reader("usda", _seed_usda, _read_any, _check_groom, text=True, special=mutate_layers),
    "strokes": Reader("json", _seed_strokes, _read_strokes, _check_strokes, text=True, structured=True),
    "jobs": Reader("json", _seed_jobs, _read_jobs, _check_jobs, text=True, structured=True),
    "edits": Reader("json", _seed_edits, _read_edits, _check_edits, text=True, structured=True),
    "jobs-toml": Reader("toml", _seed_jobs_toml, _read_jobs, _check_jobs, text=True, structured=True),
}


# -- running -------------------------------------------------------------------------------------
def mutant(reader: Reader, seeds: list[bytes], seed: int, index: int) -> tuple[bytes, list[str]]:
    rng = np.random.default_rng([seed, index])
    base = seeds[index % len(seeds)]
    if reader.special is not None and rng.random() < 0.25:
        return reader.special(rng, base)
    if reader.structured and rng.random() < 0.5:
        if reader.zipped:
            return mutate_manifest(rng, base)
        return mutate_document(rng, base, toml=reader.ext == "toml")
    if reader.zipped and rng.random() < 0.6:
        return mutate_zip(rng, base)
    return mutate_bytes(rng, base, reader.text)


#: The classes of the readers' own mutations.
OWN_CLASSES = {mutate_geometry: ("degenerate geometry",), mutate_layers: ("special file",)}
MUTATION_CLASSES = ("bit flip", "overwrite", "truncation", "huge count", "duplicated chunk", "token swap")
_CLASS_OF = {
    "flip": "bit flip",
    "overwrite": "overwrite",
    "truncate": "truncation",
    "cut": "truncation",
    "drop": "truncation",
    "huge": "huge count",
    "duplicate": "duplicated chunk",
    "swap": "token swap",
    "nest": "deep nesting",
    "bigint": "huge integer",
    "type": "wrong type",
    "ragged": "ragged array",
    "control": "control character",
    "absurd": "absurd number",
    "degenerate": "degenerate geometry",
    "special": "special file",
}


def mutation_classes(ops: list[str]) -> set[str]:
    """The classes of a mutant's operations ("points.npy: flip+huge-32", "swap a b", "cut" …)."""
    words = [w for op in ops if ": " in op for w in op.split(": ")[-1].split("+")]
    words += [op.split(" ")[0] for op in ops if ": " not in op]
    heads = [w.split("-")[0] for w in words]
    return {_CLASS_OF[h] for h in heads if h in _CLASS_OF}


def _chain(e: BaseException) -> list[BaseException]:
    seen: list[BaseException] = []
    while e is not None and e not in seen:
        seen.append(e)
        e = e.__cause__ or e.__context__
    return seen


class _Stderr:
    """fd 2 pointed at a temporary file around each read: a line usd-core (or anything beneath a
    reader) prints there would stand beside the CLI's one line."""

    def __init__(self) -> None:
        self.file = tempfile.TemporaryFile()
        atexit.register(self.file.close)  # closed before exit, where warnings are errors

    @contextlib.contextmanager
    def captured(self):
        sys.stderr.flush()
        self.file.seek(0)
        self.file.truncate()
        saved = os.dup(2)
        os.dup2(self.file.fileno(), 2)
        try:
            yield
        finally:
            sys.stderr.flush()
            os.dup2(saved, 2)
            os.close(saved)

    def text(self) -> str:
        self.file.seek(0)
        return self.file.read(400).decode("utf-8", "replace")


_STDERR = _Stderr()


def outcome(reader: Reader, path: Path) -> str | None:
    """None for a good read or a good refusal, else what went wrong (one line)."""
    with _STDERR.captured():
        result = _outcome(reader, path)
    printed = _STDERR.text()
    if printed and result in (None, "refused"):
        return f"printed on stderr: {printed[:200]!r}"
    return result


def _outcome(reader: Reader, path: Path) -> str | None:
    from hairtool.errors import FormatError, HairtoolError

    try:
        obj = reader.read(path)
    except HairtoolError as e:
        if any(isinstance(c, MemoryError) for c in _chain(e)):
            return f"refused only because memory ran out: {e}"
        if "\n" in str(e):
            return f"a message of several lines: {str(e)[:200]!r}"
        if isinstance(e, FormatError) and e.path != str(path):
            return f"the error names {e.path!r}, not the file"
        return "refused"
    except Exception as e:  # any other exception is what the fuzzing looks for
        frame = traceback.extract_tb(e.__traceback__)[-1]
        where = f"{Path(frame.filename).name}:{frame.lineno}"
        return f"{type(e).__name__} at {where}: {str(e)[:200]}"
    try:
        reader.check(obj)
    except AssertionError as e:
        return f"read, but {e}"
    return None


def cap_memory(margin: int = 2**30) -> int:
    """Cap the address space at what is mapped now plus ``margin``; returns the cap in bytes."""
    with open("/proc/self/status") as f:
        size_kb = next(int(line.split()[1]) for line in f if line.startswith("VmSize:"))
    cap = size_kb * 1024 + margin
    resource.setrlimit(resource.RLIMIT_AS, (cap, cap))
    return cap


def run(name: str, count: int, seed: int, only: int | None = None) -> dict:
    reader = READERS[name]
    with tempfile.TemporaryDirectory(prefix=f"hairtool-fuzz-{name}-") as tmp:
        work = Path(tmp)
        seeds = reader.seeds(work)
        for i, s in enumerate(seeds):  # every seed file is good before it is mutated
            p = work / f"seed{i}.{reader.ext}"
            p.write_bytes(s)
            assert outcome(reader, p) is None, (name, i, outcome(reader, p))
        reader.read(work / f"seed0.{reader.ext}")  # every lazy import done before the cap
        os.mkfifo(work / "fifo.usda")  # special files a layer may name (relative to the mutant)
        (work / "folder.usda").mkdir()
        cap = cap_memory()
        # A warning is a finding too: an overflow in a cast, or text the CLI would print
        # on stderr beside its one line.
        warnings.simplefilter("error")
        counts = {"read": 0, "refused": 0}
        own = OWN_CLASSES.get(reader.special, ())
        classes = dict.fromkeys(MUTATION_CLASSES + (STRUCTURE_CLASSES if reader.structured else ()) + own, 0)
        failures = []
        path = work / f"case.{reader.ext}"
        for index in range(count) if only is None else [only]:
            data, ops = mutant(reader, seeds, seed, index)
            for c in mutation_classes(ops) & set(classes):
                classes[c] += 1
            path.write_bytes(data)
            result = outcome(reader, path)
            if result is None:
                counts["read"] += 1
            elif result == "refused":
                counts["refused"] += 1
            else:
                failures.append({"index": index, "ops": ops, "error": result})
    return {
        "reader": name,
        "mutants": count if only is None else 1,
        **counts,
        "classes": classes,
        "failures": failures,
        "cap_mb": cap // 2**20,
        "max_rss_mb": peak_rss_mb(),
    }


def peak_rss_mb() -> int:
    """This process's peak resident memory (VmHWM: ``ru_maxrss`` would include a forking parent's)."""
    with open("/proc/self/status") as f:
        return next(int(line.split()[1]) for line in f if line.startswith("VmHWM:")) // 1024


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("reader", choices=sorted(READERS))
    parser.add_argument("--count", type=int, default=300)
    parser.add_argument("--seed", type=int, default=17)
    parser.add_argument("--only", type=int, help="run only the mutant with this index")
    args = parser.parse_args(argv)
    report = run(args.reader, args.count, args.seed, args.only)
    print(json.dumps(report))
    return 1 if report["failures"] else 0


if __name__ == "__main__":
    sys.exit(main())
