"""Controls that stay put: a wheel passing over a dock's slider, spin box or combo box scrolls
the dock; only a control with the focus (clicked, or Tab) takes the wheel."""

from __future__ import annotations

import pytest
from PySide6.QtCore import QPoint, QPointF, Qt
from PySide6.QtGui import QWheelEvent
from PySide6.QtTest import QTest
from PySide6.QtWidgets import QApplication, QDockWidget, QScrollArea

from app.ui.widgets import WHEEL_CONTROLS

pytestmark = pytest.mark.gui


def wheel(widget, steps: int = -1) -> None:
    """One wheel notch (down for negative ``steps``) over the widget's centre."""
    local = QPointF(widget.rect().center())
    event = QWheelEvent(local, QPointF(widget.mapToGlobal(local)), QPoint(0, 0), QPoint(0, 120 * steps),
                        Qt.MouseButton.NoButton, Qt.KeyboardModifier.NoModifier, Qt.ScrollPhase.NoScrollPhase,
                        False)  # fmt: skip
    QApplication.sendEvent(widget, event)


def test_a_wheel_over_wave_length_scrolls_the_anime_dock_until_it_is_clicked(make_window, qtbot):
    w = make_window(size=(900, 560))
    dock = w.sources.dock
    dock.raise_()
    qtbot.waitUntil(lambda: dock.k.isVisible())
    scroll = dock.findChild(QScrollArea).verticalScrollBar()
    assert scroll.maximum() > 0  # the dock is taller than the window: it scrolls
    length = dock.k.value()
    for control in (dock.k.spin, dock.k.slider, dock.hold):
        before = scroll.value()
        wheel(control)
        assert scroll.value() > before, control  # the dock scrolled ...
        assert dock.k.value() == length and dock.hold.value() == 2  # ... and nothing changed
        scroll.setValue(0)
    qtbot.waitUntil(lambda: dock.k.spin.isVisible())
    w.activateWindow()
    qtbot.waitUntil(w.isActiveWindow)
    QTest.mouseClick(dock.k.spin, Qt.MouseButton.LeftButton, pos=dock.k.spin.rect().center())
    assert dock.k.spin.hasFocus()
    before = scroll.value()
    wheel(dock.k.spin, 1)
    assert dock.k.value() != length and scroll.value() == before  # focused: the wheel is its own
    controls = [c for d in w.findChildren(QDockWidget) for t in WHEEL_CONTROLS for c in d.findChildren(t)]
    assert len(controls) > 40  # the tool dock, the anime dock and the timeline's key controls
    assert all(c.focusPolicy() == Qt.FocusPolicy.StrongFocus for c in controls)
