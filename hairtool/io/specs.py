"""Grooms named by a string, as a command line, a jobs file or a benchmark names them: a groom
file, or a built-in sample as ``sample:NAME[:STRANDS[:VERTICES]]``."""

from __future__ import annotations

from typing import TYPE_CHECKING

from hairtool.errors import ParameterError

if TYPE_CHECKING:
    from hairtool.groom import Groom

SAMPLE_PREFIX = "sample:"


def load_groom(spec: str) -> Groom:
    """A groom from a file (an animation's first frame) or ``sample:NAME[:STRANDS[:VERTICES]]``.

    Samples use seed 0 and their own default sizes where STRANDS or VERTICES is left out.

    Parameters
    ----------
    spec : str
        A path, or ``sample:NAME[:STRANDS[:VERTICES]]``.

    Returns
    -------
    Groom
        The groom.
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
