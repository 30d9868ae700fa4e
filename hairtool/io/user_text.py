"""The one reader of the JSON and TOML files a user writes or edits: edit files, stroke logs,
jobs files, project manifests, settings.

Every such document passes the same limits, so none of them is the reader that skipped one:
its size, then its nesting and the digits of its numbers in any base (measured on the text by
:mod:`~hairtool.io.text_limits` before a parser recurses or converts), then, on the parsed
tree, the length of every string and key and the characters in them: a control character
(a newline in a joint name, an escape sequence in a job's argument) is refused, so nothing a
message echoes can split its one line or drive the terminal.
"""

from __future__ import annotations

import json
import os
import re
import stat
import tomllib

from hairtool.errors import FormatError, quoted
from hairtool.io.text_limits import MAX_DEPTH, check_text

#: Largest document read: the longest stroke log a day of grooming writes is about 20 MB.
MAX_BYTES = 64 << 20
#: Longest string or key: a path (Linux's PATH_MAX is 4,096 bytes) is the longest a user needs.
MAX_STRING = 4096
# C0 controls but the tab, DEL, and the C1 controls (a terminal reads some as commands).
_CONTROL = re.compile(r"[\x00-\x08\x0a-\x1f\x7f-\x9f]")


def parse(
    source: str | os.PathLike[str],
    text: str,
    kind: str,
    what: str,
    max_depth: int = MAX_DEPTH,
    texts: frozenset[str] = frozenset(),
) -> object:
    """``text``, a ``kind`` ("json" or "toml") document, parsed and checked; a
    :class:`FormatError` naming ``source`` and ``what`` the document is ("a stroke log").
    ``texts``: the places (``"settings.capture.bvh"``) that hold a whole file's text, such as a
    capture's BVH a project carries: their lines and length are that file's, bounded by the
    document's size, and the reader of that text checks it.

    Parameters
    ----------
    source : str or os.PathLike
        The file the text came from, named in a refusal.
    text : str
        The document.
    kind : {"json", "toml"}
        Its language.
    what : str
        What the document is, in words.
    max_depth : int, default MAX_DEPTH
        The deepest nesting allowed.
    texts : frozenset of str, default frozenset()
        The dotted places holding embedded files.

    Returns
    -------
    object
        The parsed document.
    """
    check_text(source, text, kind, what, max_depth)
    unreadable = f"not a readable {what.split(' ', 1)[-1]}"  # "a stroke log" -> "stroke log"
    try:
        data = json.loads(text) if kind == "json" else tomllib.loads(text)
    except json.JSONDecodeError as e:
        where = f"line {e.lineno}, column {e.colno}"
        raise FormatError(source, f"{unreadable} (not valid JSON: {e.msg}, {where})") from None
    except tomllib.TOMLDecodeError as e:
        raise FormatError(source, f"{unreadable} (not valid TOML: {str(e).splitlines()[0]})") from None
    except (RecursionError, ValueError, OverflowError) as e:  # past the text checks only on a deep stack
        raise FormatError(source, f"{unreadable} ({type(e).__name__})") from None
    check_strings(source, data, texts)
    return data


def check_strings(
    source: str | os.PathLike[str], data: object, texts: frozenset[str] = frozenset()
) -> None:
    """Refuse a string or key in ``data`` longer than :data:`MAX_STRING` or holding a control
    character, naming where it is (walked without recursion); the strings at ``texts`` are
    embedded files (see :func:`parse`).

    Parameters
    ----------
    source : str or os.PathLike
        The file, named in a refusal.
    data : object
        A parsed document.
    texts : frozenset of str, default frozenset()
        The dotted places holding embedded files.

    Raises
    ------
    FormatError
        For a string too long or holding a control character.
    """
    stack: list[tuple[str, object]] = [("", data)]
    while stack:
        where, v = stack.pop()
        if isinstance(v, dict):
            for k, c in v.items():
                _check_string(source, where or "the top level", k, "key")
                stack.append((f"{where}.{k}" if where else str(k), c))
        elif isinstance(v, list):
            stack.extend((f"{where}[{i}]", c) for i, c in enumerate(v))
        elif isinstance(v, str) and where not in texts:
            _check_string(source, where or "the document", v, "string")


