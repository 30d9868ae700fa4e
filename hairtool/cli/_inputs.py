"""Input parsing shared by the subcommands (not a subcommand itself: the leading underscore
keeps :func:`hairtool.cli.command_names` from listing it).

- :func:`load_groom`: a groom file or a built-in sample, ``sample:NAME[:STRANDS[:VERTICES]]``.
- :func:`parse_vector`: ``"x,y,z"`` → three floats.

Both raise :class:`~hairtool.errors.HairtoolError` subclasses, which the CLI turns into exit
code 2 and a one-line message.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from hairtool.errors import ParameterError

if TYPE_CHECKING:
    from hairtool.groom import Groom

SAMPLE_PREFIX = "sample:"
#: ``help=`` text of an IN argument read by :func:`load_groom`.
GROOM_INPUT_HELP = "groom/animation file or sample:NAME[:S[:V]]"


def load_groom(spec: str) -> Groom:
    """A groom from a file (an animation's first frame) or ``sample:NAME[:STRANDS[:VERTICES]]``.

    Samples use seed 0 and their own default sizes where STRANDS or VERTICES is left out.
    """
    if spec.startswith(SAMPLE_PREFIX):
        from hairtool.samples import sample

        parts = spec.split(":")[1:]
        if not 1 <= len(parts) <= 3:
            raise ParameterError("IN", spec, "sample:NAME[:STRANDS[:VERTICES]]")
        try:
            sizes = [int(p) for p in parts[1:]]
        except ValueError:
            raise ParameterError("IN", spec, "whole numbers for STRANDS and VERTICES") from None
        return sample(parts[0], *sizes)
    from hairtool.io import read_groom

    return read_groom(spec)


def parse_vector(name: str, text: str) -> tuple[float, float, float]:
    """``"x,y,z"`` → ``(x, y, z)``; anything else is a :class:`ParameterError` naming ``name``."""
    try:
        v = tuple(float(c) for c in text.split(","))
    except ValueError:
        v = ()
    if len(v) != 3:
        raise ParameterError(name, text, "three numbers x,y,z")
    return v  # type: ignore[return-value]
