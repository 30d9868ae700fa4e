"""The brushes through the studio's drag path: each does what it says, symmetry mirrors, front
faces only leaves the back alone, the mask locks, every stroke is one undo step, the falloff
editor's curve reaches the samples, and an exported stroke log replays in the CLI to the bytes."""

from __future__ import annotations

import numpy as np
import pytest
from PySide6.QtCore import QPointF, Qt

from hairtool import samples
from hairtool.frozen.brushes import BrushSample, falloff_lut, root_normals
from hairtool.groom import Groom

pytestmark = pytest.mark.gui

CTRL = Qt.KeyboardModifier.ControlModifier


def plain(make_window, groom=None, **params):
    """A window on a small 3-D scalp with no noise and no clumps (unless ``params`` say)."""
    w = make_window(groom=groom if groom is not None else samples.scalp(strands=200, vertices=12))
    w.scene.set_params(w.scene.params.replace(**({"freeze": False, "clump": False} | params)))
    w.undo_stack.clear()  # (the window as opened on these parameters: only the strokes are steps)
    return w


def facing(w) -> np.ndarray:
    """``(S,)`` n · forward of each root normal: < 0 faces the camera."""
    return root_normals(w.scene.rest) @ w.viewport.camera.forward()


def front_strand(w) -> int:
    return int(np.argmin(facing(w)))


def click(ui, v, pos, modifiers=None) -> None:
    ui.send_mouse(v, "press", pos, Qt.MouseButton.LeftButton, Qt.MouseButton.LeftButton, modifiers)
    ui.send_mouse(v, "release", pos, Qt.MouseButton.LeftButton, None, modifiers)


def curvature(g: Groom) -> np.ndarray:
    """``(S,)`` summed second differences along each strand."""
    p = g.points.astype(np.float64).reshape(g.strand_count, -1, 3)
    return np.linalg.norm(p[:, :-2] - 2.0 * p[:, 1:-1] + p[:, 2:], axis=2).sum(axis=1)


def test_comb_moves_tips_along_the_drag_and_keeps_lengths(ui, make_window):
    w = plain(make_window)
    s, v = w.scene, w.viewport
    s.set_brush("comb")
    s.set_intensity(1.0)
    before = s.result
    start = v.project(before.tips[front_strand(w)])[0]
    end = start + np.array([90.0, 0.0])
    ui.drag(v, start, end, steps=9)
    after = s.result
    drag = v.cursor_on_plane(QPointF(*end)) - v.cursor_on_plane(QPointF(*start))
    moved = (after.tips - before.tips).astype(np.float64)
    touched = np.linalg.norm(moved, axis=1) > 1e-4
    assert touched.sum() >= 3
    along = moved[touched] @ (drag / np.linalg.norm(drag))
    assert np.all(along > 0) and along.sum() > 0.8 * np.linalg.norm(moved[touched], axis=1).sum()
    np.testing.assert_allclose(after.strand_lengths, before.strand_lengths, atol=1e-4)
    np.testing.assert_array_equal(after.roots, before.roots)
    assert w.undo_stack.count() == 1 and w.undo_stack.undoText() == "Comb stroke"
    assert all(isinstance(x, BrushSample) and x.brush == "comb" for x in s.pipeline.strokes)
    assert len(s.pipeline.strokes) == 9  # the press has no direction yet: one sample per move


def test_smooth_takes_out_curvature_and_keeps_roots(ui, make_window):
    w = plain(make_window)
    s, v = w.scene, w.viewport
    s.set_brush("smooth")
    s.set_intensity(1.0)
    s.set_radius(1.5)
    before = s.result
    g = before.points.reshape(before.strand_count, -1, 3)
    centre = v.project(g[front_strand(w), 6])[0]
    ui.drag(v, centre, centre + np.array([6.0, 0.0]), steps=12)
    after = s.result
    touched = np.any(after.points != before.points, axis=1).reshape(before.strand_count, -1).any(axis=1)
    assert touched.sum() >= 3
    assert np.all(curvature(after)[touched] < curvature(before)[touched])
    np.testing.assert_array_equal(after.roots, before.roots)
    np.testing.assert_allclose(after.strand_lengths, before.strand_lengths, rtol=1e-4)


