"""A stroke's moves run off the GUI thread (app.ui.engine_thread): with a slowed engine the brush
circle still follows the mouse at every frame, drawn over the last image; the moves that came in
meanwhile reach the engine together; and the stroke's log, result and undo step are those of the
same moves run one by one on the GUI thread."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from PySide6.QtCore import Qt

from hairtool import samples

pytestmark = pytest.mark.gui

LEFT = Qt.MouseButton.LeftButton
SLOW_S = 0.25  # the injected engine delay: far longer than a frame


def small(make_window):
    w = make_window(groom=samples.scalp(strands=150, vertices=10))
    w.scene.set_brush("comb")
    w.scene.set_intensity(1.0)
    return w


def circle_centre(v) -> tuple[float, float]:
    """Where the last paint put the brush circle (pixels of the framebuffer)."""
    with v.current_context():
        ring = np.frombuffer(v.renderer.overlay.vbo.read(), np.float32).reshape(-1, 2)
    return tuple(ring.mean(axis=0)[:2])


def path(v, n: int, dx: float = 8.0) -> list[np.ndarray]:
    start = np.array([v.width() / 2.0 - n * dx / 2.0, v.height() / 2.0])
    return [start + np.array([i * dx, 0.3 * i]) for i in range(n + 1)]


def test_with_a_slow_engine_the_circle_follows_every_move_within_one_frame(ui, make_window):
    w = small(make_window)
    v, s = w.viewport, w.scene
    s.moves.delay_s = SLOW_S
    points = path(v, 6)
    ui.send_mouse(v, "press", points[0], LEFT, LEFT)
    v.draw_now()
    before_draws = v.scene_draws
    dpr = v.devicePixelRatioF()
    for p in points[1:]:
        ui.send_mouse(v, "move", p, None, LEFT)
        v.draw_now()  # the one frame after the move
        assert s.moves.busy  # the engine has not caught up …
        cx, cy = circle_centre(v)  # … and the circle is where the mouse is
        assert abs(cx - p[0] * dpr) < 1.0 and abs(cy - p[1] * dpr) < 1.0
    # every one of those frames was the last image with the circle over it
    assert v.scene_draws == before_draws
    ui.send_mouse(v, "release", points[-1], LEFT)
    assert not s.moves.busy
    # moves that came in while the engine worked went to it together
    assert s.moves.runs < len(points)


def test_a_landed_result_is_drawn_and_the_circle_is_copied_with_the_last_image(ui, make_window, qtbot):
    w = small(make_window)
    v, s = w.viewport, w.scene
    s.moves.delay_s = 0.05
    points = path(v, 3, dx=20.0)
    ui.send_mouse(v, "press", points[0], LEFT, LEFT)
    for p in points[1:]:
        ui.send_mouse(v, "move", p, None, LEFT)
    landed = ui.record(s.moves.landed)
    draws = v.scene_draws
    qtbot.waitUntil(lambda: not s.moves.busy, timeout=5000)
    assert landed  # the result came back through the queued signal, not a drain
    v.draw_now()
    assert v.scene_draws > draws  # the new points are drawn
    ui.send_mouse(v, "release", points[-1], LEFT)
    v.draw_now()
    # hovering: the image is kept, only the circle moves, and it looks as a full draw does
    ui.send_mouse(v, "move", points[0], None, None)
    v.draw_now()
    draws = v.scene_draws
    ui.send_mouse(v, "move", points[1], None, None)
    copied = ui.grab(v)
    assert v.scene_draws == draws
    v.update()
    full = ui.grab(v)
    assert v.scene_draws == draws + 1
    assert np.array_equal(copied, full)


def stroke(ui, w, points, delay: float, threaded: bool):
    s, v = w.scene, w.viewport
    s.moves.delay_s, s.moves.threaded = delay, threaded
    ui.send_mouse(v, "press", points[0], LEFT, LEFT)
    for p in points[1:]:
        ui.send_mouse(v, "move", p, None, LEFT)
    ui.send_mouse(v, "release", points[-1], LEFT)
    return s.pipeline.strokes, s.result.points.copy(), v.stroke_touched


@settings(max_examples=3, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(
    steps=st.lists(st.tuples(st.floats(-25, 25), st.floats(-25, 25)), min_size=1, max_size=8),
    brush=st.sampled_from(["comb", "align", "smooth", "puff"]),
    symmetry=st.booleans(),
)
def test_a_threaded_stroke_logs_and_gives_what_the_same_moves_give_one_by_one(
    ui, make_window, steps, brush, symmetry
):
    w = small(make_window)
    w.scene.set_brush(brush)
    w.scene.set_symmetry(symmetry)
    v = w.viewport
    start = np.array([v.width() / 2.0, v.height() / 2.0])
    points = list(start + np.cumsum(np.array([(0.0, 0.0), *steps]), axis=0))
    before = w.scene.result.points.copy()
    results = []
    for threaded, delay in ((False, 0.0), (True, 0.02)):
        results.append(stroke(ui, w, points, delay, threaded))
        assert w.undo_stack.count() <= 1  # the whole stroke: one undo step
        w.undo_stack.undo()
        assert w.scene.pipeline.strokes == ()
        assert np.array_equal(w.scene.result.points, before)
        w.undo_stack.clear()
    (log0, after0, touched0), (log1, after1, touched1) = results
    assert log1 == log0
    assert np.array_equal(after1, after0)
    assert touched1 == touched0
    w.close()


def test_a_window_closed_mid_stroke_ends_its_engine_thread_before_it_goes(ui, make_window):
    """Quit in the middle of a drag: the close lands the run under way and ends the worker, so
    no thread is left to hand a result to a window being deleted (a worker that emitted while
    its window was deleted crashed a CI run)."""
    import threading

    w = small(make_window)
    v, s = w.viewport, w.scene
    s.moves.delay_s = SLOW_S
    points = path(v, 3)
    ui.send_mouse(v, "press", points[0], LEFT, LEFT)
    ui.send_mouse(v, "move", points[1], None, LEFT)
    assert s.moves.busy  # the engine is still at it
    assert any(t.name.startswith("hairtool-moves") for t in threading.enumerate())
    w.close()  # (the fixture answers Discard)
    assert not s.moves.busy
    workers = ("hairtool-moves", "hairtool-frames")
    alive = [t.name for t in threading.enumerate() if t.name.startswith(workers)]
    assert alive == []  # every window closed so far in this process ended its workers
