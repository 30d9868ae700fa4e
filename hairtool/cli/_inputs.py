"""Argument parsing shared by the subcommands (not a subcommand itself: the leading underscore
keeps :func:`hairtool.cli.command_names` from listing it).

:func:`parse_vector` (``"x,y,z"`` → three floats) raises a
:class:`~hairtool.errors.ParameterError`, which the CLI turns into exit code 2 and one line;
groom inputs are read by :func:`hairtool.io.specs.load_groom`.
"""

from __future__ import annotations

from hairtool.errors import ParameterError

#: ``help=`` text of an IN argument read by :func:`hairtool.io.specs.load_groom`.
GROOM_INPUT_HELP = "groom/animation file or sample:NAME[:S[:V]]"


def parse_vector(name: str, text: str) -> tuple[float, float, float]:
    """``"x,y,z"`` → ``(x, y, z)``; anything else is a :class:`ParameterError` naming ``name``."""
    try:
        v = tuple(float(c) for c in text.split(","))
    except ValueError:
        v = ()
    if len(v) != 3:
        raise ParameterError(name, text, "three numbers x,y,z")
    return v  # type: ignore[return-value]
