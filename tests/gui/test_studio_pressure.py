"""A pen's pressure and on-canvas sizing: tablet events (a stylus's) scale the brush size and
strength where the brush's pressure toggles say, the pressure reaches the stroke log and the CLI
replays it to the studio's bytes; F / Shift+F size the brush and its strength with the mouse,
a click or Enter keeps the value, Esc or a right click gives the old one back."""

from __future__ import annotations

import json

import numpy as np
import pytest
from PySide6.QtCore import QEvent, QPointF, Qt
from PySide6.QtGui import QInputDevice, QPointingDevice, QTabletEvent
from PySide6.QtWidgets import QApplication

from hairtool import samples
from hairtool.frozen.brushes import BrushSample

pytestmark = pytest.mark.gui

LEFT = Qt.MouseButton.LeftButton
NONE = Qt.MouseButton.NoButton
_PEN: list[QPointingDevice] = []


def pen() -> QPointingDevice:
    """A stylus (made once: Qt keeps input devices for the application's life)."""
    if not _PEN:
        caps = QInputDevice.Capability.Position | QInputDevice.Capability.Pressure
        _PEN.append(QPointingDevice(
            "test pen", 4711, QInputDevice.DeviceType.Stylus, QPointingDevice.PointerType.Pen, caps, 1, 2
        ))  # fmt: skip
    return _PEN[0]


def send_tablet(widget, kind: str, pos, pressure: float, buttons=LEFT) -> QTabletEvent:
    t = QEvent.Type
    types = {"press": t.TabletPress, "move": t.TabletMove, "release": t.TabletRelease}
    local = QPointF(float(pos[0]), float(pos[1]))
    button = LEFT if kind in ("press", "release") else NONE
    event = QTabletEvent(
        types[kind], pen(), local, widget.mapToGlobal(local), pressure, 0.0, 0.0, 0.0, 0.0, 0.0,
        Qt.KeyboardModifier.NoModifier, button, NONE if kind == "release" else buttons,
    )  # fmt: skip
    QApplication.sendEvent(widget, event)
    return event


def pen_drag(widget, start, end, pressures) -> None:
    """A pen pressed at ``start`` with ``pressures[0]``, moved to ``end`` with the others, lifted."""
    send_tablet(widget, "press", start, pressures[0])
    moves = pressures[1:]
    for f, p in zip(np.linspace(0.0, 1.0, len(moves) + 1)[1:], moves, strict=True):
        send_tablet(widget, "move", (1.0 - f) * np.asarray(start, float) + f * np.asarray(end, float), p)
    send_tablet(widget, "release", end, 0.0)


def plain(make_window):
    w = make_window(groom=samples.scalp(strands=200, vertices=12))
    w.scene.set_params(w.scene.params.replace(freeze=False, clump=False))
    w.undo_stack.clear()  # (the window as opened on these parameters: only the strokes are steps)
    return w


def tip_on_screen(w) -> np.ndarray:
    s = w.scene
    facing = s.pipeline.strand_normals @ w.viewport.camera.forward()
    return w.viewport.project(s.result.tips[int(np.argmin(facing))])[0]


def test_a_pens_pressure_scales_radius_and_strength_where_the_toggles_say(ui, make_window):
    w = plain(make_window)
    s, v = w.scene, w.viewport
    w.brush_actions["comb"].trigger()
    s.set_intensity(0.8)
    base_r = s.radius
    w.dock.pressure_radius.setChecked(True)  # the dock's Pen toggles, for this brush
    assert s.tool.pressure_radius["comb"] and s.tool.pressure_strength["comb"]  # (strength: on by default)
    assert not s.tool.pressure_radius["smooth"]  # each brush its own
    pos = tip_on_screen(w)
    event = send_tablet(v, "press", pos, 0.5)
    assert event.isAccepted()  # (so Qt sends no mouse event after it)
    pressures = (0.5, 0.25, 1.0)
    for k, p in enumerate(pressures):
        send_tablet(v, "move", pos + np.array([10.0 * (k + 1), 0.0]), p)
        ui.send_mouse(v, "move", pos + np.array([10.0 * k + 5.0, 0.0]), None, LEFT)  # (X11's copy: dropped)
    send_tablet(v, "release", pos + np.array([30.0, 0.0]), 0.0)
    log = s.pipeline.strokes
    assert [x.pressure for x in log] == list(pressures)  # (the press has no direction: no sample)
    assert [x.radius for x in log] == [base_r * p for p in pressures]
    assert [x.strength for x in log] == [0.8 * p for p in pressures]
    assert w.undo_stack.count() == 1 and w.undo_stack.undoText() == "Comb stroke"
    # both toggles off: the pen's pressure is logged, the brush is the dock's
    w.dock.pressure_radius.setChecked(False)
    w.dock.pressure_strength.setChecked(False)
    pen_drag(v, pos, pos + np.array([30.0, 10.0]), (0.3, 0.3, 0.3))
    assert [(x.radius, x.strength, x.pressure) for x in s.pipeline.strokes[3:]] == [(base_r, 0.8, 0.3)] * 2
    # the mouse presses fully
    w.dock.pressure_strength.setChecked(True)
    ui.drag(v, pos, pos + np.array([20.0, 0.0]), steps=2)
    assert [(x.strength, x.pressure) for x in s.pipeline.strokes[5:]] == [(0.8, 1.0)] * 2


