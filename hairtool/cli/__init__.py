"""The ``hairtool`` command line: one module per subcommand in this package.

A subcommand module defines ``HELP`` (one line), ``add_arguments(parser)`` and
``run(args) -> int``; it is found by name, so adding a command touches no shared list.
Heavy imports belong inside ``run`` so that ``hairtool --help`` stays fast.
"""

from __future__ import annotations

import argparse
import errno
import functools
import importlib
import os
import pkgutil
import signal
import sys
import warnings
from collections.abc import Sequence

from hairtool import __version__, interrupts
from hairtool.errors import HairtoolError, ReaderNote

EXIT_OK = 0
EXIT_BAD_INPUT = 2
#: The reader of the output went away (``hairtool info F | head -1``): 128 + SIGPIPE, the status
#: a shell reports for ``cat`` or ``grep`` stopped by a closed pipe, so ``set -o pipefail``
#: scripts see a cut listing as they do theirs, and no caller takes it for complete output.
EXIT_BROKEN_PIPE = 128 + signal.SIGPIPE


#: Entry-point group through which packages above the command line add commands: the farm's
#: ``hairtool batch`` runs commands, so the command line cannot import it (no import circle).
PLUGIN_GROUP = "hairtool.commands"


def command_modules(package: str = __name__, group: str = PLUGIN_GROUP) -> dict[str, str]:
    """Command name → module: each public module of ``package``, then the ``group`` entry points."""
    from importlib.metadata import entry_points  # 35 ms: not before the Ctrl+C handling

    here = importlib.import_module(package)
    names = [m.name for m in pkgutil.iter_modules(here.__path__) if not m.name.startswith("_")]
    found = {name: f"{package}.{name}" for name in names}
    for ep in entry_points(group=group):
        found.setdefault(ep.name, ep.value)
    return dict(sorted(found.items()))


def command_names() -> list[str]:
    return list(command_modules())


def _parser(command: str, cls: type[argparse.ArgumentParser], **kwargs) -> argparse.ArgumentParser:
    module = importlib.import_module(command_modules()[command])
    parser = cls(prog=f"hairtool {command}", description=module.__doc__, **kwargs)
    module.add_arguments(parser)
    return parser


class OneLineParser(argparse.ArgumentParser):
    """argparse's parser whose usage errors are one line (``hairtool keys: error: argument
    --keys: invalid int value: 'x'``) and exit 2, not the usage block."""

    def error(self, message: str):
        one = " ".join(message.split("\n"))
        self.exit(EXIT_BAD_INPUT, f"{self.prog}: error: {one}\n")


@functools.cache
def command_parser(command: str) -> argparse.ArgumentParser:
    """The argument parser of one ``hairtool`` command, as ``hairtool COMMAND`` builds it."""
    return _parser(command, OneLineParser)


class _RaisingParser(argparse.ArgumentParser):
    def error(self, message: str):  # argparse's own prints the usage and exits
        raise ValueError(message)


@functools.cache
def quiet_parser(command: str) -> argparse.ArgumentParser:
    """The parser of one command for reading a command line someone else will run (a batch's
    jobs): without ``--help``, and raising ``ValueError`` on bad arguments instead of printing
    the usage and exiting."""
    return _parser(command, _RaisingParser, add_help=False)


def build_parser() -> argparse.ArgumentParser:
    parser = OneLineParser(
        prog="hairtool",
        description="Hair strand grooms: read, convert, freeze, animate and key them.",
    )
    parser.add_argument("--version", action="version", version=f"hairtool {__version__}")
    parser.add_argument(
        "--raise-limits",
        metavar="FACTOR",
        type=float,
        help="multiply every work and memory limit by FACTOR, for a machine bigger than a laptop "
        "(the limits and their reasons: hairtool.budget)",
    )
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    for name, path in command_modules().items():
        module = importlib.import_module(path)
        p = sub.add_parser(name, help=module.HELP, description=module.__doc__)
        module.add_arguments(p)
        p.set_defaults(_run=module.run)
    return parser


def _say_notes(command: str):
    """A ``warnings.showwarning`` that prints a reader's note (:class:`ReaderNote`: what it left
    out of a file) as one line, ``hairtool COMMAND: warning: FILE: what``; other warnings as
    Python prints them."""
    shown = warnings.showwarning

    def show(message, category, filename, lineno, file=None, line=None):
        if issubclass(category, ReaderNote):
            one = " ".join(str(message).splitlines())
            print(f"hairtool {command}: warning: {one}", file=sys.stderr)
        else:
            shown(message, category, filename, lineno, file, line)

    return show


