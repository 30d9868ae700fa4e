"""The ``hairtool`` command line: one module per subcommand in this package.

A subcommand module defines ``HELP`` (one line), ``add_arguments(parser)`` and
``run(args) -> int``; it is found by name, so adding a command touches no shared list.
Heavy imports belong inside ``run`` so that ``hairtool --help`` stays fast.
"""

from __future__ import annotations

import argparse
import importlib
import pkgutil
import sys
from collections.abc import Sequence

from hairtool import __version__
from hairtool.errors import HairtoolError

EXIT_OK = 0
EXIT_BAD_INPUT = 2


def command_names() -> list[str]:
    here = importlib.import_module(__name__)
    return sorted(m.name for m in pkgutil.iter_modules(here.__path__) if not m.name.startswith("_"))


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="hairtool",
        description="Hair strand grooms: read, convert, freeze, animate and key them.",
    )
    parser.add_argument("--version", action="version", version=f"hairtool {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    for name in command_names():
        module = importlib.import_module(f"{__name__}.{name}")
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
    sys.exit(main())
