"""A text layer's (``.usda``) curve arrays counted against its points before usd-core parses it.

usd-core's text parser holds every value of an array literal as a parsed token before it
builds the array: about 180 bytes a value, so a 20 MB file of 10⁷ widths peaks at 1.9 GB
before the reader can say that two curves do not need 10⁷ widths. Here the text is scanned
with regular expressions and numpy (strings and comments emptied, braces matched with a
cumulative sum, commas counted in C), and in every BasisCurves prim, and every untyped
``over``, the arrays the hair reader reads (counts, widths, colour and opacity primvars) may
hold no more values than the largest ``points`` array that could be theirs: no interpolation
of a curve primvar needs more values than the curves have points, nor more curves than points.

A layer that brings in other layers (sublayers, references, payloads) may take its points from
them: there only the prims with points of their own are checked. Small files are not scanned:
their parse is small whatever they hold.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np

from hairtool.errors import FormatError
from hairtool.io.text_limits import nesting_depth

MAGIC = b"#usda"
#: Files smaller than this are not scanned (usd-core parses them in under ~100 MB).
MIN_SCAN_BYTES = 1 << 20
#: Arrays this short are never refused (what usd-core makes of them is small).
FLOOR = 1 << 16
#: More braces than this (no real stage has them; usd-core stops at a stray one) and the prims
#: are not told apart: every curve array is counted against the file's largest points array.
MAX_BRACES = 1 << 22
#: Deepest nesting of prims, dictionaries and arrays: usd-core's parse and composition of a
#: 20,000-deep stage ran for minutes (each prim's path as long as its depth); real stages nest
#: a few dozen levels (a character's skeleton under its rig under its asset).
MAX_DEPTH = 512
#: The attributes of a curves prim the reader sizes from its points, by name.
CURVE_ARRAYS = (
    "curveVertexCounts",
    "widths",
    "primvars:widths",
    "primvars:displayColor",
    "primvars:color",
    "primvars:displayOpacity",
)

# Strings (three quoting styles), asset paths and comments: emptied before anything is counted.
_SKIP = re.compile(
    rb'"""(?:[^\\]|\\.)*?"""|\'\'\'(?:[^\\]|\\.)*?\'\'\'|"(?:[^"\\\n]|\\.)*"|\'(?:[^\'\\\n]|\\.)*\''
    rb"|@@@.*?@@@|@[^@\n]*@|#[^\n]*",
    re.S,
)
_PRIM = re.compile(rb"(def|over|class)\s+([A-Za-z_]\w*\s+)?\"\"")  # (\b before it: 3x slower)
_ARCS = (b"subLayers", b"references", b"payload")
_VALUE = re.compile(rb"\S")
_ASSIGN = re.compile(rb"([A-Za-z_][\w:]*)(\.timeSamples)?\s*=\s*([\[{])")


def _arrays(text: bytes, names: tuple[str, ...]) -> list[tuple[int, str, int]]:
    """(position, name, values) of every array literal assigned to one of ``names`` (each time
    sample apart); a value is a tuple where the array holds tuples. One pass of C-speed search."""
    out = []
    wanted = {n.encode() for n in names}
    for m in _ASSIGN.finditer(text):
        name = m.group(1)
        if name not in wanted:
            continue
        if m.group(3) == b"[":
            spans = [(m.end(), text.find(b"]", m.end()))]
        else:  # time samples: {t: [...], ...}, no braces inside
            stop = text.find(b"}", m.end())
            stop = len(text) if stop < 0 else stop
            spans, at = [], m.end()
            while (first := text.find(b"[", at, stop)) >= 0:
                last = text.find(b"]", first)
                spans.append((first + 1, last))
                at = last + 1 if last >= 0 else stop
        for a, b in spans:
            b = len(text) if b < 0 else b
            tuples = text.count(b"(", a, b)
            values = tuples or (text.count(b",", a, b) + 1 if _VALUE.search(text, a, b) else 0)
            out.append((m.start(), name.decode(), values))
    return out


def _blocks(text: bytes) -> list[tuple[int, int]]:
    """(start, end) of the body of every prim that is BasisCurves or an untyped over."""
    if text.count(b"{") + text.count(b"}") > MAX_BRACES:
        return [(0, len(text))]  # one block: the whole file
    b = np.frombuffer(text, dtype=np.uint8)
    pos = np.flatnonzero((b == ord("{")) | (b == ord("}")))
    if not pos.size:
        return []
    opening = b[pos] == ord("{")
    depth = np.cumsum(np.where(opening, 1, -1).astype(np.int32))
    out = []
    for m in _PRIM.finditer(text):
        if m.start() and (text[m.start() - 1 : m.start()].isalnum() or text[m.start() - 1] == ord("_")):
            continue  # the end of a longer word
        kind = (m.group(2) or b"").strip()
        if not (kind == b"BasisCurves" or (kind == b"" and m.group(1) == b"over")):
            continue
        i = int(np.searchsorted(pos, m.end()))
        if i >= len(pos) or not opening[i]:
            continue
        closing = np.flatnonzero(depth[i:] < depth[i])
        end = int(pos[i + closing[0]]) if closing.size else len(text)
        out.append((int(pos[i]), end))
    return out


def check(path: Path) -> None:
    """Raise FormatError when a curves prim's array holds more values than its points can use,
    or when the layer nests deeper than :data:`MAX_DEPTH` (any size of file).

    Parameters
    ----------
    path : Path
        A ``.usda`` file.
    """
    with open(path, "rb") as f:
        if f.read(len(MAGIC)) != MAGIC:
            return
        size = f.seek(0, 2)
        f.seek(0)
        text = _SKIP.sub(b'""', f.read())
    depth = nesting_depth(text.decode("latin-1"))  # strings and comments emptied above
    if depth > MAX_DEPTH:
        raise FormatError(
            path,
            f"nested {depth} levels deep; a stage nests at most {MAX_DEPTH} (refused before usd-core "
            "parses it)",
        )
    if size < MIN_SCAN_BYTES:
        return
    blocks = _blocks(text)
    if not blocks:
        return
    arrays = _arrays(text, ("points", *CURVE_ARRAYS))
    file_points = max((n for _, name, n in arrays if name == "points"), default=0)
    composed = any(word in text for word in _ARCS)
    for start, end in blocks:
        inside = [(at, name, n) for at, name, n in arrays if start <= at < end]
        points = max((n for _, name, n in inside if name == "points"), default=None)
        if points is None and composed:
            continue  # its points may come from another layer
        if points is None:
            points = file_points
        for at, name, n in inside:
            if name != "points" and n > max(points, FLOOR):
                line = text.count(b"\n", 0, at) + 1
                raise FormatError(
                    path,
                    f"line {line}: {name} holds {n} values for curves of at most {points} points "
                    "(refused before usd-core parses it)",
                )
