"""How fast this machine runs right now, against the machine the speed targets were set on.

The targets of the other benchmarks are absolute times on the project's 2-core reference VM,
whose speed drifts by 10-40 % within an hour as its host's other tenants come and go. This
benchmark times three small probes and divides each into the same probe's time on that VM with
no other tenant in its way (its fastest medians over a day, 2026-12-02): ``speed`` 1.0 is the
reference machine at its best, 0.8 a moment when everything takes 25 % longer. Run it beside
another benchmark to read that one's numbers.

Probes: ``arithmetic``, multiply-adds on rows in L1 cache (the numba kernels' kind of work),
on one thread and the same work on every thread; ``memory``, copying 64 MB four times (the
streaming passes); ``python``, an interpreter loop (the studio's per-frame glue). ``host`` is
their geometric mean, with ``scaling``, how much faster the arithmetic ran on every thread than
on one: 2 on two cores of its own; on this VM, whose two cores share their host's cores with
other tenants, it was 1.3-1.9 within minutes.
"""

from __future__ import annotations

import argparse
import math
import statistics
import time

import numpy as np
from numba import njit, prange

from hairtool.bench import add_common_arguments, setup, threads

HELP = "how fast this machine is now, against the reference machine the targets were set on"

#: Rows × columns of the arithmetic probe (4 KB rows: every row stays in L1) and its rounds.
ARITHMETIC_SHAPE = (64, 512)
ARITHMETIC_ROUNDS = 12_000
MEMORY_BYTES = 64 << 20
PYTHON_STEPS = 400_000
#: Median milliseconds of each probe on the reference VM at its best (its fastest medians of a day).
REFERENCE_MS = {
    "arithmetic, 1 thread": 14.0,
    "arithmetic, all threads": 7.5,
    "memory": 15.0,
    "python": 39.0,
}


def add_arguments(parser: argparse.ArgumentParser) -> None:
    add_common_arguments(parser, quick="one run of each probe", repeat=7)


@njit(cache=True, nogil=True)
def _step_row(row: np.ndarray, a: float, b: float, rounds: int) -> None:
    for _ in range(rounds):
        for i in range(row.size):
            row[i] = row[i] * a + b


@njit(cache=True, nogil=True)
def _step_rows_serial(y, a, b, rounds):
    """Every element of ``y`` stepped y ← y·a + b, ``rounds`` times, row after row."""
    for r in range(y.shape[0]):
        _step_row(y[r], a, b, rounds)


@njit(cache=True, nogil=True, parallel=True)
def _step_rows_parallel(y, a, b, rounds):
    """:func:`_step_rows_serial`, the rows shared among the threads. (A function of its own: two
    jits of one Python function share its cache entry, parallel or not.)"""
    for r in prange(y.shape[0]):
        _step_row(y[r], a, b, rounds)


def step_rows_reference(y: np.ndarray, a: float, b: float, rounds: int) -> np.ndarray:
    """The numpy twin of the arithmetic probe."""
    y = y.copy()
    for _ in range(rounds):
        y = y * a + b
    return y


def _python_loop(steps: int) -> int:
    """Attribute reads, a dict, integer arithmetic: what per-frame glue code does."""
    table: dict[int, int] = {}
    total = 0
    for i in range(steps):
        key = i & 255
        total += table.get(key, 0) ^ i
        table[key] = total & 0xFFFF
    return total


def _probes() -> dict[str, object]:
    y = np.linspace(0.0, 1.0, ARITHMETIC_SHAPE[0] * ARITHMETIC_SHAPE[1]).reshape(ARITHMETIC_SHAPE)
    a, b = 0.999999, 1e-6  # a fixed point at 1: the values stay normal numbers
    src = np.ones(MEMORY_BYTES // 8)
    dst = np.empty_like(src)
    return {
        "arithmetic, 1 thread": lambda: _step_rows_serial(y, a, b, ARITHMETIC_ROUNDS),
        "arithmetic, all threads": lambda: _step_rows_parallel(y, a, b, ARITHMETIC_ROUNDS),
        "memory": lambda: [np.copyto(dst, src) for _ in range(4)],
        "python": lambda: _python_loop(PYTHON_STEPS),
    }


def run(args: argparse.Namespace) -> list[dict]:
    repeat = setup(args)
    probes = _probes()
    for fn in probes.values():  # compile, and fault the copy's pages in
        fn()
    times: dict[str, list[float]] = {name: [] for name in probes}
    for _ in range(repeat):  # in turn, so that a busy moment falls on every probe
        for name, fn in probes.items():
            t0 = time.perf_counter()
            fn()
            times[name].append((time.perf_counter() - t0) * 1e3)
    rows = []
    for name, ts in times.items():
        ms = statistics.median(ts)
        ref = REFERENCE_MS[name]
        rows.append({"probe": name, "ms": ms, "reference_ms": ref, "speed": ref / ms})
    speed = math.exp(sum(math.log(r["speed"]) for r in rows) / len(rows))
    one, every = (statistics.median(times[f"arithmetic, {t}"]) for t in ("1 thread", "all threads"))
    summary = {"probe": "host", "ms": None, "reference_ms": None, "speed": speed, "scaling": one / every}
    rows.append({**summary, "threads": threads()})
    return rows
