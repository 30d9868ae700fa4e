"""A pytest plugin that records each test's CPU and wall seconds (set-up, call and tear-down
together; CPU includes the children a test waited for) and the seconds numba spent compiling
kernels in the test's own process (a cold cache's share: a fresh clone compiles what the
studio's warm-up did not), with each kernel and the argument types it was compiled for, to a
JSON file, for finding what makes the suite slow:
``python -m pytest -n 0 -p tests.cpu_times tests/io`` writes ``$HAIRTOOL_TEST_TIMES`` (default
``test-times.json``; under xdist one file per worker, ``test-times.gw0.json`` …) and prints the
files by CPU and the longest compiles."""

from __future__ import annotations

import glob
import json
import os
import resource
import threading
import time
from collections import defaultdict

import pytest

_rows: dict[str, dict] = {}
_started = time.time()


def _cpu() -> float:
    own = resource.getrusage(resource.RUSAGE_SELF)
    kids = resource.getrusage(resource.RUSAGE_CHILDREN)
    return own.ru_utime + own.ru_stime + kids.ru_utime + kids.ru_stime


class _Compiles:
    """Seconds and kernels of numba's compilations (cache misses only: a kernel loaded from the
    cache sends no event), outermost ones per thread, so a kernel compiling its callees counts
    once."""

    def __init__(self) -> None:
        self.seconds = 0.0
        self.kernels: list[tuple[str, float]] = []  # (kernel and argument types, seconds)
        self._lock = threading.Lock()
        self._local = threading.local()

    def on_start(self, event) -> None:
        depth = getattr(self._local, "depth", 0)
        if depth == 0:
            self._local.started = time.perf_counter()
            func = event.data["dispatcher"].py_func
            self._local.name = f"{func.__module__}.{func.__qualname__} {event.data['args']}"
        self._local.depth = depth + 1

    def on_end(self, event) -> None:
        self._local.depth -= 1
        if self._local.depth == 0:
            took = time.perf_counter() - self._local.started
            with self._lock:
                self.seconds += took
                self.kernels.append((self._local.name, took))


_compiles = _Compiles()


def pytest_configure(config):
    from numba.core import event

    class Listener(event.Listener):  # numba takes its own listeners only
        on_start, on_end = staticmethod(_compiles.on_start), staticmethod(_compiles.on_end)

    event.register("numba:compile", Listener())


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_protocol(item, nextitem):
    cpu, wall = _cpu(), time.perf_counter()
    compiled, named = _compiles.seconds, len(_compiles.kernels)
    yield
    _rows[item.nodeid] = {
        "cpu": _cpu() - cpu,
        "wall": time.perf_counter() - wall,
        "compile": _compiles.seconds - compiled,
        "kernels": len(_compiles.kernels) - named,
        "compiled": _compiles.kernels[named:],
    }


def _path(worker: str) -> str:
    """The JSON file; each xdist worker its own (``test-times.gw0.json`` …), none overwriting
    another."""
    path = os.environ.get("HAIRTOOL_TEST_TIMES", "test-times.json")
    if not worker:
        return path
    stem, dot, ext = path.rpartition(".")
    return f"{stem}.{worker}.{ext}" if dot else f"{path}.{worker}"


def pytest_sessionfinish(session):
    if not _rows:
        return
    with open(_path(os.environ.get("PYTEST_XDIST_WORKER", "")), "w") as f:
        json.dump(_rows, f, indent=1)


def _workers_rows() -> None:
    """Under xdist the workers hold the rows: the controller reads the files they wrote in this
    run (they finish before it prints)."""
    for path in glob.glob(glob.escape(_path("gw")).replace(".gw", ".gw*", 1)):
        if os.path.getmtime(path) >= _started:
            with open(path) as f:
                _rows.update(json.load(f))


def pytest_terminal_summary(terminalreporter):
    if not _rows and not os.environ.get("PYTEST_XDIST_WORKER"):
        _workers_rows()
    files: dict[str, list[float]] = defaultdict(lambda: [0.0, 0.0, 0.0, 0])
    for node, row in _rows.items():
        f = files[node.split("::")[0]]
        for i, key in enumerate(("cpu", "wall", "compile", "kernels")):
            f[i] += row[key]
    terminalreporter.write_sep("-", "CPU, wall and numba-compile seconds (kernels compiled) per file")
    for name, (cpu, wall, compiled, kernels) in sorted(files.items(), key=lambda kv: -kv[1][0]):
        terminalreporter.write_line(f"{cpu:8.1f} {wall:8.1f} {compiled:8.1f} ({kernels:3d})  {name}")
    total = [sum(f[i] for f in files.values()) for i in range(4)]
    terminalreporter.write_line(f"{total[0]:8.1f} {total[1]:8.1f} {total[2]:8.1f} ({total[3]:3d})  all")
    compiled = [(t, k, node) for node, row in _rows.items() for k, t in row.get("compiled", [])]
    compiled.sort(reverse=True)
    if compiled:
        terminalreporter.write_sep("-", "the longest compiles: seconds, kernel and argument types, test")
        for took, kernel, node in compiled[:25]:
            terminalreporter.write_line(f"{took:8.1f}  {kernel[:160]}  {node}")
    slow = sorted(_rows.items(), key=lambda kv: -kv[1]["cpu"])[:15]
    terminalreporter.write_sep("-", "slowest tests by CPU")
    for node, row in slow:
        terminalreporter.write_line(f"{row['cpu']:8.1f} {row['wall']:8.1f} {row['compile']:8.1f}  {node}")
