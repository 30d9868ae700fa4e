"""The work and memory one command may ask for, in one place, each limit with its reason.

A command estimates what it is about to allocate or loop over (candidate points, grid cells
walked, neighbour entries, Gram tables, decoded arrays) and calls :func:`check` first; past a
limit it refuses in one line naming the parameter or file, the size and the limit, instead of
asking the machine for 25 GiB or running for minutes. The limits fit a laptop (a command stays
under about 1.5 GB and 20 s of CPU); a bigger machine raises all of them together with the
command line's ``--raise-limits FACTOR`` (or ``HAIRTOOL_BUDGET=FACTOR`` in the environment, which
a batch's child commands inherit).
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass

from hairtool.errors import HairtoolError

#: The environment variable holding the factor every limit is multiplied by.
ENV = "HAIRTOOL_BUDGET"


@dataclass(frozen=True)
class Limit:
    value: float
    unit: str
    reason: str


LIMITS: dict[str, Limit] = {
    "memory": Limit(
        1 << 30,
        "bytes",
        "one array a command builds from its input: 1 GiB, so that the interpreter, numpy, numba "
        "and the input itself (about 400 MB together) stay under 1.5 GB",
    ),
    "points": Limit(
        2e7,
        "points",
        "candidate points a brush or a planting step draws at once: 20 million (480 MB as "
        "float64 xyz) is 40 times the densest groom a studio brush makes in one stroke",
    ),
    "pairs": Limit(
        4e7,
        "neighbour pairs",
        "neighbour entries a search may hold: 16 bytes each (the forward and backward lists and "
        "their map), so 40 million take 640 MB, the most that fits beside the groom itself",
    ),
    "steps": Limit(
        5e9,
        "steps",
        "steps of a compiled loop over pairs (density's candidates against those accepted, "
        "its thinning): about 10⁹ simple steps a second, so about 5 s of CPU",
    ),
}


class BudgetError(HairtoolError, ValueError):
    """A command would need more work or memory than its budget allows; the message names what
    asked, the size and the limit."""


def factor() -> float:
    """The factor every limit is multiplied by (``HAIRTOOL_BUDGET``, 1 when unset or invalid:
    :func:`set_factor` checks the flag's value before it reaches the environment)."""
    try:
        f = float(os.environ.get(ENV, "1"))
    except ValueError:
        return 1.0
    return f if math.isfinite(f) and f > 0 else 1.0


def set_factor(value: float) -> None:
    """Raise (or lower) every limit by ``value`` for this process and the commands it starts.

    Parameters
    ----------
    value : float
        A finite factor > 0 (BudgetError otherwise).
    """
    if not (isinstance(value, int | float) and math.isfinite(value) and value > 0):
        raise BudgetError(f"--raise-limits={value!r} is invalid: expected a positive factor")
    os.environ[ENV] = repr(float(value))


def limit(kind: str) -> float:
    """The limit of ``kind`` (a key of :data:`LIMITS`) after the factor.

    Parameters
    ----------
    kind : str
        ``"memory"``, ``"points"``, ``"pairs"`` or ``"steps"`` (a key of :data:`LIMITS`).

    Returns
    -------
    float
        The limit in its unit (bytes, points, pairs, steps).
    """
    return LIMITS[kind].value * factor()


def _size(n: float, unit: str) -> str:
    if unit == "bytes":
        for div, name in ((1 << 30, "GiB"), (1 << 20, "MiB"), (1 << 10, "KiB")):
            if n >= div:
                return f"{n / div:.3g} {name}"
        return f"{n:.0f} bytes"
    return f"{n:.3g} {unit}"


def check(kind: str, size: float, what: str) -> None:
    """Refuse (:class:`BudgetError`) when ``size`` (in the limit's unit; may be inf or nan, an
    estimate that overflowed) exceeds the limit of ``kind``; ``what`` names the parameter or
    file that asked ("radius=1e+06", "capture.bvh").

    Parameters
    ----------
    kind : str
        Which limit (a key of :data:`LIMITS`).
    size : float
        The estimate, in the limit's unit.
    what : str
        The parameter or file that asked, as the line shows it.

    Raises
    ------
    BudgetError
        Where the estimate is past the limit, or not a number.
    """
    lim = limit(kind)
    if size <= lim:  # False for nan: an estimate that is not a number is refused too
        return
    unit = LIMITS[kind].unit
    shown = "more than can be counted" if not math.isfinite(size) else _size(size, unit)
    raise BudgetError(
        f"{what} needs {shown}; the limit is {_size(lim, unit)} "
        "(raise it with hairtool --raise-limits FACTOR)"
    )


def check_bytes(size: float, what: str) -> None:
    """:func:`check` of memory in bytes.

    Parameters
    ----------
    size : float
        The estimated allocation in bytes.
    what : str
        The parameter or file that asked.

    Raises
    ------
    BudgetError
        Past the memory limit.
    """
    check("memory", size, what)