def test_a_pen_never_scales_a_strength_that_is_only_a_direction(make_window):
    """The mask's strength says paint or erase: a light touch must not erase."""
    w = plain(make_window)
    s, v = w.scene, w.viewport
    w.brush_actions["mask"].trigger()
    assert not w.dock.pressure_strength.isVisibleTo(w.dock)
    pen_drag(v, tip_on_screen(w), tip_on_screen(w) + np.array([20.0, 0.0]), (0.0, 0.1, 0.05))
    assert all(isinstance(x, BrushSample) and x.strength == 1.0 for x in s.pipeline.strokes)
    assert s.locked.any()


def test_a_pen_stroke_replays_in_the_cli_to_the_studios_bytes(make_window, tmp_path):
    from hairtool import io
    from hairtool.cli import main

    rest = samples.scalp(strands=200, vertices=12)
    w = make_window(groom=rest)  # the studio's own parameters: noise, clumps, lengths kept
    s, v = w.scene, w.viewport
    s.set_symmetry(True)
    pos = tip_on_screen(w)
    for brush in ("comb", "length", "align"):
        w.brush_actions[brush].trigger()
        w.dock.pressure_radius.setChecked(True)
        pen_drag(v, pos, pos + np.array([40.0, 20.0]), (0.9, 0.35, 0.6, 0.15))
        pos = pos + np.array([-25.0, 10.0])
    assert {x.pressure for x in s.pipeline.strokes} == {0.9, 0.35, 0.6, 0.15}
    assert w.stroke_files.export(tmp_path / "strokes.json")
    logged = json.loads((tmp_path / "strokes.json").read_text())
    assert [x["pressure"] for x in logged[0]["samples"][:4]] == [0.35, 0.35, 0.6, 0.6]  # (mirrors after)
    io.write(tmp_path / "rest.npz", rest)
    args = ["freeze", str(tmp_path / "rest.npz"), str(tmp_path / "out.npz"), "--keep-lengths"]
    assert main([*args, "--strokes", str(tmp_path / "strokes.json")]) == 0
    np.testing.assert_array_equal(io.read_groom(tmp_path / "out.npz").points, s.result.points)


def action_named(w, text: str):
    return next(a for a in w.findChildren(type(w.brush_actions["comb"])) if a.text() == text)


def record_calls(obj, name: str) -> list:
    """Every call of ``obj.name`` from now on, as (args, kwargs); the method still runs."""
    calls, method = [], getattr(obj, name)

    def spy(*args, **kwargs):
        calls.append((args, kwargs))
        return method(*args, **kwargs)

    setattr(obj, name, spy)
    return calls


def hover(ui, v, pos) -> None:
    ui.send_mouse(v, "move", pos)


