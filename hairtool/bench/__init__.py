"""Benchmarks that print their numbers: ``hairtool bench NAME``, one module per benchmark.

A benchmark module defines ``HELP``, ``add_arguments(parser)`` and ``run(args) -> list[dict]``
(the rows); the CLI prints them as a table or, with ``--json``, as a JSON list. Speed targets
are ratios against a reference measured in the same run, never absolute times in unit tests.
"""

from __future__ import annotations

import statistics
import time
from collections.abc import Callable


def median_ms(fn: Callable[[], object], repeat: int = 7, warmup: int = 1, min_time: float = 0.0) -> float:
    """Median wall time of ``fn()`` in milliseconds over ``repeat`` runs after ``warmup``.

    With ``min_time`` > 0, runs go on until that many seconds have passed (for tiny timings).
    """
    for _ in range(warmup):
        fn()
    times = []
    start = time.perf_counter()
    while len(times) < repeat or (time.perf_counter() - start) < min_time:
        t0 = time.perf_counter()
        fn()
        times.append((time.perf_counter() - t0) * 1e3)
        if len(times) >= 10_000:
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
