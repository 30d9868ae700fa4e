"""Engine parameters in the dock: live updates of the drawn groom, undo steps, no echo loops."""

from __future__ import annotations

import math

import numpy as np
import pytest

pytestmark = pytest.mark.gui


def test_stiffness_slider_changes_the_drawn_groom_and_undoes(ui, make_window):
    w = make_window()
    ui.leave(w.viewport)
    assert w.scene.params.freeze  # the frozen look is on by default, so stiffness shows
    before_params, before_points, before_image = (
        w.scene.params,
        w.scene.result.points.copy(),
        ui.grab(w.viewport),
    )
    slider = w.dock.params["stretch_stiffness"].slider
    slider.setValue(0 if slider.value() > 100 else slider.maximum())
    assert w.scene.params.stretch_stiffness != before_params.stretch_stiffness
    assert not np.array_equal(w.scene.result.points, before_points)
    assert not np.array_equal(ui.grab(w.viewport), before_image)
    assert w.undo_stack.count() == 1
    w.undo_stack.undo()
    assert w.scene.params == before_params
    assert np.array_equal(w.scene.result.points, before_points)
    assert np.array_equal(ui.grab(w.viewport), before_image)
    # The dock shows the restored value without pushing another command.
    assert w.dock.params["stretch_stiffness"].value() == pytest.approx(
        before_params.stretch_stiffness, rel=1e-3
    )
    assert w.undo_stack.count() == 1 and w.undo_stack.index() == 0


def test_one_slider_drag_is_one_undo_step(make_window):
    w = make_window()
    slider = w.dock.params["bend_stiffness"].slider
    start = w.scene.params
    slider.setSliderDown(True)
    slider.sliderPressed.emit()
    for pos in (100, 200, 300, 400):
        slider.setValue(pos)
    slider.setSliderDown(False)
    slider.sliderReleased.emit()
    assert w.undo_stack.count() == 1
    last = w.scene.params.bend_stiffness
    slider.setValue(600)  # a later, separate edit of the same field is its own step
    assert w.undo_stack.count() == 2
    w.undo_stack.undo()
    assert w.scene.params.bend_stiffness == last
    w.undo_stack.undo()
    assert w.scene.params == start


def test_every_engine_parameter_has_a_control(make_window):
    w = make_window()
    from dataclasses import fields

    names = {f.name for f in fields(w.scene.params) if f.init}
    assert names == set(w.dock.params)
    angle = w.dock.params["max_bend_angle"]
    angle.spin.setValue(45.0)
    assert w.scene.params.max_bend_angle == pytest.approx(math.radians(45.0))
    clump = w.dock.params["clump"]
    clump.setChecked(not clump.isChecked())
    gap = w.dock.params["gap_mode"]
    gap.setCurrentIndex(gap.findData("off"))
    assert w.scene.params.gap_mode == "off"
    assert w.undo_stack.count() == 3


def test_brush_and_display_controls_write_the_scene(make_window):
    w = make_window()
    w.dock.intensity.spin.setValue(0.2)
    assert w.scene.intensity == pytest.approx(0.2)
    w.dock.mode.setCurrentIndex(w.dock.mode.findData("preserve-length"))
    assert w.scene.align_mode == "preserve-length"
    w.dock.line_width.spin.setValue(4.0)
    assert w.scene.line_width == 4.0 and w.viewport.renderer is not None
    w.dock.ramp.setCurrentText("viridis")
    assert w.scene.ramp == "viridis"
    assert w.undo_stack.count() == 0  # brush and display settings are not edits of the groom
