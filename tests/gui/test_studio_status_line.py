"""The status line and the values of a document: one message at a time in its own label (never
drawn over the counts, the jobs' progress or the engine's), cleared when another groom opens;
the frame rate and key settings are each document's own; the error budget field shows a figure
of the current keys, whatever the interpolation."""

from __future__ import annotations

import itertools
import time

import numpy as np
import pytest
from PySide6.QtWidgets import QWidget

from hairtool import samples

pytestmark = pytest.mark.gui

LONG = "tests/data/motion/pymo_walk.bvh"  # 120 fps
WALK = "tests/data/motion/mocapbank_walk.bvh"



def test_a_long_message_is_shortened_in_its_own_place_and_no_two_widgets_overlap(make_window, qtbot):
    w = make_window(size=(900, 600))
    bar = w.statusBar()
    w.jobs.run("Solving keys (1064 frames)", lambda progress, cancelled: time.sleep(0.5))
    long = "Sintel's guides; her render hair follows once the engine is ready " * 3
    bar.showMessage(long)
    w.frame_label.setText("update 633.0 ms (pipeline 633.0, upload 1.2, draw 8.6)")
    qtbot.wait(50)
    assert w.job_status.isVisible()
    assert bar.currentMessage() == long and bar.message_label.text() == long
    shown = bar.message_label.shown_text()
    assert shown.endswith("…") and len(shown) < len(long) and bar.message_label.toolTip() == long
    widgets = [c for c in bar.findChildren(QWidget) if c.parent() is bar and c.isVisible()]
    for a, b in itertools.combinations(widgets, 2):
        assert not a.geometry().intersects(b.geometry()), (a, b)
    w.jobs.wait()


def test_opening_another_groom_clears_the_status_line(ui, make_window):
    w = make_window(groom=samples.portrait(strands=12, vertices=6))
    v = w.viewport
    start = v.project(w.scene.result.tips[3:4])[0]
    ui.drag(v, start, start + np.array([-60.0, -40.0]), steps=4)
    w.scene.last_update_ms = 633.0
    w._update_frame_time()
    assert w.frame_label.text().startswith("update ") and "pipeline 633.0" in w.frame_label.detail
    w.statusBar().showMessage("The brush touched no strand")
    assert w.open_path("tests/data/grooms/ponytail_tail.tfx")
    # the last groom's words are gone; a .tfx says no up axis, so the one its hair gives is said
    assert w.statusBar().currentMessage().startswith("Y up: .tfx files do not say")
    assert w.frame_label.text() == ""
    w._update_frame_time()
    assert "pipeline 633" not in w.frame_label.detail  # the last groom's stroke time is gone


def test_new_from_sample_brings_its_own_frame_rate_and_error_budget(make_window):
    w = make_window()
    assert w.open_path(LONG)
    m = w.animation
    m.set_settings(interp="hermite", mode="budget", budget=123.0)
    assert m.fps == 120.0 and w.timeline.fps_spin.value() == 120.0
    w.new_from_sample("comb")
    assert m.animation is None and m.fps == 24.0 and w.timeline.fps_spin.value() == 24.0
    assert m.settings.mode == "count" and m.settings.budget == 1.0  # the capture's numbers go
    assert m.settings.interp == "hermite"  # the method chosen stays
    assert w.animation_ui.recorder is None


def test_the_budget_field_shows_the_current_keys_error_across_interpolations(make_window):
    w = make_window()
    assert w.open_path(WALK)
    m, c = w.animation, w.timeline.controls
    for interp in ("linear", "hermite", "linear"):
        m.set_settings(interp=interp)
        assert m.settings.mode == "count"
        e = m.key_errors()[0]
        assert c.budget.value() == pytest.approx(e, rel=1e-6)  # a figure of these keys, not a clamp
    keys = m.dp_keys.copy()
    c._set_mode("budget")  # switching to the budget keeps the keys
    assert m.settings.mode == "budget" and m.settings.budget == m.key_errors()[0]
    np.testing.assert_array_equal(m.dp_keys, keys)
    budget = m.settings.budget
    m.set_settings(interp="hermite")  # in budget mode the budget itself is kept
    assert m.settings.budget == budget and c.budget.value() == pytest.approx(budget, rel=1e-6)
    assert m.key_errors()[0] <= budget
