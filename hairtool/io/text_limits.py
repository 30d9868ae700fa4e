"""Limits on JSON and TOML documents, checked on their text before a parser sees it.

Python's ``json`` and ``tomllib`` recurse once per level of nesting (a file nested 100,000
deep ends in a RecursionError, or worse in a parser that catches it late) and turn every
integer literal into an ``int`` (beyond 4,300 digits a ValueError; 10⁴⁰⁰ overflows ``float()``
afterwards), and ``tomllib`` spends time and memory quadratic in the parts of a dotted key (a
100,000-part key ``a.a.a… = 1`` took 22 GB). :func:`check_text` measures the deepest nesting,
the longest run of digits and the longest dotted key outside strings and comments, with
regular expressions and numpy (no Python loop over the text), so jobs files, stroke logs and
project manifests refuse such documents in one line naming the file, the line and the limit.
"""

from __future__ import annotations

import os
import re

import numpy as np

from hairtool.errors import FormatError

#: Deepest nesting of lists and objects a document may have (jobs files need 4, stroke logs 5).
MAX_DEPTH = 64
#: Longest run of digits outside strings, in any base (TOML's ``0x``, ``0o`` and ``0b``
#: integers too): no count, index, coordinate or argument needs more (float64 keeps 17
#: significant digits; an int64 has 19 decimal or 16 hex digits).
MAX_DIGITS = 40
#: Most parts of a TOML dotted key or table name (``[a.b.c]``): a jobs file needs one.
MAX_KEY_PARTS = 16

# JSON strings hold no raw control characters, so replacing each with "" keeps line numbers.
_JSON_STRINGS = re.compile(r'"(?:[^"\\\x00-\x1f]|\\.)*"')
# TOML: multi-line strings first (replaced keeping their newlines), then one-line strings and comments.
_TOML_LONG = re.compile(r'"""(?:[^\\]|\\.)*?"""{0,2}|\'\'\'.*?\'\'\'\'{0,2}', re.S)
_TOML_SHORT = re.compile(r'"(?:[^"\\\n]|\\.)*"|\'[^\'\n]*\'|#[^\n]*')
_NOT_BRACKET = re.compile(r"[^\[\]{}]+")
# A token that starts with a digit: decimal runs, and hex, octal or binary integers after their
# prefix (letters are hex digits there), all counted.
_LONG_DIGITS = re.compile(rf"\d\w{{{MAX_DIGITS},}}")
# A bare or (emptied) quoted key part, then more than MAX_KEY_PARTS - 1 dotted ones.
_KEY_PART = r'(?:[\w-]+|"")'
_LONG_KEY = re.compile(rf"{_KEY_PART}(?:[ \t]*\.[ \t]*{_KEY_PART}){{{MAX_KEY_PARTS},}}")


def _structure(text: str, kind: str) -> str:
    """``text`` with every string (and TOML comment) emptied, line breaks kept."""
    if kind == "json":
        return _JSON_STRINGS.sub('""', text)
    text = _TOML_LONG.sub(lambda m: '""' + "\n" * m.group().count("\n"), text)
    return _TOML_SHORT.sub('""', text)


_CHUNK = 1 << 22  # brackets summed at a time: 16 MB of int32 steps, however large the file


def nesting_depth(structure: str) -> int:
    """The deepest nesting of ``[`` and ``{`` in text whose strings are emptied.

    Parameters
    ----------
    structure : str
        The text, strings emptied.

    Returns
    -------
    int
        The depth.
    """
    brackets = _NOT_BRACKET.sub("", structure).encode("ascii")
    depth = deepest = 0
    for start in range(0, len(brackets), _CHUNK):
        b = np.frombuffer(brackets, dtype=np.uint8, count=min(_CHUNK, len(brackets) - start), offset=start)
        steps = ((b == ord("[")) | (b == ord("{"))).astype(np.int32) * 2 - 1
        running = np.cumsum(steps)
        deepest = max(deepest, depth + int(running.max()))
        depth += int(running[-1])
    return deepest


def check_text(
    path: str | os.PathLike[str], text: str, kind: str, what: str, max_depth: int = MAX_DEPTH
) -> None:
    """Refuse a ``kind`` ("json" or "toml") document nested deeper than ``max_depth`` or holding
    a number of more than :data:`MAX_DIGITS` digits (a :class:`FormatError` naming ``path``
    and ``what`` the file is, such as "a jobs file").

    Parameters
    ----------
    path : str or os.PathLike
        The file, named in a refusal.
    text : str
        Its text.
    kind : {"json", "toml"}
        Its language.
    what : str
        What the file is.
    max_depth : int, default MAX_DEPTH
        The deepest nesting allowed.
    """
    structure = _structure(text, kind)
    depth = nesting_depth(structure)
    if depth > max_depth:
        raise FormatError(path, f"nested {depth} levels deep; {what} nests at most {max_depth}")
    m = _LONG_DIGITS.search(structure)
    if m is not None:
        line = structure.count("\n", 0, m.start()) + 1
        token = m.group()
        digits = len(token) - token.count("_") - (2 if token[:2].lower() in ("0x", "0o", "0b") else 0)
        raise FormatError(
            path, f"line {line}: a number of {digits} digits; {what} holds none longer than {MAX_DIGITS}"
        )
    m = _LONG_KEY.search(structure) if kind == "toml" else None
    if m is not None:
        line = structure.count("\n", 0, m.start()) + 1
        parts = m.group().count(".") + 1
        raise FormatError(
            path, f"line {line}: a dotted key of {parts} parts; {what} has none longer than {MAX_KEY_PARTS}"
        )
