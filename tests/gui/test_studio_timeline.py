"""The timeline dock in a real window: scrubbing moves the viewport's frame, both key rows show
exactly the engine's keys, the key-count slider updates rows and curves, view modes, key edits
with undo, and a cancelled solve that leaves the old keys."""

from __future__ import annotations

import numpy as np
import pytest
from PySide6.QtGui import QColor, QImage

from app.ui.timeline_plots import DP_COLOUR, UNIFORM_COLOUR
from hairtool import samples
from hairtool.keys import session as ks
from hairtool.keys.costs import cost_table
from hairtool.keys.dp import select_keys, uniform_keys
from hairtool.keys.edit import edit_animation
from hairtool.keys.features import hair_features
from hairtool.keys.reconstruct import interpolate_at, position_errors, reconstruct
from hairtool.simulate.sway import sway_animation

pytestmark = pytest.mark.gui

N_FRAMES = 40


@pytest.fixture
def studio(make_window):
    """A window with a 12-strand comb and a 40-frame swaying animation with a flick at 27."""
    w = make_window(groom=samples.comb(strands=12, vertices=8), size=(1400, 900))
    anim = sway_animation(w.scene.result, N_FRAMES, 24.0, flick_frame=27)
    w.animation.load_animation(anim, "sway")
    return w, anim


def drawn_like(ui, w, points, coverage: bool = False) -> float:
    """How well the viewport's pixels match ``points`` drawn with its camera: IoU of the hair
    pixels of a grab and of an offscreen render of those points (1 = the same strands); with
    ``coverage``, the fraction of the render's hair pixels that are lit in the grab."""
    from app.render.offscreen import render_image

    v = w.viewport
    ui.leave(v)
    view = ui.grab(v)
    with v.current_context() as ctx:
        image = render_image(
            w.scene.result.with_points(points),
            size=(view.shape[1], view.shape[0]),
            camera=v.camera,
            line_width=w.scene.line_width,
            ctx=ctx,
        )
    a, b = ui.hair_mask(view), ui.hair_mask(image[..., :3])
    return float((a & b).sum() / max((b if coverage else a | b).sum(), 1))


def assert_drawn(ui, w, points, *others) -> None:
    """The viewport shows ``points``, and clearly not any of ``others``."""
    iou = drawn_like(ui, w, points)
    assert iou > 0.65, iou  # (the offscreen render is multisampled, the viewport not)
    for other in others:
        other_iou = drawn_like(ui, w, other)
        assert other_iou < iou - 0.2, (iou, other_iou)


def engine_keys(anim, k: int, settings: ks.KeySettings | None = None) -> np.ndarray:
    s = settings or ks.KeySettings()
    table = cost_table(hair_features(anim, s.feature_options()), s.interp, s.curvature, s.objective)
    return select_keys(table, keys=k, objective=s.objective).keys


def image_of(widget) -> np.ndarray:
    image = widget.grab().toImage().convertToFormat(QImage.Format.Format_RGB888)
    w, h = image.width(), image.height()
    data = np.frombuffer(image.constBits(), np.uint8, count=image.bytesPerLine() * h)
    return data.reshape(h, image.bytesPerLine())[:, : w * 3].reshape(h, w, 3).copy()


def row_hits(view, row: str, colour: QColor) -> list[int]:
    """Frames whose marker in a key row shows ``colour`` (within 3 px of the frame's x)."""
    image = image_of(view)
    rect = view.row_rect(row)
    target = np.array([colour.red(), colour.green(), colour.blue()], float)
    band = image[rect.top() : rect.bottom() + 1].astype(float)
    near = np.abs(band - target).max(axis=2) < 40  # (rows, x)
    hits = []
    for f in range(view.model.n_frames):
        x = round(view.frame_to_x(f))
        if near[:, max(x - 3, 0) : x + 4].any():
            hits.append(f)
    return hits


