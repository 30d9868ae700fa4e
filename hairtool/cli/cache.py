"""Fill numba's kernel cache ahead of the commands' first runs (a farm image's build step).

``hairtool cache warm`` runs every command once on a seeded sample groom
(:data:`hairtool.first_runs.RECIPES`), each in a child process, so every kernel the commands
use is compiled into numba's cache (``NUMBA_CACHE_DIR`` when set, else beside the installed
package, or ``~/.cache/numba`` when that is read-only). A command's first run then loads its
kernels in a fraction of a second instead of compiling them for most of a minute.
"""

from __future__ import annotations

import argparse
import sys

HELP = "compile every kernel the commands use into the kernel cache (for a farm image)"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    sub = parser.add_subparsers(dest="action", metavar="ACTION", required=True)
    warm = sub.add_parser(
        "warm",
        help="run each command once on a sample groom, which compiles its kernels into the cache",
        description=__doc__,
    )
    warm.add_argument(
        "--if-needed",
        action="store_true",
        help="do nothing when this version's warm-up already finished into this cache",
    )


def _report(label: str, status: int, seconds: float, message: str) -> None:
    if status == 0:
        print(f"{label}: {seconds:.1f} s", flush=True)
    else:
        print(f"{label}: failed ({message or f'exit status {status}'})", flush=True)


def run(args: argparse.Namespace) -> int:
    import time

    from hairtool import first_runs

    t0 = time.perf_counter()
    try:
        failed = first_runs.warm_once(report=_report, force=not args.if_needed)
    except OSError as e:  # the record's folder cannot be made or written
        print(
            f"hairtool cache: error: {e.filename or first_runs.stamp_path()}: {e.strerror or e}",
            file=sys.stderr,
        )
        return 2
    if failed is None:
        print("the kernel cache is warm already")
        return 0
    if failed:
        print(f"hairtool cache: error: not warmed: {', '.join(failed)}", file=sys.stderr)
        return 1
    print(f"the kernel cache is warm ({time.perf_counter() - t0:.0f} s)")
    return 0
