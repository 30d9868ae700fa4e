"""Quitting is quiet: the studio closing during a first start's warm-up, and the warm-up child
whose studio is gone (however it went), end without a traceback or a stray process."""

from __future__ import annotations

import os
import subprocess
import sys
import time

import pytest

from app.ui import kernel_warmup

pytestmark = pytest.mark.gui


def _cold_env(tmp_path) -> dict:
    """An empty kernel cache and a fresh home: the studio starts as on a first start."""
    for name in ("numba", "cache", "home", "config"):
        (tmp_path / name).mkdir()
    return {
        **os.environ,
        "NUMBA_CACHE_DIR": str(tmp_path / "numba"),
        "XDG_CACHE_HOME": str(tmp_path / "cache"),
        "XDG_CONFIG_HOME": str(tmp_path / "config"),
        "HOME": str(tmp_path / "home"),
    }


def _gone(pid: int, timeout_s: float = 10.0) -> bool:
    end = time.monotonic() + timeout_s
    while time.monotonic() < end:
        try:
            os.kill(pid, 0)
        except ProcessLookupError:
            return True
        try:  # our own child: reap it
            if os.waitpid(pid, os.WNOHANG)[0] == pid:
                return True
        except ChildProcessError:
            pass
        time.sleep(0.1)
    return False


def test_the_warm_up_ends_quietly_when_its_studio_is_gone(tmp_path):
    warm_up = subprocess.Popen(
        [sys.executable, "-m", "app.ui.kernel_warmup", "--with-parent"],
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        env=_cold_env(tmp_path),
        cwd=tmp_path,
    )
    time.sleep(1.0)  # compiling its first kernels by now
    warm_up.stdout.close()  # the studio's end of both pipes closes, as when it dies
    warm_up.stdin.close()
    try:
        code = warm_up.wait(timeout=30)  # a cold warm-up takes a minute or more
    except subprocess.TimeoutExpired:
        warm_up.kill()
        pytest.fail("the warm-up went on compiling for a studio that is gone")
    err = warm_up.stderr.read().decode(errors="replace")
    assert code == 0 and "Traceback" not in err and "Error" not in err, err


ONE_STEP_LANE = r"""
from app.ui import kernel_warmup as kw
kw.STEPS = (("one step", lambda: None),)
kw.LANES = (("one step",),)
kw.entry(["--lane", "1", "--with-parent"])
"""


def test_a_lane_the_studio_started_ends_cleanly_when_its_steps_are_done(tmp_path):
    """Its studio still there (standard input open): the lane reports its step, records it and
    exits 0, with nothing on standard error (it used to abort at shutdown, exit 134)."""
    lane = subprocess.Popen(
        [sys.executable, "-c", ONE_STEP_LANE],
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        env=_cold_env(tmp_path),
    )
    try:
        code = lane.wait(timeout=120)  # stdin stays open: the studio is still running
    finally:
        lane.stdin.close()
    out, err = lane.stdout.read().decode(), lane.stderr.read().decode(errors="replace")
    assert code == 0 and err == "", err
    assert out.splitlines() == ["step 1 1 one step"]


QUIT_SOON = r"""
import sys
from PySide6.QtCore import QTimer
from app import main
from app.ui import window

start = window.MainWindow.start_warmup

def start_then_quit(self):
    start(self)
    print("warm-up", *(p.processId() for p in self.engine_start.processes), flush=True)
    QTimer.singleShot(1500, self.close)  # the artist quits while the kernels compile

window.MainWindow.start_warmup = start_then_quit
sys.exit(main.main([]))
"""


def test_quitting_during_the_first_start_warm_up_is_quiet(tmp_path):
    try:  # once, the window went on compiling every kernel for minutes after the click
        run = subprocess.run(
            [sys.executable, "-X", "faulthandler", "-c", QUIT_SOON],
            capture_output=True,
            text=True,
            timeout=60,
            env=_cold_env(tmp_path),
            cwd=tmp_path,
        )
    except subprocess.TimeoutExpired:
        pytest.fail("Quit during the warm-up did not end the studio within a minute")
    assert run.returncode == 0, run.stderr[-3000:]
    assert "Traceback" not in run.stderr and "Fatal" not in run.stderr, run.stderr[-3000:]
    line = next(line for line in run.stdout.splitlines() if line.startswith("warm-up"))
    pids = [int(p) for p in line.split()[1:]]
    assert len(pids) == len(kernel_warmup.LANES)  # one process per lane
    for pid in pids:
        assert pid > 0 and _gone(pid), "a warm-up outlived the studio"