def test_scrubbing_sets_the_frame_and_the_viewport_draws_it(ui, studio):
    w, anim = studio
    view = w.timeline.view
    y = view.row_rect("curves").center().y()
    first = ui.grab(w.viewport)
    ui.send_mouse(view, "press", (view.frame_to_x(17), y), ui_left(), ui_left())
    assert w.animation.frame == 17
    assert_drawn(ui, w, anim.frames[17], anim.frames[0])
    assert w.viewport.shown_frame == 17
    ui.send_mouse(view, "move", (view.frame_to_x(33) + 2, y), None, ui_left())
    ui.send_mouse(view, "release", (view.frame_to_x(33), y), ui_left(), None)
    assert w.animation.frame == 33
    assert_drawn(ui, w, anim.frames[33], anim.frames[17])
    later = ui.grab(w.viewport)
    assert (np.abs(later.astype(int) - first).max(axis=2) > 40).mean() > 0.001  # other pixels lit
    assert w.timeline.frame_spin.value() == 33


def ui_left():
    from PySide6.QtCore import Qt

    return Qt.MouseButton.LeftButton


def test_key_rows_show_exactly_the_engines_keys(studio):
    w, anim = studio
    m, view = w.animation, w.timeline.view
    k = m.key_solve.knee  # the default count
    want = engine_keys(anim, k)
    np.testing.assert_array_equal(m.dp_keys, want)
    np.testing.assert_array_equal(m.uniform_keys, uniform_keys(N_FRAMES, k))
    assert row_hits(view, "dp", DP_COLOUR) == want.tolist()
    assert row_hits(view, "uniform", UNIFORM_COLOUR) == uniform_keys(N_FRAMES, k).tolist()
    assert row_hits(view, "dp", UNIFORM_COLOUR) == []  # the rows look different
    assert view.drawn_keys == {"dp": want.tolist(), "uniform": uniform_keys(N_FRAMES, k).tolist()}


def test_key_count_slider_updates_both_rows_and_the_curves(studio):
    w, anim = studio
    m, view, slider = w.animation, w.timeline.view, w.timeline.controls.count_slider
    assert slider.maximum() == N_FRAMES and slider.value() == m.key_solve.knee
    before = image_of(view)
    slider.setValue(9)  # as a drag of the slider does
    want = engine_keys(anim, 9)
    np.testing.assert_array_equal(m.dp_keys, want)
    assert row_hits(view, "dp", DP_COLOUR) == want.tolist()
    assert row_hits(view, "uniform", UNIFORM_COLOUR) == uniform_keys(N_FRAMES, 9).tolist()
    assert w.timeline.controls.count_spin.value() == 9
    a = m.analysis
    np.testing.assert_array_equal(a.dp.keys, want)
    np.testing.assert_array_equal(a.uniform.keys, uniform_keys(N_FRAMES, 9))
    for err, keys in ((a.dp, want), (a.uniform, uniform_keys(N_FRAMES, 9))):
        ref = position_errors(anim, reconstruct(anim, keys))
        np.testing.assert_allclose(err.mean, ref.per_frame_mean, rtol=1e-4, atol=1e-7)
        np.testing.assert_allclose(err.tip, ref.per_frame_tip, rtol=1e-4, atol=1e-7)
    curves = view.row_rect("curves")
    after = image_of(view)
    changed = np.abs(after.astype(int) - before)[curves.top() :].max(axis=2) > 30
    assert changed.mean() > 0.005  # the error curves were redrawn for the new keys
    # a click in the error-vs-count plot picks a count too
    plot = w.timeline.plot
    from PySide6.QtTest import QTest

    QTest.mouseClick(plot, ui_left(), pos=plot.rect().center())
    assert m.dp_keys.size == plot.count_at(plot.rect().center().x())