def test_length_grows_and_ctrl_shrinks_by_the_stated_fraction(ui, make_window):
    w = plain(make_window)
    s, v = w.scene, w.viewport
    s.set_brush("length")
    s.set_intensity(0.2)
    s.set_falloff("constant")  # every strand the brush reaches: the whole fraction
    before = s.result
    lo, hi = before.bounds
    s.set_radius(0.25 * float(np.max(hi - lo)))  # wide enough to reach the grown tips again
    pos = v.project(before.tips[front_strand(w)])[0]
    click(ui, v, pos)  # one sample: the press
    grown = s.result.strand_lengths / before.strand_lengths
    hit = grown > 1.0 + 1e-6
    assert hit.sum() >= 2
    np.testing.assert_allclose(grown[hit], 1.2, rtol=1e-5)
    np.testing.assert_allclose(grown[~hit], 1.0, rtol=1e-6)
    mid = s.result
    click(ui, v, pos, CTRL)  # Ctrl: shrink by the same fraction
    shrunk = s.result.strand_lengths / mid.strand_lengths
    cut = shrunk < 1.0 - 1e-6
    assert cut.sum() >= 2 and np.all(hit[cut])
    np.testing.assert_allclose(shrunk[cut], 0.8, rtol=1e-5)
    np.testing.assert_allclose(shrunk[~cut], 1.0, rtol=1e-6)
    s.set_subtract("length", True)  # the Direction control: shrink without Ctrl
    assert w.dock.sign.currentText() == "Shrink"
    assert w.undo_stack.count() == 2


def test_puff_lifts_tips_away_from_the_scalp(ui, make_window):
    w = plain(make_window)
    s, v = w.scene, w.viewport
    s.set_brush("puff")
    s.set_intensity(0.5)
    s.set_radius(1.5)
    before = s.result
    centre = s.pipeline.scalp_centre
    pos = v.project(before.roots[front_strand(w)])[0]
    click(ui, v, pos)
    after = s.result
    lifted = np.linalg.norm(after.tips - centre, axis=1) - np.linalg.norm(before.tips - centre, axis=1)
    moved = np.any(after.points != before.points, axis=1).reshape(before.strand_count, -1).any(axis=1)
    assert moved.sum() >= 3
    assert np.all(lifted[moved] > 0)
    np.testing.assert_array_equal(after.roots, before.roots)
    np.testing.assert_allclose(after.strand_lengths, before.strand_lengths, rtol=1e-4)


def test_masked_strands_stay_bit_identical_under_a_comb_and_show_it(ui, make_window):
    from app.ui.colouring import vertex_colors

    w = plain(make_window)
    s, v = w.scene, w.viewport
    s.set_brush("mask")
    s.set_falloff("constant")
    colours_before = vertex_colors(s)
    pos = v.project(s.result.tips[front_strand(w)])[0]
    click(ui, v, pos)
    locked = s.locked.copy()
    assert 2 <= locked.sum() < s.result.strand_count
    np.testing.assert_array_equal(locked, s.pipeline.locked)
    top = s.result.topology
    masked_v = np.repeat(locked, top.counts)
    colours = vertex_colors(s)
    assert colours is not None and np.all(np.abs(colours[masked_v] - _ramp(s)[masked_v]).max(axis=1) > 0.05)
    if colours_before is not None:
        np.testing.assert_array_equal(colours[~masked_v], colours_before[~masked_v])
    before = s.result
    s.set_brush("comb")
    s.set_intensity(1.0)
    s.set_radius(3.0)
    s.set_front_only(False)
    ui.drag(v, pos, pos + np.array([80.0, 30.0]))
    after = s.result.points.reshape(before.strand_count, -1, 3)
    old = before.points.reshape(before.strand_count, -1, 3)
    np.testing.assert_array_equal(after[locked], old[locked])
    assert np.any(after[~locked] != old[~locked])
    s.set_brush("mask")  # Ctrl erases: the mask goes, and with it the colour
    click(ui, v, pos, CTRL)
    assert not s.locked.any()
    assert w.undo_stack.count() == 3


