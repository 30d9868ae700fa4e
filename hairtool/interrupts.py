"""Ctrl+C in the command line, at any moment: one "interrupted" line and exit status 130.

Installed by the program's first lines (:mod:`hairtool.__main__`, which the ``hairtool``
script runs) before anything heavy is imported (argparse, numpy, numba, usd-core, Dask), so an
interrupt during the imports prints no traceback. The handler records the interrupt, says the
line and points stderr at /dev/null before it raises :class:`KeyboardInterrupt`: a C extension
that swallows the exception (usd-core loading its plugins does) must neither turn an
interrupted command into a successful one (the entry reads :func:`was_interrupted` when the
command returns) nor print its own warnings beside the line, and the exit hooks of libraries
stopped halfway add nothing either (the batch's Dask workers write theirs nowhere:
:mod:`hairtool.farm.cluster`).

Before the program's first line runs, the interrupt is Python's: in its first instants the
process ends by the signal itself (no line; a shell reports 130), and while Python imports its
``site`` module it prints Python's traceback, out of any program's reach.
"""

from __future__ import annotations

import os
import signal
import sys

#: 128 + SIGINT: the status a shell reports for a program stopped by Ctrl+C.
EXIT_INTERRUPTED = 128 + signal.SIGINT

_interrupted = False
_installed = False
_said = False
_prog = "hairtool"
_stderr: int | None = None  # the program's own stderr, whatever fd 2 is pointed at for a while


def _say(program: bool) -> None:
    """Write ``PROG: interrupted`` with ``os.write`` (nothing buffered can be cut by a second
    Ctrl+C); in the program, once, and stderr goes to /dev/null after it (a caller of
    :func:`hairtool.cli.main` in its own process keeps its stderr and gets a line each time)."""
    global _said
    if program and _said:
        return
    try:
        os.write(_stderr if program and _stderr is not None else 2, f"{_prog}: interrupted\n".encode())
    except OSError:
        pass
    if program:
        _said = True
        silence_stderr()


def _handler(signum, frame) -> None:
    global _interrupted
    _interrupted = True
    _say(program=True)
    raise KeyboardInterrupt


def _unraisable(info) -> None:
    """Python's hook for an exception it cannot raise (one in a weakref callback or a
    destructor): the interrupt raised there is recorded already, the rest as Python shows it."""
    if isinstance(info.exc_value, KeyboardInterrupt):
        return
    sys.__unraisablehook__(info)


def _excepthook(kind, value, tb) -> None:
    """An interrupt no one caught (raised before the entry's ``try``) ends as its one line."""
    if issubclass(kind, KeyboardInterrupt):
        _say(program=True)
        return
    sys.__excepthook__(kind, value, tb)


def install() -> None:
    """Count, say and raise on SIGINT (the main thread of the main interpreter only); an
    interrupt raised where Python cannot raise it (an import lock's callback) or caught by no
    one prints no traceback. Only the program calls it: a library importing hairtool keeps its
    own Ctrl+C."""
    global _installed, _stderr
    _installed = True
    if _stderr is None:
        try:
            _stderr = os.dup(2)  # not inherited by child processes
        except OSError:  # started with fd 2 closed
            _stderr = None
    signal.signal(signal.SIGINT, _handler)
    sys.unraisablehook = _unraisable
    sys.excepthook = _excepthook


def name(prog: str) -> None:
    """The program's name in the line from now on (``hairtool COMMAND`` once it is parsed)."""
    global _prog
    _prog = prog


def was_interrupted() -> bool:
    """Whether SIGINT arrived since :func:`install`, caught or swallowed."""
    return _interrupted


def report(prog: str | None = None) -> int:
    """Ignore further interrupts, print ``prog: interrupted`` as one line unless the handler
    said it already, and return 130."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    if prog is not None and not _said:
        name(prog)
    _say(program=_installed)
    return EXIT_INTERRUPTED


def restore_stderr(saved: int) -> None:
    """Point fd 2 back at ``saved`` after a stretch where it pointed elsewhere (usd-core's
    diagnostics, the Dask workers' filter), or at /dev/null once the interrupted line is said."""
    if _said:
        silence_stderr()
    else:
        os.dup2(saved, 2)


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
