"""Ctrl+C in the command line, at any moment: one "interrupted" line and exit status 130.

Installed by the program's entry before anything heavy is imported (numpy, numba, usd-core,
Dask), so an interrupt during the imports prints no traceback. The handler records the
interrupt before it raises :class:`KeyboardInterrupt`, because a C extension that swallows
the exception (usd-core loading its plugins does) must not turn an interrupted command into a
successful one: the entry reads :func:`was_interrupted` when the command returns. Once the
line is written, :func:`silence_stderr` keeps the exit hooks of libraries stopped halfway
from adding theirs (the batch's Dask workers write theirs nowhere:
:mod:`hairtool.farm.cluster`).
"""

from __future__ import annotations

import os
import signal
import sys

#: 128 + SIGINT: the status a shell reports for a program stopped by Ctrl+C.
EXIT_INTERRUPTED = 128 + signal.SIGINT

_interrupted = False


def _handler(signum, frame) -> None:
    global _interrupted
    _interrupted = True
    raise KeyboardInterrupt


def _unraisable(info) -> None:
    """Python's hook for an exception it cannot raise (one in a weakref callback or a
    destructor): the interrupt raised there is recorded already, the rest as Python shows it."""
    if isinstance(info.exc_value, KeyboardInterrupt):
        return
    sys.__unraisablehook__(info)


def install() -> None:
    """Count and raise on SIGINT (the main thread of the main interpreter only); an interrupt
    raised where Python cannot raise it (an import lock's callback) prints no traceback."""
    signal.signal(signal.SIGINT, _handler)
    sys.unraisablehook = _unraisable


def was_interrupted() -> bool:
    """Whether SIGINT arrived since :func:`install`, caught or swallowed."""
    return _interrupted


def report(prog: str) -> int:
    """Ignore further interrupts, print ``prog: interrupted`` as one line and return 130. The
    line is written with ``os.write``: nothing buffered can be cut by a second Ctrl+C."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        os.write(2, f"{prog}: interrupted\n".encode())
    except OSError:
        pass
    return EXIT_INTERRUPTED


def silence_stderr() -> None:
    """Point fd 2 at /dev/null once the "interrupted" line is written: a library stopped halfway
    (a Dask cluster that was starting) complains from its exit hooks, after the line that
    already said what happened."""
    try:
        sys.stderr.flush()
    except (OSError, ValueError, AttributeError):
        pass
    devnull = os.open(os.devnull, os.O_WRONLY)
    os.dup2(devnull, 2)
    os.close(devnull)
