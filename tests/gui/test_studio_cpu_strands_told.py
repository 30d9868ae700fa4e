"""A comb drag over CPU strands: the engine's region reaches the raster (it compares only the
vertices the move wrote), and every frame's strands are the bytes of a fresh full draw."""

from __future__ import annotations

import numpy as np
import pytest
from PySide6.QtCore import Qt

from app.render.soft_raster import StrandRaster
from hairtool import samples

pytestmark = pytest.mark.gui


def test_a_comb_drag_tells_the_raster_what_moved_and_draws_the_bytes_of_a_fresh_draw(
    ui, make_window, monkeypatch
):
    w = make_window(groom=samples.scalp(strands=1500, vertices=10, seed=4))
    s, v = w.scene, w.viewport
    assert v.renderer.line_method() == "cpu"
    ui.grab(v)
    s.set_brush("comb")
    s.set_radius(0.08 * float(np.max(s.result.bounds[1] - s.result.bounds[0])))
    told, frames = [], []
    real = StrandRaster.draw

    def draw(raster, points, starts, colors, mvp, size, width, clear=(0, 0, 0, 0), scale=None, changed=None):
        rgba, depth = real(raster, points, starts, colors, mvp, size, width, clear, scale, changed)
        told.append(changed is not None)
        fresh = real(StrandRaster(), points, starts, colors, mvp, size, width, clear, scale)
        frames.append(np.array_equal(rgba, fresh[0]) and np.array_equal(depth, fresh[1]))
        return rgba, depth

    monkeypatch.setattr(StrandRaster, "draw", draw)
    tip = int(np.argmin(v.camera.depth(s.result.tips)))  # the tip nearest the eye
    start = v.project(s.result.tips[tip : tip + 1])[0]
    left = Qt.MouseButton.LeftButton
    ui.send_mouse(v, "press", start, left, left)
    for k in range(1, 6):
        ui.send_mouse(v, "move", start + k * np.array([8.0, 3.0]), None, left)
        s.moves.drain()  # the move's result (the engine runs it off the GUI thread)
        v.draw_now()
    ui.send_mouse(v, "release", start + 5 * np.array([8.0, 3.0]), left, None)
    v.draw_now()
    assert all(frames) and len(frames) >= 6
    assert sum(told) >= 3  # the drag's frames were told what moved
