"""The viewport: colours on screen, the align drag, undo/redo of a stroke, navigation, brush size."""

from __future__ import annotations

import numpy as np
import pytest
from PySide6.QtCore import QPoint, QPointF, Qt
from PySide6.QtGui import QWheelEvent
from PySide6.QtWidgets import QApplication

from app.render.ramps import RAMPS
from hairtool import samples

pytestmark = pytest.mark.gui


def _strongest(image: np.ndarray, xy: np.ndarray, bg=(0.16, 0.17, 0.19)) -> np.ndarray:
    """At each pixel position, the colour in its 3×3 neighbourhood that differs most from the background."""
    h, w, _ = image.shape
    bg = np.round(np.asarray(bg) * 255.0)
    out = []
    for x, y in np.floor(xy).astype(int):
        patch = image[max(y - 1, 0) : min(y + 2, h), max(x - 1, 0) : min(x + 2, w)].reshape(-1, 3)
        out.append(patch[np.argmax(np.abs(patch - bg).max(axis=1))])
    return np.array(out, dtype=np.float64)


def test_strands_are_coloured_from_the_root_colour_to_the_tip_colour(ui, make_window):
    w = make_window(groom=samples.portrait(strands=30, vertices=20))
    w.scene.set_ramp("red-blue")  # red roots, blue tips (the frozen-hair paper's Fig. 1)
    image = ui.grab(w.viewport)
    g = w.scene.result
    roots = _strongest(image, w.viewport.project(g.roots))
    tips = _strongest(image, w.viewport.project(g.tips))
    root_c, tip_c = RAMPS["red-blue"][0] * 255.0, RAMPS["red-blue"][-1] * 255.0
    near_root = np.linalg.norm(roots - root_c, axis=1) < np.linalg.norm(roots - tip_c, axis=1)
    near_tip = np.linalg.norm(tips - tip_c, axis=1) < np.linalg.norm(tips - root_c, axis=1)
    assert near_root.mean() > 0.9 and near_tip.mean() > 0.9
    assert np.median(roots[:, 0] - roots[:, 2]) > 80  # red
    assert np.median(tips[:, 2] - tips[:, 0]) > 80  # blue


def test_left_drag_moves_tips_toward_the_cursor_and_keeps_roots(ui, make_window):
    w = make_window()
    v, scene = w.viewport, w.scene
    before = scene.result
    s = 5
    start = v.project(before.tips[s : s + 1])[0]
    end = start + np.array([90.0, -40.0])
    uploads = []
    renderer = v.renderer
    original = renderer.set_groom
    renderer.set_groom = lambda g: (uploads.append(g), original(g))
    ui.drag(v, start, end)
    ui.grab(v)
    assert uploads == []  # while editing only positions go to the GPU ...
    v.makeCurrent()
    on_gpu = np.frombuffer(renderer.position_buffer.read(), dtype=np.float32).reshape(-1, 3)
    v.doneCurrent()
    np.testing.assert_array_equal(on_gpu, scene.result.points)  # ... and they are the edited ones
    after = scene.result
    cursor = v.cursor_on_plane(QPointF(*end))
    np.testing.assert_array_equal(after.roots, before.roots)
    d0 = np.linalg.norm(before.tips[s] - cursor)
    d1 = np.linalg.norm(after.tips[s] - cursor)
    assert d1 < 0.8 * d0
    assert w.undo_stack.count() == 1  # one stroke, one undo step
    assert "ms" in w.frame_label.text() and "cursor" in w.cursor_label.text()


def test_undo_restores_exact_positions_and_redo_reapplies(ui, make_window):
    w = make_window()
    v, scene = w.viewport, w.scene
    ui.leave(v)
    before_points = scene.result.points.copy()
    before_image = ui.grab(v)
    start = v.project(scene.result.tips[100:101])[0]
    ui.drag(v, start, start + np.array([-80.0, -60.0]))
    after_points = scene.result.points.copy()
    assert not np.array_equal(after_points, before_points)
    ui.leave(v)
    after_image = ui.grab(v)
    assert not np.array_equal(after_image, before_image)

    w.undo_stack.undo()
    assert np.array_equal(scene.result.points, before_points)
    assert np.array_equal(ui.grab(v), before_image)  # the view shows it too
    w.undo_stack.redo()
    assert np.array_equal(scene.result.points, after_points)
    assert np.array_equal(ui.grab(v), after_image)