def test_tau_budget_objective_and_interpolation_controls(studio):
    w, anim = studio
    m, c = w.animation, w.timeline.controls
    c.mode.setCurrentIndex(c.mode.findData("tau"))
    c.mode.activated.emit(c.mode.currentIndex())
    c.tau.spin.setValue(0.05)
    assert m.settings.mode == "tau" and m.settings.tau == pytest.approx(0.05)
    table = m.key_solve.table  # tau is a share of the two-key error
    np.testing.assert_array_equal(m.dp_keys, select_keys(table, penalty=0.05 * table[0, -1]).keys)
    c.interp.setCurrentIndex(c.interp.findData("hermite"))
    c.interp.activated.emit(c.interp.currentIndex())
    assert m.key_solve.table_key[1] == "hermite"
    c.objective.setCurrentIndex(c.objective.findData("worst"))
    c.objective.activated.emit(c.objective.currentIndex())  # tau needs the total objective
    assert w.errors and "tau" in w.errors[-1][1]
    assert m.settings.objective == "total" and c.objective.currentData() == "total"
    c.budget.spin.setValue(0.5)
    assert m.settings.mode == "budget"
    np.testing.assert_array_equal(m.dp_keys, select_keys(m.key_solve.table, budget=0.5).keys)
    c.samples.setValue(6)
    c.tip_weight.setValue(3.0)
    c.curvature.setValue(0.5)
    s = m.settings
    assert (s.samples, s.tip_weight, s.curvature) == (6, 3.0, 0.5)
    table = cost_table(hair_features(anim, s.feature_options()), "hermite", 0.5, "total")
    np.testing.assert_array_equal(m.key_solve.table, table)


def test_view_modes_draw_the_reconstruction_the_ghost_and_the_error_colours(ui, studio):
    w, anim = studio
    m, v = w.animation, w.viewport
    m.set_frame(11)
    rebuilt = interpolate_at(ks.key_poses_of(anim, m.dp_keys, "linear"), [11], np.float32)[0]
    assert not np.allclose(rebuilt, anim.frames[11])
    m.set_view_mode("reconstruction")
    assert_drawn(ui, w, rebuilt, anim.frames[11])
    np.testing.assert_allclose(v.frame_points, rebuilt, atol=1e-6)
    m.set_view_mode("original")
    without_ghost = drawn_like(ui, w, rebuilt, coverage=True)
    m.set_view_mode("ghost")  # the original over the reconstruction: both are on screen
    assert drawn_like(ui, w, anim.frames[11], coverage=True) > 0.75
    assert drawn_like(ui, w, rebuilt, coverage=True) > max(0.7, without_ghost + 0.15)
    np.testing.assert_array_equal(v.frame_points, anim.frames[11])
    np.testing.assert_allclose(v.renderer.ghost_points, rebuilt, atol=1e-6)
    assert w.timeline.controls.view.currentData() == "ghost"
    m.set_view_mode("error")
    ui.grab(v)
    assert v.renderer.ghost_points is None and v.renderer.use_vertex_colors
    err = np.linalg.norm(anim.frames[11] - rebuilt, axis=1)
    # hotter (brighter) where the reconstruction misses more: roots (error ~0) are darkest
    assert np.corrcoef(err, v.frame_colors.sum(axis=1))[0, 1] > 0.8
    image = ui.grab(v).astype(int)
    lit = ui.hair_mask(image)
    assert np.median(image[lit][:, 0] - image[lit][:, 2]) > 40  # the heat ramp: red, orange, yellow
    m.set_view_mode("original")
    ui.grab(v)
    assert not v.renderer.use_vertex_colors and v.frame_colors is None


