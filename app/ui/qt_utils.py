"""Small Qt helpers shared by the studio's widgets."""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager

from PySide6.QtCore import QEvent, QObject, QPointF, Qt
from PySide6.QtGui import QMouseEvent
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
