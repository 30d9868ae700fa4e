"""A pytest plugin that records each test's CPU and wall seconds (set-up, call and tear-down
together; CPU includes the children a test waited for) to a JSON file, for finding what makes
the suite slow: ``python -m pytest -n 0 -p tests.cpu_times tests/io`` writes
``$HAIRTOOL_TEST_TIMES`` (default ``test-times.json``) and prints the files by CPU."""

from __future__ import annotations

import json
import os
import resource
import time
from collections import defaultdict

import pytest

_rows: dict[str, dict] = {}


def _cpu() -> float:
    own = resource.getrusage(resource.RUSAGE_SELF)
    kids = resource.getrusage(resource.RUSAGE_CHILDREN)
    return own.ru_utime + own.ru_stime + kids.ru_utime + kids.ru_stime


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_protocol(item, nextitem):
    cpu, wall = _cpu(), time.perf_counter()
    yield
    _rows[item.nodeid] = {"cpu": _cpu() - cpu, "wall": time.perf_counter() - wall}


def pytest_sessionfinish(session):
    if not _rows:
        return
    path = os.environ.get("HAIRTOOL_TEST_TIMES", "test-times.json")
    with open(path, "w") as f:
        json.dump(_rows, f, indent=1)


def pytest_terminal_summary(terminalreporter):
    files: dict[str, list[float]] = defaultdict(lambda: [0.0, 0.0])
    for node, row in _rows.items():
        f = files[node.split("::")[0]]
        f[0] += row["cpu"]
        f[1] += row["wall"]
    terminalreporter.write_sep("-", "CPU and wall seconds per file")
    for name, (cpu, wall) in sorted(files.items(), key=lambda kv: -kv[1][0]):
        terminalreporter.write_line(f"{cpu:8.1f} {wall:8.1f}  {name}")
    slow = sorted(_rows.items(), key=lambda kv: -kv[1]["cpu"])[:15]
    terminalreporter.write_sep("-", "slowest tests by CPU")
    for node, row in slow:
        terminalreporter.write_line(f"{row['cpu']:8.1f} {row['wall']:8.1f}  {node}")
