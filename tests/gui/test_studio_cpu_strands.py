"""The viewport on llvmpipe rasterizes strands on the CPU: the picture GL draws, head included."""

from __future__ import annotations

import numpy as np
import pytest

pytestmark = pytest.mark.gui


def test_cpu_strands_in_the_viewport_look_like_gl_strands_over_the_head(ui, make_window):
    w = make_window()
    assert w.open_bundled_sample() and w.scene.mesh is not None
    v = w.viewport
    ui.leave(v)
    images = {}
    for raster in ("auto", "gl", "cpu"):
        v.renderer.strand_raster = raster
        images[raster] = ui.grab(v)
        assert v.ctx.error == "GL_NO_ERROR", raster  # Qt reads its framebuffer back fine
    assert v.renderer.software_gl  # so auto is cpu
    np.testing.assert_array_equal(images["auto"], images["cpu"])
    hair = ui.hair_mask(images["gl"])
    assert 0.05 < hair.mean() < 0.9
    differ = np.abs(images["gl"].astype(int) - images["cpu"].astype(int)).max(axis=2) > 40
    assert differ.mean() < 0.01  # the same strands, in front of and behind the same head


def test_dragging_with_cpu_strands_uploads_no_positions(ui, make_window):
    w = make_window()
    v = w.viewport
    assert v.renderer.line_method() == "cpu"
    before = ui.grab(v)
    tip = v.project(w.scene.result.tips[7:8])[0]
    ui.drag(v, tip, tip + np.array([70.0, -30.0]))
    after = ui.grab(v)
    assert v.renderer._main.last_used == "cpu"  # positions stayed on the CPU while dragging
    assert (np.abs(after.astype(int) - before.astype(int)).max(axis=2) > 40).mean() > 0.001


MSAA_SCRIPT = """
import json, sys, tempfile
import numpy as np
from app.surface import configure_gl
configure_gl()
from PySide6.QtCore import QSettings
from PySide6.QtGui import QImage
from PySide6.QtWidgets import QApplication
from app.ui.window import MainWindow
app = QApplication(sys.argv[:1])
settings = QSettings(tempfile.mkdtemp() + "/s.ini", QSettings.Format.IniFormat)
w = MainWindow(settings=settings)
w.ask_save_changes = lambda: "discard"
w.resize(800, 600)
w.show()
for _ in range(30):
    app.processEvents()
w.open_bundled_sample()
v = w.viewport
out = {"samples": v.samples}
for raster in ("gl", "cpu"):
    v.renderer.strand_raster = raster
    im = v.grabFramebuffer().convertToFormat(QImage.Format.Format_RGB888)
    a = np.frombuffer(im.constBits(), np.uint8, count=im.bytesPerLine() * im.height())
    a = a.reshape(im.height(), -1)[:, : im.width() * 3].reshape(im.height(), im.width(), 3).astype(int)
    out[raster] = a
    out[raster + "_error"] = v.ctx.error
d = np.abs(out.pop("gl") - out["cpu"]).max(axis=2)
out["differ"] = float((d > 40).mean())
out["lit"] = float((out.pop("cpu").max(axis=2) > 60).mean())
print(json.dumps(out))
w.close()
"""


def test_cpu_strands_in_a_multisampled_viewport(tmp_path):
    # Qt's framebuffer is multisampled here, which moderngl cannot see: the viewport must say so.
    import json
    import os
    import subprocess
    import sys

    env = {**os.environ, "HAIRTOOL_MSAA": "4", "HAIRTOOL_STRAND_RASTER": "auto"}
    command = [sys.executable, "-c", MSAA_SCRIPT]
    run = subprocess.run(command, env=env, capture_output=True, text=True, timeout=120, cwd=tmp_path)
    assert run.returncode == 0, run.stderr
    out = json.loads(run.stdout.strip().splitlines()[-1])
    assert out["samples"] == 4
    assert out["gl_error"] == out["cpu_error"] == "GL_NO_ERROR"
    assert out["lit"] > 0.05 and out["differ"] < 0.02
