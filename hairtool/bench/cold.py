"""Each command's first run on an empty kernel cache, against its run on the cache it filled.

One row per command line of :data:`hairtool.first_runs.RECIPES` (a seeded 2,000-strand scalp
sample, its children and a hemisphere scalp; ``freeze large`` on 1,008,000 vertices, where freeze
runs its parallel kernels), plus ``freeze sintel``, the bundled Sintel guides
(``resources/`` of a checkout), the command the cold-start target is set on. Each run is a child
process ``python -m hairtool …``: ``cold_s`` with ``NUMBA_CACHE_DIR`` a new empty folder,
``warm_s`` the same command again on the cache that run filled (the median of ``--repeat``);
``compile_share`` is (cold - warm) / cold, the share of the first run numba spent compiling and
caching. Both include the interpreter's start and the imports (about 1 s), as a user's do.
Print ``hairtool bench host`` beside it on a shared machine. ``--kernels N`` runs the cold run
through :func:`record` and adds what it compiled: ``compile_cpu_s`` (the compiling thread's CPU
seconds) and the ``N`` kernels that took longest, each without the callees it compiled (a
compile-ahead process's kernels, :mod:`hairtool.compile_ahead`, are not counted).
"""

from __future__ import annotations

import argparse
import json
import runpy
import shutil
import statistics
import sys
import tempfile
import time
from pathlib import Path

from hairtool import first_runs
from hairtool.bench import add_common_arguments, setup

HELP = "cold and warm seconds of each command's first run (a fresh kernel cache per command)"
#: The command the cold-start target is set on (issue 44): ``freeze`` of the bundled guides.
SINTEL = "freeze sintel"
QUICK = ("sample", "freeze", SINTEL)


def _sintel() -> Path:
    return Path(first_runs.__file__).resolve().parents[1] / "resources" / "sintel_hair.tfx"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    names = [*first_runs.labels(), SINTEL]
    parser.add_argument(
        "--commands",
        nargs="+",
        metavar="LABEL",
        choices=names,
        help=f"of: {', '.join(repr(n) for n in names)} (default all; what a chosen one reads runs first)",
    )
    parser.add_argument(
        "--kernels",
        type=int,
        default=0,
        metavar="N",
        help="also time each kernel's compile in the cold run: the N slowest per command",
    )
    add_common_arguments(parser, quick="sample, freeze and freeze sintel only, one warm run", repeat=2)


def _argv(label: str, folder: Path) -> list[str] | None:
    if label == SINTEL:
        src = _sintel()
        return ["freeze", str(src), str(folder / "sintel-frozen.hair")] if src.is_file() else None
    return first_runs.argv(label, folder)


def run(args: argparse.Namespace) -> list[dict]:
    repeat = setup(args)
    names = args.commands or (list(QUICK) if args.quick else [*first_runs.labels(), SINTEL])
    # the recipes that write what the chosen ones read first (most read sample's groom)
    names = first_runs.with_inputs([n for n in names if n != SINTEL]) + [n for n in names if n == SINTEL]
    rows = []
    with tempfile.TemporaryDirectory(prefix="hairtool-cold-") as tmp:
        folder = Path(tmp)
        first_runs.prepare(folder)
        for label in names:
            argv = _argv(label, folder)
            if argv is None:
                continue
            cache = folder / f"cache-{len(rows)}"
            cache.mkdir()
            env = first_runs.child_env(cache)
            if args.threads is not None:
                env["NUMBA_NUM_THREADS"] = str(args.threads)
            log = folder / f"kernels-{len(rows)}.json"
            if args.kernels > 0:
                rc, cold, message = first_runs.run_child([str(log), *argv], env, module=__name__)
            else:
                rc, cold, message = first_runs.run_child(argv, env)
            row = {"command": label, "cold_s": cold, "warm_s": None, "compile_share": None, "status": rc}
            if args.kernels > 0 and log.is_file():
                seconds = json.loads(log.read_text())
                slowest = sorted(seconds.items(), key=lambda kv: -kv[1])[: args.kernels]
                row["compile_cpu_s"] = sum(seconds.values())
                row["slowest"] = ", ".join(f"{name.split(':')[-1]} {s:.2f}" for name, s in slowest)
            if rc == 0:
                warm = statistics.median(first_runs.run_child(argv, env)[1] for _ in range(repeat))
                row.update(warm_s=warm, compile_share=(cold - warm) / cold)
            else:
                row["error"] = message
            rows.append(row)
            shutil.rmtree(cache, ignore_errors=True)
    return rows


def record(log: str, argv: list[str]) -> int:
    """Run ``hairtool ARGV`` in this process and write, to ``log`` as JSON, each kernel's compile
    (``module:function`` → the compiling thread's CPU seconds, less the callees it compiled);
    the command's exit status."""
    from numba.core import event

    open_spans: list[list[float]] = []  # [start, seconds of the callees compiled inside]
    seconds: dict[str, float] = {}

    class Compiles(event.Listener):
        def on_start(self, ev) -> None:
            open_spans.append([time.thread_time(), 0.0])

        def on_end(self, ev) -> None:
            start, inner = open_spans.pop()
            took = time.thread_time() - start
            if open_spans:
                open_spans[-1][1] += took
            fn = ev.data["dispatcher"].py_func
            name = f"{fn.__module__}:{fn.__qualname__}"
            seconds[name] = seconds.get(name, 0.0) + took - inner

    event.register("numba:compile", Compiles())
    sys.argv = ["hairtool", *argv]
    try:  # the program ``python -m hairtool`` runs, in this process (as run_child's child runs it)
        runpy.run_module("hairtool", run_name="__main__", alter_sys=True)
        status = 0
    except SystemExit as e:
        status = e.code if isinstance(e.code, int) else int(e.code is not None)
    finally:
        Path(log).write_text(json.dumps(seconds))
    return status


if __name__ == "__main__":  # python -m hairtool.bench.cold LOG ARGS: one recorded command
    sys.exit(record(sys.argv[1], sys.argv[2:]))