def main(argv: Sequence[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    interrupts.name(f"hairtool {args.command}")
    try:
        if args.raise_limits is not None:
            from hairtool import budget

            budget.set_factor(args.raise_limits)
        with warnings.catch_warnings():
            warnings.simplefilter("always", ReaderNote)  # every file's note, each time it is read
            warnings.showwarning = _say_notes(args.command)
            return int(args._run(args) or EXIT_OK)
    except HairtoolError as e:
        print(f"hairtool {args.command}: error: {e}", file=sys.stderr)
        return EXIT_BAD_INPUT
    except KeyboardInterrupt:
        return interrupts.report(f"hairtool {args.command}")


def entry() -> None:
    """The ``hairtool`` program: :func:`main`, its output flushed here, a closed pipe quiet.

    Python ignores SIGPIPE and raises BrokenPipeError at the write instead: caught here (after
    every ``with`` block of the command has removed its temporary files, which the signal's
    default action would leave behind), stdout is pointed at /dev/null so that the flush at
    exit cannot report the pipe again, and the status is :data:`EXIT_BROKEN_PIPE`. A stdout
    closed from the start (``>&-``) is the same pipe when something was printed; a full one
    (``> /dev/full``) is one line and exit 2. Ctrl+C at any moment is one line and exit 130
    (:mod:`hairtool.interrupts`, installed first).
    """
    interrupts.install()  # before any command module imports numpy, numba or usd-core
    closed = _ClosedStdout.replace()
    try:
        try:
            status = main()
        except SystemExit as e:  # argparse's --help, --version and usage errors
            status = e.code
        if interrupts.was_interrupted() and status != interrupts.EXIT_INTERRUPTED:
            status = interrupts.report("hairtool")  # swallowed on its way (usd-core's plugin loading)
        sys.stdout.flush()  # now, where a closed pipe can still be caught
        if closed is not None and closed.wrote and status == EXIT_OK:
            status = EXIT_BROKEN_PIPE  # its output went nowhere, as into a closed pipe
    except KeyboardInterrupt:  # while the command modules were imported, or in the flush
        status = interrupts.report("hairtool")
    except BrokenPipeError:
        for stream in (sys.stdout, sys.stderr):
            try:
                stream.flush()
            except BrokenPipeError:
                devnull = os.open(os.devnull, os.O_WRONLY)
                os.dup2(devnull, stream.fileno())
                os.close(devnull)
        status = EXIT_BROKEN_PIPE
    except OSError as e:
        if e.errno not in _FULL:
            raise
        _quiet_stdout()  # a full disk or device behind stdout: one line, the output is not whole
        reason = os.strerror(e.errno) if e.errno else str(e)
        print(f"hairtool: error: cannot write the output: {reason}", file=sys.stderr)
        status = EXIT_BAD_INPUT
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # the command is over: its status stands
    if status == interrupts.EXIT_INTERRUPTED:
        interrupts.silence_stderr()  # its line is said: nothing the interrupted libraries' exit hooks print
    sys.exit(status)


#: A write to stdout failed because where it goes is full (``hairtool info F > /dev/full``).
_FULL = (errno.ENOSPC, errno.EDQUOT, errno.EFBIG)


class _ClosedStdout:
    """Stands for ``sys.stdout`` when the command started with fd 1 closed (``>&-``): Python
    then sets ``sys.stdout`` to None. Writes are counted and dropped, and fd 1 is held on
    /dev/null, so a file the command opens cannot take fd 1 and receive what was printed."""

    def __init__(self) -> None:
        self.wrote = False

    def write(self, text: str) -> int:
        self.wrote = self.wrote or bool(text)
        return len(text)

    def flush(self) -> None:
        pass

    @classmethod
    def replace(cls) -> _ClosedStdout | None:
        if sys.stdout is not None:
            return None
        devnull = os.open(os.devnull, os.O_WRONLY)
        if devnull != 1:
            os.dup2(devnull, 1)
            os.close(devnull)
        sys.stdout = stand_in = cls()
        return stand_in


def _quiet_stdout() -> None:
    """Point fd 1 at /dev/null and drop what is buffered, so the flush at exit fails no more."""
    if sys.stdout is None:
        return
    devnull = os.open(os.devnull, os.O_WRONLY)
    try:
        os.dup2(devnull, sys.stdout.fileno())
    except (OSError, ValueError):
        pass
    os.close(devnull)
    sys.stdout = open(os.devnull, "w")
