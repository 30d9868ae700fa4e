"""Benchmarks that print their numbers: ``hairtool bench NAME``, one module per benchmark.

A benchmark module defines ``HELP``, ``add_arguments(parser)`` and ``run(args) -> list[dict]``
(the rows); the CLI prints them as a table or, with ``--json``, as a JSON list. Speed targets
are ratios against a reference measured in the same run, never absolute times in unit tests.
"""

from __future__ import annotations

import argparse
import math
import os
import statistics
import time
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from hairtool.groom import Groom



def _data_dir() -> Path:
    """The real grooms and captures: ``$HAIRTOOL_BENCH_DATA`` when set (a studio's own grooms),
    else the checkout's ``tests/data`` (they travel with the repository), else ``../shared/data``."""
    chosen = os.environ.get("HAIRTOOL_BENCH_DATA")
    if chosen:
        return Path(chosen)
    checkout = Path(__file__).resolve().parents[2]
    bundled = checkout / "tests" / "data"
    return bundled if bundled.is_dir() else checkout.parent / "shared" / "data"


DATA_DIR = _data_dir()
GROOMS_DIR = DATA_DIR / "grooms"
MOTION_DIR = DATA_DIR / "motion"


def median_ms(
    fn: Callable[[], object],
    repeat: int = 7,
    warmup: int = 1,
    min_time: float = 0.0,
    max_time: float = math.inf,
) -> float:
    """Median wall time of ``fn()`` in milliseconds over ``repeat`` runs after ``warmup``.

    With ``min_time`` > 0, runs go on until that many seconds have passed (for tiny timings);
    with ``max_time``, they stop once that many seconds have passed (at least one run, for the
    slow ones).
    """
    for _ in range(warmup):
        fn()
    times = []
    start = time.perf_counter()
    while len(times) < repeat or (time.perf_counter() - start) < min_time:
        t0 = time.perf_counter()
        fn()
        times.append((time.perf_counter() - t0) * 1e3)
        if len(times) >= 10_000 or (time.perf_counter() - start) >= max_time:
            break
    return statistics.median(times)


def format_table(rows: list[dict]) -> str:
    """Rows as an aligned text table (columns from the first row's keys)."""
    if not rows:
        return "(no rows)"
    cols = list(rows[0])
    for r in rows[1:]:
        cols += [c for c in r if c not in cols]

    def cell(v: object) -> str:
        if v is None:
            return "-"
        if isinstance(v, float):
            return f"{v:.3g}" if abs(v) < 1000 else f"{v:.0f}"
        return str(v)

    table = [[cell(r.get(c)) for c in cols] for r in rows]
    widths = [max(len(c), *(len(t[i]) for t in table)) for i, c in enumerate(cols)]
    lines = ["  ".join(c.rjust(w) for c, w in zip(cols, widths, strict=True))]
    lines += ["  ".join(v.rjust(w) for v, w in zip(t, widths, strict=True)) for t in table]
    return "\n".join(lines)


def add_common_arguments(
    parser: argparse.ArgumentParser, *, quick: str, repeat: int, grooms: list[str] | None = None
) -> None:
    """``--quick`` (described by ``quick``), ``--repeat`` (default ``repeat``), ``--threads`` and,
    for benchmarks over grooms (``grooms``: the default specs), ``--grooms`` (see :func:`grooms`)."""
    parser.add_argument("--quick", action="store_true", help=quick)
    parser.add_argument(
        "--repeat", type=int, default=repeat, help=f"timed runs per number (median, default {repeat})"
    )
    parser.add_argument("--threads", type=int, default=None, help="numba threads (default: all)")
    if grooms is not None:
        parser.add_argument(
            "--grooms",
            nargs="+",
            metavar="GROOM",
            help="'real' (every .tfx in shared/data/grooms), STRANDSxVERTICES (a scalp sample), a groom "
            f"file or sample:NAME[:S[:V]] (default: {' '.join(grooms)})",
        )


def setup(args: argparse.Namespace, quick_repeat: int = 1) -> int:
    """Check ``--repeat`` and apply ``--threads``; the repeat count (``quick_repeat`` with ``--quick``)."""
    from hairtool.errors import ParameterError

    if args.repeat < 1:
        raise ParameterError("repeat", args.repeat, "a whole number ≥ 1")
    if args.threads is not None:
        import numba

        numba.set_num_threads(max(1, min(args.threads, numba.config.NUMBA_NUM_THREADS)))
    return quick_repeat if args.quick else args.repeat


def threads() -> int:
    """Numba threads the timings ran with."""
    import numba

    return numba.get_num_threads()


def ratio(num: float | None, den: float | None) -> float | None:
    """``num / den``, or None where either is missing or ``den`` is not positive."""
    if num is None or den is None or not den > 0:
        return None
    return num / den


def grooms(specs: list[str]) -> Iterator[tuple[str, Groom, Path | None]]:
    """``(name, groom, source file or None)`` for each spec: ``real`` (every ``.tfx`` in
    :data:`GROOMS_DIR`), ``STRANDSxVERTICES`` (a seeded scalp sample), a groom file or
    ``sample:NAME[:S[:V]]``."""
    from hairtool.errors import ParameterError
    from hairtool.io.specs import SAMPLE_PREFIX, load_groom
    from hairtool.samples import scalp

    for spec in specs:
        if spec == "real":
            paths = sorted(GROOMS_DIR.glob("*.tfx"))
            if not paths:
                raise ParameterError("grooms", spec, f"TressFX files in {GROOMS_DIR}")
            for path in paths:
                yield path.stem, load_groom(str(path)), path
        elif "x" in spec and all(p.isdigit() for p in spec.split("x")):
            s, v = (int(p) for p in spec.split("x"))
            yield f"scalp {spec}", scalp(s, v, seed=0), None
        elif spec.startswith(SAMPLE_PREFIX):
            yield spec, load_groom(spec), None
        else:
            yield Path(spec).stem, load_groom(spec), Path(spec)