def _ramp(scene):
    from app.render.ramps import ramp_texture, sample_linear
    from app.render.strands import RAMP_TEXELS

    return sample_linear(ramp_texture(scene.ramp, RAMP_TEXELS), scene.drawn_topology.vertex_param)


def test_clump_brush_paints_each_strands_clump_strength(ui, make_window):
    from app.ui.colouring import CLUMP_RGB, CLUMP_TINT, vertex_colors
    from app.ui.window import CLUMP_FULL
    w = plain(make_window, clump=True)
    s, v = w.scene, w.viewport
    s.set_brush("clump")
    s.set_falloff("constant")
    s.set_intensity(1.0)
    before = s.result
    pos = v.project(before.tips[front_strand(w)])[0]
    assert w.dock.sign.currentText() == "Erase"  # a new groom clumps fully: the brush starts erasing
    s.set_subtract("clump", False)
    assert w.dock.sign.currentText() == "Paint"
    click(ui, v, pos)  # paint where every strand clumps fully already: nothing to do, and it says so
    assert w.statusBar().currentMessage() == CLUMP_FULL
    colours_before = vertex_colors(s)
    click(ui, v, pos, CTRL)  # erase: those strands no longer clump
    strength = s.pipeline.clump_strength
    off = strength < 1.0
    assert off.sum() >= 2 and np.all(strength[off] == 0.0)
    off_v = np.repeat(off, s.result.topology.counts)  # drawn in the clump brush's own colour
    colours = vertex_colors(s)
    loose = (1 - CLUMP_TINT) * _ramp(s)[off_v] + CLUMP_TINT * CLUMP_RGB
    np.testing.assert_allclose(colours[off_v], loose, atol=1e-5)
    if colours_before is not None:
        np.testing.assert_array_equal(colours[~off_v], colours_before[~off_v])
    assert not np.array_equal(s.result.points, before.points)
    s.set_subtract("clump", False)
    click(ui, v, pos)  # paint back: full clumping, the first result again
    assert np.all(s.pipeline.clump_strength == 1.0)
    np.testing.assert_array_equal(s.result.points, before.points)
    assert vertex_colors(s) is colours_before or np.array_equal(vertex_colors(s), colours_before)
    w.undo_stack.undo()
    np.testing.assert_array_equal(s.pipeline.clump_strength, strength)
    assert w.undo_stack.count() == 3


def mirrored_scalp() -> tuple[Groom, np.ndarray]:
    """Strands on x > 0 and their mirror images across x = 0: ``(groom, partner of each strand)``."""
    g = samples.scalp(strands=160, vertices=12)
    p = g.points.reshape(g.strand_count, -1, 3)
    right = p[p[:, 0, 0] > 0.15]
    left = right * np.array([-1.0, 1.0, 1.0], np.float32)
    n = len(right)
    pts = np.concatenate([right, left]).astype(np.float32)
    groom = Groom(pts.reshape(-1, 3), np.full(2 * n, p.shape[1]))
    partner = np.concatenate([np.arange(n, 2 * n), np.arange(n)])
    return groom, partner


def test_x_symmetry_mirrors_the_stroke(ui, make_window):
    groom, partner = mirrored_scalp()
    w = plain(make_window, groom=groom)
    s, v = w.scene, w.viewport
    s.set_mirror_x(0.0)
    w.symmetry_action.trigger()  # Shift+X
    assert s.tool.symmetry and w.dock.symmetry.isChecked()
    s.set_brush("comb")
    s.set_intensity(1.0)
    s.set_front_only(False)  # this camera is not symmetric; the mirrored sample's view is
    before = s.result
    right = np.flatnonzero(before.roots[:, 0] > 0)
    tip = right[np.argmin(facing(w)[right])]
    start = v.project(before.tips[tip])[0]
    ui.drag(v, start, start + np.array([40.0, 50.0]))
    after = s.result.points.reshape(groom.strand_count, -1, 3).astype(np.float64)
    old = before.points.reshape(groom.strand_count, -1, 3)
    moved = np.any(after != old, axis=(1, 2))
    assert moved[right].sum() >= 2
    np.testing.assert_array_equal(moved, moved[partner])
    np.testing.assert_allclose(after[partner] * np.array([-1.0, 1.0, 1.0]), after, atol=1e-5)
    assert len(s.pipeline.strokes) % 2 == 0  # each move's mirror right after it


