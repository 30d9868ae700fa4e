"""Small Qt helpers shared by the studio's widgets."""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager

from PySide6.QtCore import QEvent, QObject, QPointF, Qt
from PySide6.QtGui import QAction, QKeySequence, QMouseEvent
from PySide6.QtWidgets import QApplication, QWidget

_MOUSE_EVENTS = {
    "press": QEvent.Type.MouseButtonPress,
    "move": QEvent.Type.MouseMove,
    "release": QEvent.Type.MouseButtonRelease,
}


@contextmanager
def signals_blocked(*objects: QObject) -> Iterator[None]:
    """Update widgets from the model without their change signals echoing back into it."""
    previous = [o.blockSignals(True) for o in objects]
    try:
        yield
    finally:
        for o, was in zip(objects, previous, strict=True):
            o.blockSignals(was)


def send_mouse(
    widget: QWidget,
    kind: str,
    pos,
    button: Qt.MouseButton | None = None,
    buttons: Qt.MouseButton | None = None,
    modifiers: Qt.KeyboardModifier | None = None,
) -> None:
    """Deliver one mouse event synchronously (``kind`` "press" | "move" | "release", ``pos`` in
    widget pixels): how tests, benchmarks and the screenshot script drive the studio as a user."""
    none = Qt.MouseButton.NoButton
    local = QPointF(float(pos[0]), float(pos[1]))
    event = QMouseEvent(
        _MOUSE_EVENTS[kind],
        local,
        widget.mapToGlobal(local),
        none if button is None else button,
        none if buttons is None else buttons,
        Qt.KeyboardModifier.NoModifier if modifiers is None else modifiers,
    )
    QApplication.sendEvent(widget, event)


def set_available(action: QAction, available: bool, why_not: str, tip: str = "") -> None:
    """Enable ``action`` where it can apply; greyed out, its tooltip says why (``why_not``), as
    an action that cannot apply must not be an error after the click."""
    action.setEnabled(available)
    action.setToolTip(tip or action.text().replace("&", "") if available else why_not)


def add_action(owner: QObject, menu, text: str, slot, shortcut=None, *, checkable: bool = False) -> QAction:
    """A menu entry calling ``slot``, with one shortcut or a list of them (owned by ``owner``)."""
    action = QAction(text, owner)
    if shortcut is not None:
        keys = shortcut if isinstance(shortcut, list) else [shortcut]
        action.setShortcuts([QKeySequence(k) for k in keys])
    action.setCheckable(checkable)
    action.triggered.connect(slot)
    menu.addAction(action)
    return action
