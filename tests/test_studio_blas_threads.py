"""The studio gives numpy's OpenBLAS one thread before numpy loads (its spinning workers held a
core the engine's numba threads waited for), unless the environment already says how many."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

CODE = "import app, os, numpy; print(os.environ['OPENBLAS_NUM_THREADS'], len(os.listdir('/proc/self/task')))"


def _run(env: dict) -> list[str]:
    out = subprocess.run([sys.executable, "-c", CODE], env=env, capture_output=True, text=True, check=True)
    return out.stdout.split()


@pytest.mark.skipif(not os.path.isdir("/proc/self/task"), reason="threads counted from /proc")
def test_openblas_runs_on_the_studios_own_thread_unless_told_otherwise():
    env = {k: v for k, v in os.environ.items() if k not in ("OPENBLAS_NUM_THREADS", "GOTO_NUM_THREADS")}
    assert _run(env) == ["1", "1"]  # no BLAS worker thread besides the main one
    assert _run(env | {"OPENBLAS_NUM_THREADS": "2"})[0] == "2"