def test_f_sizes_the_brush_on_the_canvas_click_keeps_esc_cancels(ui, make_window):
    w = plain(make_window)
    s, v = w.scene, w.viewport
    r0 = s.radius
    at = np.array([450.0, 300.0])
    hover(ui, v, at)
    action = action_named(w, "Si&ze on canvas")
    assert [k.toString() for k in action.shortcuts()] == ["F"]
    action.trigger()
    assert v.sizing.active and s.radius == r0  # the circle starts at the brush's size
    assert "Brush size" in w.statusBar().currentMessage()
    ppu = v.camera.pixels_per_unit_at(s.centre, v.height())
    centre = np.array([v.sizing.centre.x(), v.sizing.centre.y()])
    np.testing.assert_allclose(np.linalg.norm(at - centre), r0 * ppu, rtol=1e-9)
    hover(ui, v, centre + np.array([0.0, 2.0 * r0 * ppu]))  # twice as far: twice the size
    assert s.radius == pytest.approx(2.0 * r0)
    assert w.dock.radius.value() == pytest.approx(2.0 * r0, rel=1e-3)
    assert f"{s.radius:.4g}" in w.statusBar().currentMessage()
    ui.grab(v)  # paints once the renderer exists
    drawn = record_calls(v.renderer, "set_overlay_circle")
    v.update()
    ui.grab(v)  # the circle, round the sizing's centre, at the new size
    (c, r, _), _ = drawn[-1]
    np.testing.assert_allclose(c, centre * v.devicePixelRatioF())
    assert r == pytest.approx(2.0 * r0 * ppu * v.devicePixelRatioF())
    ui.send_mouse(v, "press", centre + np.array([0.0, 2.0 * r0 * ppu]), LEFT, LEFT)
    ui.send_mouse(v, "release", centre + np.array([0.0, 2.0 * r0 * ppu]), LEFT, None)
    assert not v.sizing.active and s.radius == pytest.approx(2.0 * r0)
    assert not s.pipeline.strokes  # the click was no stroke
    # Esc cancels; so does a right click
    r1 = s.radius
    w.viewport.setFocus()
    for cancel in ("esc", "right"):
        action.trigger()
        c = np.array([v.sizing.centre.x(), v.sizing.centre.y()])
        hover(ui, v, c + np.array([0.5 * r1 * ppu, 0.0]))
        assert s.radius == pytest.approx(0.5 * r1)
        if cancel == "esc":
            ui_key(v, Qt.Key.Key_Escape)
        else:
            ui.send_mouse(v, "press", c, Qt.MouseButton.RightButton, Qt.MouseButton.RightButton)
        assert not v.sizing.active and s.radius == r1
        assert "back to" in w.statusBar().currentMessage()
    assert not s.pipeline.strokes


def ui_key(widget, key) -> None:
    from PySide6.QtGui import QKeyEvent

    QApplication.sendEvent(widget, QKeyEvent(QEvent.Type.KeyPress, key, Qt.KeyboardModifier.NoModifier))


def test_shift_f_sets_the_strength_on_the_canvas_enter_keeps(ui, make_window):
    from app.ui.brush_sizing import STRENGTH_PX

    w = plain(make_window)
    s, v = w.scene, w.viewport
    w.brush_actions["smooth"].trigger()
    s.set_intensity(0.5)
    hover(ui, v, (400.0, 300.0))
    action = action_named(w, "S&trength on canvas")
    assert [k.toString() for k in action.shortcuts()] == ["Shift+F"]
    action.trigger()
    assert v.sizing.active and "Strength 0.5" in w.statusBar().currentMessage()
    c = np.array([v.sizing.centre.x(), v.sizing.centre.y()])
    np.testing.assert_allclose(c, (400.0 - 0.5 * STRENGTH_PX, 300.0))
    hover(ui, v, c + np.array([0.0, 0.8 * STRENGTH_PX]))
    assert s.intensity == pytest.approx(0.8)
    hover(ui, v, c + np.array([3.0 * STRENGTH_PX, 0.0]))  # beyond the ring: full strength
    assert s.intensity == 1.0
    hover(ui, v, c + np.array([0.3 * STRENGTH_PX, 0.0]))
    ui_key(v, Qt.Key.Key_Return)
    assert not v.sizing.active and s.intensity == pytest.approx(0.3)
    assert s.tool.strength["comb"] != pytest.approx(0.3)  # the current brush's strength only
    # a second sizing while one runs ends the first as cancelled
    action.trigger()
    hover(ui, v, (100.0, 100.0))
    action_named(w, "Si&ze on canvas").trigger()
    assert v.sizing.kind == "radius" and s.intensity == pytest.approx(0.3)
    ui_key(v, Qt.Key.Key_Escape)


def test_the_period_key_frames_all(ui, make_window, qtbot):
    w = plain(make_window)
    action = action_named(w, "&Frame all")
    assert [k.toString() for k in action.shortcuts()] == ["."]


def test_a_project_keeps_each_brushs_pen_toggles(make_window, tmp_path):
    w = plain(make_window)
    w.brush_actions["smooth"].trigger()
    w.dock.pressure_radius.setChecked(True)
    w.dock.pressure_strength.setChecked(False)
    path = tmp_path / "pen.hairproj"
    assert w.project.save_to(path)
    w2 = plain(make_window)
    assert w2.project.open_project(path), w2.errors
    tool = w2.scene.tool
    assert tool.pressure_radius["smooth"] and not tool.pressure_strength["smooth"]
    assert not tool.pressure_radius["comb"] and tool.pressure_strength["comb"]
    w2.brush_actions["smooth"].trigger()
    assert w2.dock.pressure_radius.isChecked() and not w2.dock.pressure_strength.isChecked()
