"""A worker that dies costs one failed test: every other test runs once and the run ends
(``tests/xdist_recovery.py``; xdist's own file scheduling ran the test again and could wait
forever at the end)."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import pytest

HERE = Path(__file__).resolve().parent

CONFTEST = f"""
import importlib.util

def pytest_configure(config):
    spec = importlib.util.spec_from_file_location("recovery", {str(HERE / "xdist_recovery.py")!r})
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    config.pluginmanager.register(module.Plugin(), "xdist-recovery")
"""

# file 6 kills its worker in its second test, once (a second run of that test would pass)
TEST_FILE = """
import os, pathlib, signal, time

def test_1():
    time.sleep(0.05)

def test_2():
    flag = pathlib.Path(__file__).with_suffix(".died")
    if __file__.endswith("test_6.py") and not flag.exists():
        flag.touch()
        os.kill(os.getpid(), signal.SIGKILL)

def test_3():
    time.sleep(0.05)
"""


@pytest.mark.slow(seconds=8)
def test_a_dead_worker_fails_one_test_and_the_run_ends(tmp_path):
    (tmp_path / "conftest.py").write_text(CONFTEST)
    for i in range(10):
        (tmp_path / f"test_{i}.py").write_text(TEST_FILE)
    done = subprocess.run(
        [sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", "-p", "no:faulthandler",
         "-n", "2", "--dist", "loadfile", "--no-loadscope-reorder", "-o", "addopts=", str(tmp_path)],
        cwd=tmp_path, capture_output=True, text=True, timeout=120, check=False,
    )  # fmt: skip
    out = done.stdout + done.stderr
    assert done.returncode == 1, out
    assert re.search(r"\b1 failed, 29 passed\b", out), out
    assert "crashed while running 'test_6.py::test_2'" in out, out