def test_front_faces_only_leaves_the_back_of_the_head_alone(ui, make_window):
    w = plain(make_window)
    s, v = w.scene, w.viewport
    assert s.tool.front_only and w.dock.front_only.isChecked()  # on by default
    s.set_brush("comb")
    s.set_intensity(1.0)
    s.set_radius(10.0)  # the whole groom inside the brush
    before = s.result
    back = facing(w) > 0.35  # clearly turned away from the camera (every ray of the view)
    assert back.sum() >= 10
    start = np.array([v.width() / 2, v.height() / 2])
    ui.drag(v, start, start + np.array([60.0, 0.0]))
    shape = (before.strand_count, -1, 3)
    after, old = s.result.points.reshape(shape), before.points.reshape(shape)
    np.testing.assert_array_equal(after[back], old[back])
    assert np.any(after[~back] != old[~back])
    assert all(x.view is not None for x in s.pipeline.strokes)
    w.undo_stack.undo()
    w.front_only_action.trigger()  # off: the back moves too
    assert not s.tool.front_only
    ui.drag(v, start, start + np.array([60.0, 0.0]))
    assert np.any(s.result.points.reshape(shape)[back] != old[back])


def test_undo_restores_the_bytes_of_each_stroke(ui, make_window):
    w = make_window(groom=samples.scalp(strands=200, vertices=12))  # noise and clumps on
    s, v = w.scene, w.viewport
    states = [s.result.points.copy()]
    pos = v.project(s.result.tips[front_strand(w)])[0]
    strokes = (("comb", (60.0, 0.0)), ("smooth", (5.0, 5.0)), ("puff", (0.0, 0.0)), ("mask", (1.0, 0.0)))
    for brush, delta in strokes:
        w.brush_actions[brush].trigger()
        ui.drag(v, pos, pos + np.array(delta), steps=4)
        states.append(s.result.points.copy())
    assert w.undo_stack.count() == 4
    for i in range(4, 0, -1):
        w.undo_stack.undo()
        np.testing.assert_array_equal(s.result.points, states[i - 1])
    for i in range(1, 5):
        w.undo_stack.redo()
        np.testing.assert_array_equal(s.result.points, states[i])


def test_exported_strokes_replay_in_the_cli_to_the_studios_bytes(ui, make_window, tmp_path):
    from hairtool import io
    from hairtool.cli import main

    rest = samples.scalp(strands=200, vertices=12)
    w = make_window(groom=rest)  # the studio's own parameters: noise, clumps, lengths kept
    s, v = w.scene, w.viewport
    s.set_symmetry(True)
    s.set_falloff([[0.0, 1.0], [0.4, 0.9], [1.0, 0.0]])
    pos = v.project(s.result.tips[front_strand(w)])[0]
    for brush in ("comb", "length", "smooth", "puff", "mask", "clump", "comb", "align"):
        w.brush_actions[brush].trigger()
        ui.drag(v, pos, pos + np.array([40.0, 25.0]), steps=4, modifiers=CTRL if brush == "clump" else None)
        pos = pos + np.array([-30.0, 10.0])
    assert w.stroke_files.export(tmp_path / "strokes.json")
    io.write(tmp_path / "rest.npz", rest)
    args = ["freeze", str(tmp_path / "rest.npz"), str(tmp_path / "out.npz"), "--keep-lengths"]
    assert main([*args, "--strokes", str(tmp_path / "strokes.json")]) == 0
    np.testing.assert_array_equal(io.read_groom(tmp_path / "out.npz").points, s.result.points)
    # ... and Import / Replay Strokes on the rest groom gives them again, as one undo step
    w.set_groom(rest)
    assert w.stroke_files.replay(tmp_path / "strokes.json")
    np.testing.assert_array_equal(w.scene.result.points, s.result.points)
    assert w.undo_stack.count() == 1
    w.undo_stack.undo()
    assert not w.scene.pipeline.strokes