def _check_string(source, where: str, s: object, kind: str) -> None:
    if not isinstance(s, str):
        return
    shown = quoted(where, 80)
    if len(s) > MAX_STRING:
        raise FormatError(source, f"a {kind} at {shown} of {len(s)} characters; at most {MAX_STRING}")
    m = _CONTROL.search(s)
    if m is not None:
        raise FormatError(
            source, f"the {kind} {quoted(s, 60)} at {shown} holds a control character {m.group()!r}"
        )


def read_bytes(path: str | os.PathLike[str], what: str, max_bytes: int | None = MAX_BYTES) -> bytes:
    """A regular file's bytes, or a :class:`FormatError` naming it: the one way a reader of a
    user's file opens it (a FIFO or a device is refused before it is opened for reading, so it
    cannot block; an unreadable file is refused with the system's reason).

    Parameters
    ----------
    path : str or os.PathLike
        The file.
    what : str
        What the file should be, for the refusal ("a stroke log").
    max_bytes : int or None
        The largest file read (None: any size).

    Returns
    -------
    bytes
        The file's contents.

    Raises
    ------
    FormatError
        Not a regular file, too large, or unreadable; the message names the file.
    """
    p = os.fspath(path)
    limit = -1 if max_bytes is None else max_bytes + 1
    try:
        st = os.stat(p)
        if not stat.S_ISREG(st.st_mode):
            raise FormatError(p, f"not a regular file, so not {what}")
        if max_bytes is not None and st.st_size > max_bytes:
            raise FormatError(p, f"{st.st_size} bytes; {what} is at most {max_bytes >> 20} MB")
        with open(p, "rb") as f:
            raw = f.read(limit)
    except OSError as e:
        raise FormatError(p, f"cannot read: {e.strerror or e}") from None
    if max_bytes is not None and len(raw) > max_bytes:  # grew since the stat
        raise FormatError(p, f"more than {max_bytes >> 20} MB; {what} is at most that")
    return raw


def read_text(path: str | os.PathLike[str], what: str, max_bytes: int = MAX_BYTES) -> str:
    """A regular file's UTF-8 text, at most ``max_bytes`` long (:func:`read_bytes`).

    Parameters
    ----------
    path : str or os.PathLike
        The file.
    what : str
        What it is, in words (a refusal says so).
    max_bytes : int, default MAX_BYTES
        The largest file read.

    Returns
    -------
    str
        Its text.
    """
    raw = read_bytes(path, what, max_bytes)
    try:
        return raw.decode("utf-8")
    except UnicodeDecodeError as e:
        raise FormatError(os.fspath(path), f"not UTF-8 text (byte {e.start})") from None


def read(
    path: str | os.PathLike[str],
    what: str,
    kind: str | None = None,
    max_bytes: int = MAX_BYTES,
    max_depth: int = MAX_DEPTH,
    texts: frozenset[str] = frozenset(),
) -> object:
    """A JSON or TOML file (``kind``, else its suffix: ``.toml`` is TOML, anything else JSON)
    read and parsed under every limit (``texts`` as :func:`parse`'s); a :class:`FormatError`
    names the file.

    Parameters
    ----------
    path : str or os.PathLike
        The file.
    what : str
        What it is, in words.
    kind : {"json", "toml"}, optional
        Its language (None: by its suffix).
    max_bytes : int, default MAX_BYTES
        The largest file read.
    max_depth : int, default MAX_DEPTH
        The deepest nesting allowed.
    texts : frozenset of str, default frozenset()
        The dotted places holding embedded files.

    Returns
    -------
    object
        The parsed document.
    """
    p = os.fspath(path)
    kind = kind or ("toml" if p.lower().endswith(".toml") else "json")
    return parse(p, read_text(p, what, max_bytes), kind, what, max_depth, texts)
