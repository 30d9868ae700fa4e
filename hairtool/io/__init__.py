"""Reading and writing grooms and animations; the format is chosen by file extension.

Each format module defines ``read(path)`` and, where writable, ``write(path, obj)``. Readers
raise :class:`~hairtool.errors.FormatError` naming the file for any bad input; writers go
through :mod:`hairtool.io.atomic` so a failed write never leaves a half file.
"""

from __future__ import annotations

import importlib
import os
from dataclasses import dataclass
from pathlib import Path

from hairtool.errors import FormatError, GroomError
from hairtool.groom import Animation, Groom


@dataclass(frozen=True)
class Format:
    """One file format: its name, extensions, the module that reads and writes it, and what it can
    hold (``animated``: its writer keeps every frame of an :class:`~hairtool.groom.Animation`)."""

    name: str
    extensions: tuple[str, ...]
    module: str
    readable: bool = True
    writable: bool = True
    animated: bool = False  # the writer keeps every frame of an Animation

    def load(self):
        return importlib.import_module(f"hairtool.io.{self.module}")


FORMATS: tuple[Format, ...] = (
    Format("HAIR (Cem Yuksel)", (".hair",), "hairfile"),
    Format("TressFX", (".tfx",), "tfx", writable=False),
    Format("USD BasisCurves", (".usda", ".usdc", ".usd"), "usd", animated=True),
    Format("hairtool cache", (".npz",), "npz", animated=True),
    Format("Wavefront OBJ polylines", (".obj",), "obj"),
    Format("USC-HairSalon strands", (".data",), "usc_data"),
)


def _supported(kind: str) -> str:
    exts = [e for f in FORMATS if getattr(f, kind) for e in f.extensions]
    return ", ".join(exts)


def format_for(path: str | os.PathLike[str], *, writing: bool = False) -> Format:
    """The format of a path, by its extension (case does not matter).

    Parameters
    ----------
    path
        The file's path; only its extension is looked at.
    writing
        Find a format that can write the file rather than read it.

    Returns
    -------
    Format
        The format of that extension.

    Raises
    ------
    FormatError
        No format reads (or writes) that extension; the message lists the extensions that work.
    """
    ext = Path(path).suffix.lower()
    kind = "writable" if writing else "readable"
    for f in FORMATS:
        if ext in f.extensions and getattr(f, kind):
            return f
    verb = "write" if writing else "read"
    raise FormatError(path, f"cannot {verb} '{ext or 'no extension'}' files; supported: {_supported(kind)}")


def read(path: str | os.PathLike[str]) -> Groom | Animation:
    """Read a groom or an animation, whichever the file holds.

    Parameters
    ----------
    path
        A ``.hair``, ``.tfx``, ``.usda``/``.usdc``/``.usd``, ``.npz`` or ``.obj`` file.

    Returns
    -------
    Groom or Animation
        An :class:`~hairtool.groom.Animation` where the file holds time samples or frames (USD,
        ``.npz``), a :class:`~hairtool.groom.Groom` otherwise, with the file's attributes and
        scene description.

    Raises
    ------
    FormatError
        The file is missing, unreadable, truncated, corrupt or of an unknown extension; the
        message names the file.
    """
    fmt = format_for(path)
    p = Path(path)
    if not p.is_file():
        raise FormatError(path, "no such file" if not p.exists() else "not a regular file")
    try:
        return fmt.load().read(p)
    except GroomError as e:
        raise FormatError(path, str(e)) from None
    except (OSError, MemoryError) as e:
        raise FormatError(path, f"cannot read: {e}") from None


def read_groom(path: str | os.PathLike[str]) -> Groom:
    """Read a groom; for an animation, its first frame.

    Parameters
    ----------
    path
        Any file :func:`read` reads.

    Returns
    -------
    Groom
        The groom, or the animation's rest pose (its first frame).

    Raises
    ------
    FormatError
        As :func:`read`.
    """
    obj = read(path)
    return obj.rest if isinstance(obj, Animation) else obj


def write(path: str | os.PathLike[str], obj: Groom | Animation) -> None:
    """Write a groom or animation; formats without time samples get an animation's first frame.

    The file is written to a temporary file beside ``path`` and renamed into place, so a failed
    write never leaves a partial file.

    Parameters
    ----------
    path
        The file to write; its extension picks the format (``.hair``, ``.usda``/``.usdc``/``.usd``,
        ``.npz`` or ``.obj``).
    obj
        The groom or animation, written with its attributes and, where the format holds it, its
        scene description.

    Raises
    ------
    FormatError
        The extension cannot be written, or the file cannot be written; the message names it.
    """
    fmt = format_for(path, writing=True)
    if isinstance(obj, Animation) and not fmt.animated:
        obj = obj.rest
    try:
        fmt.load().write(Path(path), obj)
    except OSError as e:
        raise FormatError(path, f"cannot write: {e}") from None