def test_a_bad_stroke_log_is_refused_with_its_name(make_window, tmp_path):
    w = make_window(groom=samples.scalp(strands=50, vertices=8))
    bad = tmp_path / "bad.json"
    bad.write_text('[{"brush": "comb", "samples": [{"cursor": [0, 0], "radius": 1, "strength": 1}]}]')
    before = w.scene.result.points.copy()
    assert not w.stroke_files.replay(bad)
    assert w.errors and "bad.json" in w.errors[-1][1]
    np.testing.assert_array_equal(w.scene.result.points, before)
    assert w.undo_stack.count() == 0


def test_the_falloff_editors_curve_reaches_the_samples(ui, qtbot, make_window):
    w = plain(make_window)
    s, v, dock = w.scene, w.viewport, w.dock
    w.brush_actions["comb"].trigger()
    assert dock.curve.isEnabled() and dock.falloff.currentData() == "smooth"
    editor = dock.curve
    dock.widget().ensureWidgetVisible(editor)
    mid = editor.point_pos(2)  # a preset's middle point: dragging it makes the curve the artist's
    target = mid + QPointF(0.0, 20.0)
    qtbot.mousePress(editor, Qt.MouseButton.LeftButton, pos=mid.toPoint())
    qtbot.mouseMove(editor, target.toPoint())
    qtbot.mouseRelease(editor, Qt.MouseButton.LeftButton, pos=target.toPoint())
    curve = s.tool.falloff
    assert not isinstance(curve, str) and len(curve) == 5 and dock.falloff.currentData() is None
    assert curve[2][1] < falloff_lut("smooth")[128] - 0.05  # dragged down
    qtbot.mouseDClick(editor, Qt.MouseButton.LeftButton, pos=(editor.point_pos(0) + QPointF(15, 0)).toPoint())
    assert len(s.tool.falloff) == 6  # double-click adds a point
    qtbot.mouseClick(editor, Qt.MouseButton.RightButton, pos=editor.point_pos(1).toPoint())
    assert len(s.tool.falloff) == 5  # right-click removes it
    qtbot.mouseClick(editor, Qt.MouseButton.RightButton, pos=editor.point_pos(0).toPoint())
    assert len(s.tool.falloff) == 5  # the end points stay
    pos = v.project(s.result.tips[front_strand(w)])[0]
    ui.drag(v, pos, pos + np.array([30.0, 0.0]), steps=2)
    expected = tuple(falloff_lut(s.tool.falloff).tolist())
    assert s.pipeline.strokes and all(x.lut == expected for x in s.pipeline.strokes)
    dock.falloff.setCurrentIndex(dock.falloff.findData("linear"))
    assert s.tool.falloff == "linear"


def test_a_mask_stroke_that_touches_no_strand_says_so(ui, make_window):
    from app.ui.window import MISSED_STRANDS

    w = plain(make_window)
    s, v = w.scene, w.viewport
    s.set_brush("mask")
    s.set_radius(0.05)
    ui.drag(v, (5.0, 5.0), (25.0, 5.0))
    assert w.statusBar().currentMessage() == MISSED_STRANDS
    w.statusBar().clearMessage()
    pos = v.project(s.result.tips[front_strand(w)])[0]
    ui.drag(v, pos, pos + np.array([2.0, 0.0]))
    assert s.locked.any() and w.statusBar().currentMessage() != MISSED_STRANDS
    ui.drag(v, pos, pos + np.array([2.0, 0.0]))  # the same strands again: nothing changes, but touched
    assert w.statusBar().currentMessage() != MISSED_STRANDS