def test_navigation_orbit_pan_zoom_frame(ui, make_window):
    w = make_window(groom=samples.scalp(strands=200, vertices=10))
    v, cam = w.viewport, w.viewport.camera
    assert not cam.ortho
    points = w.scene.result.points.copy()
    yaw, distance = cam.yaw, cam.distance
    ui.drag(v, (200, 200), (260, 200), button=Qt.MouseButton.MiddleButton)
    assert cam.yaw != yaw
    target = cam.target.copy()
    ui.drag(
        v,
        (200, 200),
        (260, 230),
        button=Qt.MouseButton.MiddleButton,
        modifiers=Qt.KeyboardModifier.ShiftModifier,
    )
    assert not np.allclose(cam.target, target)
    yaw = cam.yaw
    ui.drag(v, (200, 200), (200, 260), modifiers=Qt.KeyboardModifier.AltModifier)
    assert cam.pitch != 0.15 or cam.yaw != yaw
    np.testing.assert_array_equal(w.scene.result.points, points)  # navigation never edits
    assert w.undo_stack.count() == 0
    _wheel(v, 120)
    assert cam.distance < distance
    radius = w.scene.radius
    _wheel(v, 120, Qt.KeyboardModifier.ControlModifier)
    assert w.scene.radius > radius and cam.distance < distance
    w.viewport.frame_all()
    assert np.allclose(cam.target, (np.add(*w.scene.result.bounds)) / 2)
    w.ortho_action.trigger()
    assert v.camera.ortho and w.ortho_action.isChecked()
    w.new_from_sample("portrait")  # planar: opens in 2-D; the toggle goes to 3-D whatever its mark
    assert v.camera.ortho
    w.ortho_action.trigger()
    assert not v.camera.ortho and not w.ortho_action.isChecked()
    mask = ui.hair_mask(ui.grab(v))
    assert mask.any()


def test_keys_resize_the_brush_and_frame_all(ui, make_window, qtbot):
    w = make_window()

    def active() -> bool:  # no window manager under Xvfb: ask for the focus directly, again
        if not w.isActiveWindow():  # while it has not come (a loaded host answers late)
            w.windowHandle().requestActivate()
        return w.isActiveWindow()

    qtbot.waitUntil(active, timeout=15_000)
    w.viewport.setFocus()
    r = w.scene.radius
    qtbot.keyClick(w.viewport, Qt.Key.Key_BracketRight)
    assert w.scene.radius == pytest.approx(r * 1.1)
    qtbot.keyClick(w.viewport, Qt.Key.Key_BracketLeft)
    qtbot.keyClick(w.viewport, Qt.Key.Key_BracketLeft)
    assert w.scene.radius == pytest.approx(r / 1.1)
    assert w.dock.radius.value() == pytest.approx(r / 1.1, rel=1e-3)
    w.viewport.camera.zoom(3)
    qtbot.keyClick(w.viewport, Qt.Key.Key_Period)  # frame all
    framed = w.viewport.camera.copy()
    w.viewport.frame_all()
    assert w.viewport.camera.state() == framed.state()


@pytest.mark.parametrize("mode", ["strand", "clump", "displacement"])
def test_colour_modes_change_the_picture(ui, make_window, mode):
    w = make_window(groom=samples.portrait(strands=60, vertices=12))
    ui.leave(w.viewport)
    base = ui.grab(w.viewport)
    w.scene.set_colour_mode(mode)
    if mode == "displacement":  # nothing has moved yet: all strands at the cold end of the heat ramp
        v = w.viewport
        start = v.project(w.scene.result.tips[10:11])[0]
        ui.drag(v, start, start + np.array([80.0, 0.0]))
        ui.leave(v)
    image = ui.grab(w.viewport)
    assert w.viewport.renderer.use_vertex_colors
    assert not np.array_equal(image, base)
    w.colour_actions["root-to-tip"].trigger()
    ui.grab(w.viewport)
    assert not w.viewport.renderer.use_vertex_colors


def _wheel(widget, delta: int, modifiers=Qt.KeyboardModifier.NoModifier) -> None:
    pos = QPointF(100, 100)
    event = QWheelEvent(pos, widget.mapToGlobal(pos), QPoint(0, 0), QPoint(0, delta), Qt.MouseButton.NoButton,
                        modifiers, Qt.ScrollPhase.NoScrollPhase, False)  # fmt: skip
    QApplication.sendEvent(widget, event)


def _ring_radius(image: np.ndarray, centre: np.ndarray) -> float:
    """Median distance from ``centre`` of the brush ring's orange pixels."""
    r, g, b = (image[..., i].astype(int) for i in range(3))
    ys, xs = np.nonzero((r > 200) & (g > 90) & (g < 180) & (b < 80))
    assert xs.size > 20, "no brush circle on screen"
    return float(np.median(np.hypot(xs + 0.5 - centre[0], ys + 0.5 - centre[1])))


def test_brush_circle_follows_the_cursor_with_the_radius(ui, make_window):
    w = make_window(groom=samples.portrait(strands=10, vertices=6))
    v = w.viewport
    w.scene.set_radius(0.5)
    centre = np.array([v.width() / 2.0, v.height() / 2.0])
    ui.send_mouse(v, "move", centre)
    expected = 0.5 * v.camera.pixels_per_unit_at(w.scene.centre, v.height())
    assert _ring_radius(ui.grab(v), centre) == pytest.approx(expected, abs=2.0)
    _wheel(v, 240, Qt.KeyboardModifier.ControlModifier)  # two notches bigger
    assert _ring_radius(ui.grab(v), centre) == pytest.approx(expected * 1.1**2, abs=2.0)
    ui.leave(v)
    r, g, b = (ui.grab(v)[..., i].astype(int) for i in range(3))
    assert not np.any((r > 200) & (g > 90) & (g < 180) & (b < 80))
