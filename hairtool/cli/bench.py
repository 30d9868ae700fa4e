"""Run a benchmark and print its numbers (``--json`` for a machine-readable list of rows)."""

from __future__ import annotations

import argparse
import importlib
import json

from hairtool.cli import command_modules

HELP = "run a benchmark (freeze, keys, …) and print its numbers"
#: Entry-point group through which packages above the command line add benchmarks (the farm's).
PLUGIN_GROUP = "hairtool.benchmarks"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    sub = parser.add_subparsers(dest="benchmark", metavar="BENCHMARK", required=True)
    for name, path in command_modules("hairtool.bench", PLUGIN_GROUP).items():
        module = importlib.import_module(path)
        p = sub.add_parser(name, help=module.HELP, description=module.__doc__)
        p.add_argument("--json", action="store_true", help="print a JSON list of rows")
        module.add_arguments(p)
        p.set_defaults(_bench=module.run)


def run(args: argparse.Namespace) -> int:
    from hairtool.bench import format_table

    rows = args._bench(args)
    if args.json:
        print(json.dumps(rows, indent=1))
    else:
        print(format_table(rows))
    return 0
