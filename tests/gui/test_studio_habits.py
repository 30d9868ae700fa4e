"""Blender's habits: the numpad views (Ctrl for the opposite side) in either up axis, Frame
selected, N / T / Ctrl+Space for the panels, F3's search over every menu action, and the Help
menu's shortcut sheet made from the menus."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from PySide6.QtCore import QPointF
from PySide6.QtWidgets import QDockWidget

from app.ui.help_menu import shortcut_rows, shortcut_sheet
from app.ui.search_actions import menu_actions, open_search, plain
from app.ui.view_keys import VIEW_KEYS
from hairtool import samples

pytestmark = pytest.mark.gui

OPPOSITE = {"front": "back", "right": "left", "top": "bottom"}
KEY_OF = {name: key for _, name, key in VIEW_KEYS}


def expected_forward(view: str, up: str) -> np.ndarray:
    """Where each view looks, in the DCCs' terms: front along the groom's forward axis (−z
    Y-up, +y Z-up), right at the groom's right side (along −x), top down the up axis."""
    up_v = np.array([0.0, 1.0, 0.0]) if up == "Y" else np.array([0.0, 0.0, 1.0])
    front = np.array([0.0, 0.0, -1.0]) if up == "Y" else np.array([0.0, 1.0, 0.0])
    base = {"front": front, "right": np.array([-1.0, 0.0, 0.0]), "top": -up_v}
    if view in base:
        return base[view]
    return -base[next(k for k, v in OPPOSITE.items() if v == view)]


@pytest.fixture
def window(make_window):
    return make_window(groom=samples.scalp(strands=120, vertices=8))


@settings(max_examples=8, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(view=st.sampled_from([name for _, name, _ in VIEW_KEYS]), up=st.sampled_from(["Y", "Z"]))
def test_each_numpad_view_looks_the_way_blender_does_in_either_up_axis(window, view, up):
    w = window
    w.set_up_axis(up)
    action = w.habit_actions[view]
    assert [k.toString() for k in action.shortcuts()] == [KEY_OF[view]]
    action.trigger()
    forward = w.viewport.camera.forward()
    assert float(forward @ expected_forward(view, up)) > np.cos(np.radians(1.5))


def test_frame_selected_fits_the_selection_and_frames_all_when_all_are_selected(window):
    w, v, s = window, window.viewport, window.scene
    w.habit_actions["selected"].trigger()  # everything selected: the same as frame all
    framed = v.camera.state()
    v.frame_all()
    assert v.camera.state() == framed
    assert [k.toString() for k in w.habit_actions["selected"].shortcuts()] == ["Num+."]
    # a box around a corner of the groom's picture selects a few strands
    pix = v.project(s.result.points)
    lo = pix.min(axis=0)
    size = pix.max(axis=0) - lo
    s.selection_step(v.box_sample(QPointF(*(lo - 2)), QPointF(*(lo + 0.3 * size)), "set"))
    chosen = s.selected & ~s.hidden
    assert 0 < chosen.sum() < s.result.strand_count
    w.habit_actions["selected"].trigger()
    pts = s.result.points[chosen[s.result.topology.strand_index]]
    inside = v.project(pts)
    span = inside.max(axis=0) - inside.min(axis=0)
    assert np.all(inside >= -1) and np.all(inside <= [v.width() + 1, v.height() + 1])
    assert span.max() > 0.5 * min(v.width(), v.height())  # the selection fills the view


def test_n_and_t_toggle_their_docks_and_ctrl_space_gives_the_view_everything_then_back(window):
    w = window
    sidebar, timeline, maximise = (w.habit_actions[k] for k in ("sidebar", "timeline", "maximise"))
    assert [sidebar.shortcuts()[0].toString(), timeline.shortcuts()[0].toString()] == ["N", "T"]
    shown = w.dock.isVisible()
    sidebar.trigger()
    assert w.dock.isVisible() != shown
    sidebar.trigger()
    assert w.dock.isVisible() == shown
    was = w.timeline.isVisible()
    timeline.trigger()
    assert w.timeline.isVisible() != was
    before = {d.objectName() or id(d): d.isVisible() for d in w.findChildren(QDockWidget)}
    assert any(before.values())
    maximise.trigger()
    assert not any(d.isVisible() for d in w.findChildren(QDockWidget))
    maximise.trigger()
    assert {d.objectName() or id(d): d.isVisible() for d in w.findChildren(QDockWidget)} == before


def test_f3_finds_every_menu_action_by_any_words_of_its_path_and_runs_it(window):
    w = window
    found = menu_actions(w.menuBar())
    paths = [p for p, _ in found]
    assert len(paths) >= 40 and len(set(paths)) > 0.9 * len(paths)
    assert "View ▸ Numpad views ▸ Right" in paths and "Help ▸ Search actions…" in paths
    search = open_search(w)
    search.query.setText("RIGHT numpad")
    assert [plain(search.list.item(i).text()).split("    ")[0] for i in range(search.list.count())] == [
        "View ▸ Numpad views ▸ Right"
    ]
    assert search.run_current()
    assert abs(w.viewport.camera.yaw - np.pi / 2) < 1e-9
    search = open_search(w)
    search.query.setText("no action is called this")
    assert search.list.count() == 0 and not search.run_current()
    search.close()


def test_the_shortcut_sheet_lists_every_shortcut_of_the_menus(window):
    w = window
    rows = shortcut_rows(w)
    sheet = shortcut_sheet(w)
    with_keys = [(p, a) for p, a in menu_actions(w.menuBar()) if a.shortcuts()]
    assert len(rows) == len(with_keys)
    for path, keys in rows:
        assert path.split(" ▸ ", 1)[1].replace("&", "&amp;") in sheet
        assert keys in sheet
    assert ("Help ▸ Search actions…", "F3") in rows
    assert ("View ▸ Maximise view", "Ctrl+Space") in rows


@pytest.mark.parametrize("keymap", ["blender", "maya"])
def test_no_two_actions_share_a_shortcut_in_either_keymap(window, keymap):
    from PySide6.QtGui import QAction

    from app.ui.preferences import Preferences, apply

    apply(window, Preferences(keymap=keymap))
    seen: dict[str, str] = {}
    for a in window.findChildren(QAction):
        for k in a.shortcuts():
            text = k.toString()
            assert text not in seen or seen[text] == a.text(), f"{text}: {seen.get(text)} and {a.text()}"
            seen[text] = a.text()