def test_each_brush_remembers_its_size_and_strength_and_keys_pick_brushes(make_window):
    w = plain(make_window)
    s = w.scene
    s.set_brush("comb")
    s.set_radius(0.3)
    s.set_intensity(0.9)
    s.set_brush("smooth")
    s.set_radius(0.7)
    assert w.dock.radius.value() == pytest.approx(0.7)
    s.set_brush("comb")
    assert (s.radius, s.intensity) == (pytest.approx(0.3), pytest.approx(0.9))
    assert w.dock.brush.currentData() == "comb" and w.brush_actions["comb"].isChecked()
    for key, brush in (("S", "smooth"), ("M", "mask"), ("W", "select"), ("Shift+C", "align")):
        action = w.brush_actions[brush]
        assert action.shortcut().toString() == key  # (Xvfb without a window manager activates no window)
        action.trigger()
        assert s.brush == brush and w.dock.brush.currentData() == brush
    assert not w.dock.curve.isEnabled()  # align weighs by the paper's rule, not the curve
    assert w.dock.mode.isVisibleTo(w.dock) and w.dock.intensity.isVisibleTo(w.dock)
    s.set_brush("mask")
    assert not w.dock.mode.isVisibleTo(w.dock) and not w.dock.intensity.isVisibleTo(w.dock)
    w.dock.brush.setCurrentIndex(w.dock.brush.findData("length"))
    assert s.brush == "length" and w.dock.sign.currentText() == "Grow"


def test_a_project_keeps_the_brush_settings_and_the_mask(ui, make_window, tmp_path):
    w = plain(make_window)
    s, v = w.scene, w.viewport
    s.set_brush("comb")
    s.set_radius(0.4)
    s.set_brush("mask")
    s.set_falloff([[0.0, 1.0], [0.5, 0.25], [1.0, 0.0]])
    s.set_symmetry(True)
    s.set_mirror_x(0.125)
    s.set_front_only(False)
    s.set_subtract("length", True)
    pos = v.project(s.result.tips[front_strand(w)])[0]
    click(ui, v, pos)
    locked = s.locked.copy()
    assert locked.any()
    assert w.project.save_to(tmp_path / "brushes.hairproj")
    w2 = make_window()
    assert w2.project.open_project(w.project.path)
    t = w2.scene.tool
    assert (t.brush, t.symmetry, t.mirror_x, t.front_only) == ("mask", True, 0.125, False)
    assert t.falloff == ((0.0, 1.0), (0.5, 0.25), (1.0, 0.0)) and t.subtract["length"]
    assert t.radius["comb"] == pytest.approx(0.4)
    np.testing.assert_array_equal(w2.scene.locked, locked)
    assert w2.dock.mirror_x.value() == pytest.approx(0.125) and not w2.errors


def test_the_brush_controls_fit_a_laptop_screen(make_window):
    from PySide6.QtWidgets import QApplication, QScrollArea

    w = make_window(size=(1366, 768 - 32))
    QApplication.processEvents()
    assert w.minimumSizeHint().height() <= 768 - 32
    bar = w.brush_bar
    assert bar.isVisible() and bar.geometry().right() <= w.width()
    for name, action in w.brush_actions.items():
        button = bar.widgetForAction(action)
        assert button is not None and button.isVisible(), name  # not folded into the overflow menu
        assert bar.geometry().contains(button.geometry().translated(bar.pos())), name
    w.dock.raise_()
    QApplication.processEvents()
    for control in (w.dock.brush, w.dock.curve, w.dock.falloff, w.dock.mirror_x, w.dock.front_only):
        area = control.parentWidget()
        while not isinstance(area, QScrollArea):
            area = area.parentWidget()
        area.ensureWidgetVisible(control)
        QApplication.processEvents()
        assert not control.visibleRegion().isEmpty(), control


def test_the_symmetry_plane_is_drawn_where_the_artist_puts_it(ui, make_window):
    w = make_window(groom=samples.scalp(strands=60, vertices=8))
    v, s = w.viewport, w.scene

    def violet(image):
        im = image.astype(int)
        return (im[..., 0] > 150) & (im[..., 2] > 190) & (im[..., 1] < 150)

    ui.leave(v)
    assert violet(ui.grab(v)).sum() == 0
    s.set_symmetry(True)
    s.set_mirror_x(0.0)
    image = ui.grab(v)
    assert violet(image).sum() > 100
    px = v.mirror_outline(v.width(), v.height())
    s.set_mirror_x(1.5)  # moved: the outline follows
    moved = v.mirror_outline(v.width(), v.height())
    assert np.all(moved[:, 0] > px[:, 0])
    assert w.dock.mirror_x.value() == pytest.approx(1.5)
    w.dock.mirror_centre.click()
    assert s.tool.mirror_x is None
    assert w.dock.mirror_x.value() == pytest.approx(s.pipeline.scalp_centre[0], abs=1e-4)


