"""The viewport under a brush: a move that changed a few strands writes only those strands'
vertices to the GPU (bytes counted at :func:`app.render.strand_gpu.write_buffer`), and after the
stroke the vertex buffer holds, byte for byte, what a whole upload of the groom would."""

from __future__ import annotations

import numpy as np
import pytest
from PySide6.QtCore import Qt

from app.render import strand_gpu
from hairtool import samples

pytestmark = pytest.mark.gui


@pytest.mark.parametrize("shaded", [False, True])
def test_a_comb_move_uploads_the_strands_it_moved_and_the_buffer_is_a_whole_upload(
    ui, make_window, monkeypatch, shaded
):
    w = make_window(groom=samples.scalp(strands=3000, vertices=12, seed=4))
    s, v = w.scene, w.viewport
    s.set_params(s.params.replace(freeze=False, clump=False))
    s.set_colour_mode("hair" if shaded else "root-to-tip")
    v.renderer.strand_raster = "gl"  # on llvmpipe the default is the CPU raster: no GL upload
    ui.grab(v)
    s.set_brush("comb")
    s.set_radius(0.08 * float(np.max(s.result.bounds[1] - s.result.bounds[0])))
    v.makeCurrent()
    buffer = v.renderer.position_buffer
    v.doneCurrent()
    full = s.result.points.nbytes
    sent: list[int] = []
    real = strand_gpu.write_buffer

    def counting(buf, data, offset=0):
        if buf is buffer:
            sent.append(int(np.asarray(data).nbytes))
        return real(buf, data, offset)

    monkeypatch.setattr(strand_gpu, "write_buffer", counting)
    before = s.result.points.copy()
    tip = int(np.argmin(v.camera.depth(s.result.tips)))  # the tip nearest the eye
    start = v.project(s.result.tips[tip : tip + 1])[0]
    left = Qt.MouseButton.LeftButton
    ui.send_mouse(v, "press", start, left, left)
    per_move = []
    for k in range(1, 7):
        ui.send_mouse(v, "move", start + k * np.array([10.0, 2.0]), None, left)
        s.moves.drain()  # the move's result (the engine runs it off the GUI thread)
        before_draw = sum(sent)
        v.draw_now()  # each move's frame, as the screen would show it
        per_move.append(sum(sent) - before_draw)
    ui.send_mouse(v, "release", start + 6 * np.array([10.0, 2.0]), left, None)
    v.draw_now()
    changed = (s.result.points != before).any(axis=1)
    assert 0 < changed.sum() < 0.3 * len(changed)  # the comb moved some strands, not all
    assert all(0 < b < 0.4 * full for b in per_move), (per_move, full)  # a part of the buffer each
    v.makeCurrent()
    on_gpu = buffer.read()
    colours = v.renderer.color_buffer.read() if shaded else None
    v.doneCurrent()
    assert on_gpu == np.ascontiguousarray(s.result.points, np.float32).tobytes()
    if shaded:  # the shade of the moved strands alone was redone, and it is the whole shade
        from app.render.hair_shading import light_and_eye, shade

        r = v.renderer
        light, eye = light_and_eye(*v.camera.basis())
        want = shade(s.result.points, s.result.offsets, r._ramp_vertex_colors(), light, eye, r.hair_look)
        assert colours == want.tobytes()
