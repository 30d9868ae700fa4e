"""The studio lets numba's OpenMP threads wait passively (their spinning held a core the next
kernel or the draw needed: a bear comb drag took 0.76-0.89× the time with it on a shared 2-core
host), set before any kernel loads libgomp, unless the environment already says how to wait."""

from __future__ import annotations

import os
import subprocess
import sys

CODE = "import os, app; print(os.environ['OMP_WAIT_POLICY'])"


def _policy(env: dict) -> str:
    out = subprocess.run([sys.executable, "-c", CODE], env=env, capture_output=True, text=True, check=True)
    return out.stdout.strip()


def test_the_studio_waits_passively_unless_told_otherwise():
    env = {k: v for k, v in os.environ.items() if k != "OMP_WAIT_POLICY"}
    assert _policy(env) == "PASSIVE"
    assert _policy(env | {"OMP_WAIT_POLICY": "ACTIVE"}) == "ACTIVE"