def test_dragging_at_a_key_edits_it_spreads_through_the_residuals_and_undoes(ui, studio):
    w, anim = studio
    m, v = w.animation, w.viewport
    keys = m.dp_keys.copy()
    key = int(keys[1])
    m.set_frame(key)
    ui.grab(v)
    tip = anim.frames[key][anim.topology.tip_indices[6]]
    start = v.project(tip[None])[0]
    ui.drag(v, start, start + np.array([60.0, -40.0]))
    edited = m.animation.frames
    assert not np.array_equal(edited[key], anim.frames[key])
    roots = anim.topology.root_indices
    np.testing.assert_array_equal(edited[:, roots], anim.frames[:, roots])  # roots stay
    whole = edit_animation(anim, keys, {key: edited[key]}).frames
    np.testing.assert_array_equal(edited, whole)  # the residual scheme over every frame
    lo, hi = int(keys[0]), int(keys[2])
    np.testing.assert_array_equal(edited[: lo + 1], anim.frames[: lo + 1])
    np.testing.assert_array_equal(edited[hi:], anim.frames[hi:])
    assert not np.array_equal(edited[(lo + key) // 2], anim.frames[(lo + key) // 2])
    np.testing.assert_array_equal(m.dp_keys, keys)  # the keys stay
    assert_drawn(ui, w, edited[key], anim.frames[key])
    # the new animation is the first step of the document, the key edit the second
    assert w.undo_stack.count() == 2 and w.undo_stack.undoText() == f"Edit key {key}"
    w.undo_stack.undo()
    np.testing.assert_array_equal(m.animation.frames, anim.frames)
    w.undo_stack.redo()
    np.testing.assert_array_equal(m.animation.frames, whole)


def test_dragging_between_keys_edits_nothing(ui, studio):
    w, anim = studio
    m, v = w.animation, w.viewport
    between = int(m.dp_keys[0] + m.dp_keys[1]) // 2
    m.set_frame(between)
    ui.grab(v)
    start = v.project(anim.frames[between][anim.topology.tip_indices[6]][None])[0]
    ui.drag(v, start, start + np.array([60.0, -40.0]))
    assert m.animation is anim and w.undo_stack.count() == 1  # the new animation's step only
    assert "key frame" in w.statusBar().currentMessage()


def test_a_cancelled_solve_leaves_the_old_keys(studio):
    w, anim = studio
    m, c = w.animation, w.timeline.controls
    m.inline_values = 0  # solve in the background, as for a long animation
    keys, solve, analysis = m.dp_keys.copy(), m.key_solve, m.analysis
    c.interp.setCurrentIndex(c.interp.findData("hermite"))
    c.interp.activated.emit(c.interp.currentIndex())
    assert m.busy and m.settings.interp == "hermite"
    assert w.job_status.isVisibleTo(w) and "Solving keys" in w.job_status.label.text()
    w.job_status.cancel_button.click()
    assert w.jobs.wait(20)
    assert m.key_solve is solve and m.analysis is analysis and not m.busy
    np.testing.assert_array_equal(m.dp_keys, keys)
    assert m.settings.interp == "linear" and c.interp.currentData() == "linear"
    assert not w.job_status.isVisibleTo(w)
    # the same solve, not cancelled, lands from the worker thread
    c.interp.setCurrentIndex(c.interp.findData("hermite"))
    c.interp.activated.emit(c.interp.currentIndex())
    assert w.jobs.wait(20)
    knee = m.key_solve.knee  # the default count, on the Hermite table
    np.testing.assert_array_equal(m.dp_keys, engine_keys(anim, knee, ks.KeySettings(interp="hermite")))
    assert m.analysis is not analysis and not m.busy


def test_slider_moves_during_background_work_end_on_the_last_count(studio):
    w, anim = studio
    m, slider = w.animation, w.timeline.controls.count_slider
    m.inline_values = 0
    for k in (5, 6, 7, 8):
        slider.setValue(k)  # rows answer at once; each error pass replaces the previous one
        assert m.dp_keys.size == k
    assert m.busy
    assert w.jobs.wait(20)
    want = engine_keys(anim, 8)
    np.testing.assert_array_equal(m.dp_keys, want)
    np.testing.assert_array_equal(m.analysis.dp.keys, want)
    assert not m.busy and not w.job_status.isVisibleTo(w)


def test_export_still_writes_the_frame_on_screen(tmp_path, studio):
    import imageio.v3 as iio

    w, _ = studio
    shots = []
    for frame in (0, 27):
        w.animation.set_frame(frame)
        path = tmp_path / f"frame{frame}.png"
        assert w.export_still(path, size=(160, 120))
        shots.append(iio.imread(path).astype(int))
    assert not w.errors
    assert (np.abs(shots[0] - shots[1]).max(axis=2) > 40).mean() > 0.002
