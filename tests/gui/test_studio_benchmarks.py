"""The timeline benchmark runs to the end and reports every number (it times nothing here; the
drag benchmark's smoke test is in test_studio_model)."""

from __future__ import annotations

import json
import math

import pytest

pytestmark = pytest.mark.gui


def _numbers_ok(rows, columns):
    for row in rows:
        for c in columns:
            v = row[c]
            number = isinstance(v, int | float) and math.isfinite(v) and v >= 0
            assert v is None or v == "-" or number, (c, row)


def test_timeline_benchmark_runs_through_and_closes_its_window(qapp, capsys):
    from PySide6.QtWidgets import QApplication

    from app import bench_timeline

    argv = ["--strands", "20", "--vertices", "6", "--frames", "12", "--moves", "3", "--json"]
    assert bench_timeline.main(argv) == 0
    rows = json.loads(capsys.readouterr().out)
    assert any("scrub" in r["what"] for r in rows) and any("solve" in r["what"] for r in rows)
    _numbers_ok(rows, ("ms",))
    QApplication.processEvents()
    assert not [w for w in QApplication.topLevelWidgets() if w.isVisible()]


@pytest.mark.slow(seconds=12)
def test_the_drag_benchmark_as_a_command_prints_its_table_and_exits_cleanly(tmp_path):
    """As a script runs it: its own process, its window deleted before the interpreter ends (a
    window left to ``deleteLater`` with no event loop was torn down at exit, after its display
    connection: a segfault after the table)."""
    import os
    import subprocess
    import sys

    from tests.conftest import GROOMS

    groom = str(GROOMS / "sintel_hair.tfx")
    done = subprocess.run(
        [sys.executable, "-m", "app.bench", "--groom", groom, "--moves", "3", "--json"],
        capture_output=True, text=True, timeout=300, check=False, env=dict(os.environ, QT_QPA_PLATFORM="xcb"),
    )  # fmt: skip
    assert done.returncode == 0, done.stderr[-2000:]
    rows = json.loads(done.stdout)
    assert rows and rows[0]["moves"] == 3
