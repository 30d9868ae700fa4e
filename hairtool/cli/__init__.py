"""The ``hairtool`` command line: one module per subcommand in this package.

A subcommand module defines ``HELP`` (one line), ``add_arguments(parser)`` and
``run(args) -> int``; it is found by name, so adding a command touches no shared list.
Heavy imports belong inside ``run`` so that ``hairtool --help`` stays fast.
"""

from __future__ import annotations

import argparse
import functools
import importlib
import os
import pkgutil
import signal
import sys
from collections.abc import Sequence
from importlib.metadata import entry_points

from hairtool import __version__
from hairtool.errors import HairtoolError

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


@functools.cache
def command_parser(command: str) -> argparse.ArgumentParser:
    """The argument parser of one ``hairtool`` command, as ``hairtool COMMAND`` builds it."""
    return _parser(command, argparse.ArgumentParser)


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
    parser = argparse.ArgumentParser(
        prog="hairtool",
        description="Hair strand grooms: read, convert, freeze, animate and key them.",
    )
    parser.add_argument("--version", action="version", version=f"hairtool {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    for name, path in command_modules().items():
        module = importlib.import_module(path)
        p = sub.add_parser(name, help=module.HELP, description=module.__doc__)
        module.add_arguments(p)
        p.set_defaults(_run=module.run)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        return int(args._run(args) or EXIT_OK)
    except HairtoolError as e:
        print(f"hairtool {args.command}: error: {e}", file=sys.stderr)
        return EXIT_BAD_INPUT
    except KeyboardInterrupt:
        print(f"hairtool {args.command}: interrupted", file=sys.stderr)
        return 130


def entry() -> None:
    """The ``hairtool`` program: :func:`main`, its output flushed here, a closed pipe quiet.

    Python ignores SIGPIPE and raises BrokenPipeError at the write instead: caught here (after
    every ``with`` block of the command has removed its temporary files, which the signal's
    default action would leave behind), stdout is pointed at /dev/null so that the flush at
    exit cannot report the pipe again, and the status is :data:`EXIT_BROKEN_PIPE`.
    """
    try:
        try:
            status = main()
        except SystemExit as e:  # argparse's --help, --version and usage errors
            status = e.code
        sys.stdout.flush()  # now, where a closed pipe can still be caught
    except BrokenPipeError:
        for stream in (sys.stdout, sys.stderr):
            try:
                stream.flush()
            except BrokenPipeError:
                devnull = os.open(os.devnull, os.O_WRONLY)
                os.dup2(devnull, stream.fileno())
                os.close(devnull)
        status = EXIT_BROKEN_PIPE
    sys.exit(status)
