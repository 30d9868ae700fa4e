"""The studio loads its cached kernels while it idles after an open, so that an artist's first
stroke waits for none of them; it never loads while a button is held in the viewport."""

from __future__ import annotations

import json
import os
import subprocess
import sys

import pytest

pytestmark = pytest.mark.gui

#: A studio on a small scalp, then a comb stroke; ``wait``: after the preload has finished (what
#: the studio does in its idle time), ``now``: at once. Prints the numba kernels the stroke
#: loaded from the cache or compiled.
SCRIPT = r"""
import gc, json, sys, tempfile, time
import numpy as np
from numba.core import event
from numba.core.dispatcher import Dispatcher

compiled = []
class Compiles(event.Listener):
    def on_start(self, e):
        compiled.append(e.data["dispatcher"].py_func.__qualname__)
    def on_end(self, e):
        pass
event.register("numba:compile", Compiles())

from app.surface import configure_gl
configure_gl()
from PySide6.QtCore import QSettings, Qt
from PySide6.QtWidgets import QApplication
from app.ui.qt_utils import send_mouse
from app.ui.window import MainWindow
from hairtool import samples

app = QApplication([])
settings = QSettings(tempfile.mkdtemp() + "/studio.ini", QSettings.Format.IniFormat)
w = MainWindow(groom=samples.scalp(strands=300, vertices=12), settings=settings)
w.ask_save_changes = lambda: "discard"
w.resize(640, 480)
w.show()
app.processEvents()
if sys.argv[1] == "wait":
    deadline = time.perf_counter() + 120
    while not w.kernel_preload.done and time.perf_counter() < deadline:
        app.processEvents()
    assert w.kernel_preload.done
w.scene.set_brush("comb")
v = w.viewport
v.draw_now()

def loads():
    return sum(sum(d._cache_hits.values()) for d in gc.get_objects() if isinstance(d, Dispatcher))

before, compiled[:] = loads(), []
tip = v.project(w.scene.result.tips[:1])[0]
left = Qt.MouseButton.LeftButton
send_mouse(v, "press", tip, left, left, None)
for f in np.linspace(0.0, 1.0, 6)[1:]:
    send_mouse(v, "move", tip + f * np.array([60.0, 5.0]), None, left, None)
    v.draw_now()
send_mouse(v, "release", tip + np.array([60.0, 5.0]), left, None, None)
v.draw_now()
assert w.undo_stack.count() == 1
print(json.dumps({"loaded": loads() - before, "compiled": compiled, "preloaded": w.kernel_preload.loaded}))
w.close()
"""


def _stroke(when: str) -> dict:
    out = subprocess.run(
        [sys.executable, "-c", SCRIPT, when], env=dict(os.environ), capture_output=True, text=True,
        timeout=900, check=False,
    )  # fmt: skip
    assert out.returncode == 0, out.stderr[-3000:]
    return json.loads(out.stdout.strip().splitlines()[-1])


def test_a_first_stroke_after_the_idle_preload_loads_and_compiles_no_kernel():
    at_once = _stroke("now")  # (and the cache holds every kernel of the stroke afterwards)
    assert at_once["loaded"] + len(at_once["compiled"]) > 0  # without the preload the stroke waits
    after = _stroke("wait")
    assert after["preloaded"] > 0
    assert after["loaded"] == 0 and not after["compiled"], after


def test_the_preload_waits_while_a_button_is_held(qtbot):
    from app.ui.kernel_preload import KernelPreload

    held = [True]
    preload = KernelPreload(lambda: held[0])
    preload.start()
    qtbot.wait(300)
    assert not preload.done and preload.loaded == 0
    held[0] = False
    qtbot.waitUntil(lambda: preload.done, timeout=60_000)
