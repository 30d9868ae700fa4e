"""Errors that reach the user as one line, never as a traceback."""

from __future__ import annotations

import math
import os


class HairtoolError(Exception):
    """Base of every error the CLI and the studio report as a message."""


class FormatError(HairtoolError):
    """A file could not be read or written; the message names the file."""

    def __init__(self, path: str | os.PathLike[str], reason: str) -> None:
        """The message is ``PATH: reason``.

        Parameters
        ----------
        path : str or os.PathLike
            The file that could not be read or written.
        reason : str
            What is wrong with it, one line.
        """
        self.path = os.fspath(path)
        self.reason = reason
        super().__init__(f"{self.path}: {reason}")


class ParameterError(HairtoolError, ValueError):
    """A parameter is out of range; the message names it and its valid range."""

    def __init__(self, name: str, value: object, expected: str) -> None:
        """The message is ``NAME=VALUE is invalid: expected EXPECTED``.

        Parameters
        ----------
        name : str
            The parameter as the caller knows it (an option, a field, a file's key).
        value : object
            The value refused (shown with ``repr``, so one line stays one line).
        expected : str
            The valid range or kinds, in words.
        """
        self.name = name
        self.value = value
        super().__init__(f"{name}={value!r} is invalid: expected {expected}")


def finite_number(name: str, value: object) -> float:
    """``value`` as a finite float, or a :class:`ParameterError` naming ``name``."""
    try:
        v = float(value)  # type: ignore[arg-type]
    except (TypeError, ValueError):
        raise ParameterError(name, value, "a finite number") from None
    if not math.isfinite(v):
        raise ParameterError(name, value, "a finite number")
    return v


class GroomError(HairtoolError, ValueError):
    """Arrays do not describe a valid groom or animation."""


class ReaderNote(UserWarning):
    """Something a reader left out of what a file holds (a USC-HairSalon bald scalp sample), said
    as a warning so it is never silent: the CLI prints it as one line on stderr."""


class Cancelled(Exception):
    """Raised inside a long call once its ``cancelled()`` callback turned True (a studio job's
    Cancel button, a superseded job): the work stops and its result is dropped."""


def quoted(text: object, limit: int = 60) -> str:
    """A user's string as a message shows it: quoted and escaped as ``repr`` does (a newline or
    control character in a joint, channel or field name stays ``\\n``, so one line stays one
    line), cut to ``limit`` characters with ``…``. The one way messages print user strings."""
    s = text if isinstance(text, str) else str(text)
    if len(s) > limit:
        return repr(s[:limit])[:-1] + "…" + repr(s[:limit])[-1]
    return repr(s)