def test_with_render_hair_brushes_act_on_the_guides_and_masked_guides_children_show_it(ui, make_window):
    from app.ui.colouring import MASK_KEEP, MASK_RGB, vertex_colors
    from hairtool.guides.binding import bind_roots

    w = plain(make_window, groom=samples.scalp(strands=60, vertices=12, seed=4))
    s, v = w.scene, w.viewport
    s.set_binding(bind_roots(s.rest, count=600, seed=2))
    s.set_colour_mode("hair")
    s.set_brush("mask")
    s.set_falloff("constant")
    pos = v.project(s.result.tips[front_strand(w)])[0]
    click(ui, v, pos)
    locked = s.locked
    assert locked.any() and not locked.all()
    colours = vertex_colors(s)
    s.locked = np.zeros_like(locked)  # the same picture without the mask
    plain_colours = vertex_colors(s)
    s.locked = locked
    top, b = s.drawn_topology, s.drawn_binding()
    child_masked = np.repeat(locked[b.guide_ids[:, 0]], b.counts)
    n = len(child_masked)
    masked = np.concatenate([child_masked, np.repeat(locked, s.result.topology.counts)])
    assert child_masked.any() and not child_masked.all()
    dimmed = MASK_KEEP * plain_colours[masked] + (1 - MASK_KEEP) * MASK_RGB
    np.testing.assert_allclose(colours[masked], dimmed)
    np.testing.assert_array_equal(colours[~masked], plain_colours[~masked])
    assert top.vertex_count == n + s.result.vertex_count
    before = s.result
    w.brush_actions["comb"].trigger()
    s.set_radius(5.0)
    s.set_front_only(False)
    ui.drag(v, pos, pos + np.array([50.0, 0.0]))
    shape = (before.strand_count, -1, 3)
    after, old = s.result.points.reshape(shape), before.points.reshape(shape)
    np.testing.assert_array_equal(after[locked], old[locked])
    np.testing.assert_array_equal(s.drawn_points[:n], s.render_hair().points)


def test_one_move_gives_its_sample_and_the_mirrored_one_for_every_brush():
    from app.ui.brush_tool import SIGNED, BrushTool, brushes
    from hairtool.frozen.brushes import BRUSHES
    from hairtool.frozen.pipeline import AlignSample

    assert sorted(brushes()) == sorted(BRUSHES)  # the toolbar lists the engine's brushes
    tool = BrushTool(symmetry=True)
    tool.reset_radius(0.5)
    for name in brushes():
        tool.set_brush(name)
        first, second = tool.samples((1.0, 2.0, 3.0), (0.1, 0.0, 0.0), (0.0, 0.0, -1.0), 0.25, invert=True)
        assert second.cursor == (-0.5, 2.0, 3.0) and first.view == (0.0, 0.0, -1.0)
        assert second.view == (-0.0, 0.0, -1.0) and first.radius == second.radius == 0.5
        if isinstance(first, AlignSample):
            assert first.intensity == 0.8 and first.mode == "paper"
        else:
            assert first.brush == name and second.direction == (-0.1, 0.0, 0.0)
            # Ctrl inverts the signed ones (from the direction each starts in: clump erases)
            sign = (1.0 if tool.subtract[name] else -1.0) if name in SIGNED else 1.0
            assert first.strength == sign * tool.strength[name]
    tool.set_brush("comb")
    assert tool.samples((0, 0, 0), (0, 0, 0), None, 0.0) == []  # a comb standing still does nothing
    tool.front_only = False
    assert tool.samples((0, 0, 0), (1, 0, 0), (0, 0, 1), 0.0)[0].view is None
