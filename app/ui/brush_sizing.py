"""Sizing the brush on the canvas, as Blender's F / Shift+F: the mouse's distance from a centre
sets the brush size (F) or its strength (Shift+F) while the circle follows; a left click or
Enter keeps the value, Esc or a right click gives the old one back. And a pen's pressure, read
from a tablet event (a mouse presses fully).

The viewport owns one :class:`CanvasSizing` and hands it its mouse and key events while it is
active; the value goes to the scene as the dock's sliders would set it.
"""

from __future__ import annotations

import math

from PySide6.QtCore import QObject, QPointF, Qt, Signal
from PySide6.QtGui import QTabletEvent

#: Logical pixels from the centre that mean full strength (Blender's radial control is 200 px).
STRENGTH_PX = 200.0
MIN_RADIUS_PX = 2.0  # the smallest circle sizing gives (a brush of no size brushes nothing)
KINDS = {"radius": "Brush size", "strength": "Strength"}


def pen_pressure(event: object) -> float:
    """A tablet event's pressure in [0, 1]; 1.0 for any other event (a mouse presses fully)."""
    if isinstance(event, QTabletEvent):
        p = float(event.pressure())
        return min(max(p, 0.0), 1.0) if math.isfinite(p) else 1.0
    return 1.0


class CanvasSizing(QObject):
    """See the module docstring. ``message`` says the value (and how to finish) for the status
    line; ``finished(kept)`` when it ends."""

    message = Signal(str)
    finished = Signal(bool)

    def __init__(self, viewport) -> None:
        super().__init__(viewport)
        self.viewport = viewport
        self.kind: str | None = None  # "radius" | "strength" while sizing
        self.centre = QPointF()
        self._old = 0.0

    @property
    def active(self) -> bool:
        return self.kind is not None

    def _pixels_per_unit(self) -> float:
        v = self.viewport
        return float(v.camera.pixels_per_unit_at(v.scene.centre, max(v.height(), 1)))

    def _value(self) -> float:
        s = self.viewport.scene
        return s.radius if self.kind == "radius" else s.intensity

    def start(self, kind: str) -> bool:
        """Begin sizing ``kind`` ("radius" or "strength") from the mouse where it is (the view's
        middle when it is outside): the centre is put so that the current value is the mouse's
        distance from it. False while a drag is under way."""
        if kind not in KINDS:
            raise ValueError(f"unknown sizing {kind!r}")
        v = self.viewport
        if v.is_dragging():
            return False
        if self.active:
            self.cancel()
        self.kind = kind
        self._old = self._value()
        at = v.hover_pos()
        if at is None:
            at = QPointF(v.width() / 2.0, v.height() / 2.0)
        self.centre = QPointF(at.x() - self.circle_px(), at.y())
        v.setFocus(Qt.FocusReason.ShortcutFocusReason)
        self._say()
        v.update()
        return True

    def circle_px(self) -> float:
        """The circle's radius in logical pixels: the brush's size, or the strength's share of
        :data:`STRENGTH_PX`."""
        if self.kind == "strength":
            return self.viewport.scene.intensity * STRENGTH_PX
        return self.viewport.scene.radius * self._pixels_per_unit()

    def move(self, pos: QPointF) -> None:
        """The mouse at ``pos``: the value its distance from the centre gives."""
        d = math.hypot(pos.x() - self.centre.x(), pos.y() - self.centre.y())
        s = self.viewport.scene
        if self.kind == "radius":
            lo, hi = s.rest.bounds
            extent = max(float((hi - lo).max()), 1e-3)  # the dock's range: 1/1000 to twice the groom
            radius = max(d, MIN_RADIUS_PX) / max(self._pixels_per_unit(), 1e-12)
            s.set_radius(min(max(radius, extent * 1e-3), extent * 2.0))
        elif self.kind == "strength":
            s.set_intensity(min(d / STRENGTH_PX, 1.0))
        self._say()

    def confirm(self) -> None:
        if self.active:
            self._end(True)

    def cancel(self) -> None:
        """The value back as it was before sizing began."""
        if not self.active:
            return
        s = self.viewport.scene
        if self.kind == "radius":
            s.set_radius(self._old)
        else:
            s.set_intensity(self._old)
        self._end(False)

    def _end(self, kept: bool) -> None:
        label, value = KINDS[self.kind], self._value()
        self.kind = None
        self.message.emit(f"{label} {value:.4g}" if kept else f"{label} back to {value:.4g}")
        self.viewport.update()
        self.finished.emit(kept)

    def _say(self) -> None:
        self.message.emit(
            f"{KINDS[self.kind]} {self._value():.4g}: move the mouse; click or Enter keeps it, "
            "Esc or right-click cancels"
        )

    # -- the viewport's events while sizing ------------------------------------------------------
    def mouse_press(self, event) -> None:
        if event.button() == Qt.MouseButton.LeftButton:
            self.move(event.position())
            self.confirm()
        elif event.button() == Qt.MouseButton.RightButton:
            self.cancel()

    def key_press(self, event) -> bool:
        """Enter keeps, Esc cancels; True where the key was one of those."""
        if event.key() in (Qt.Key.Key_Return, Qt.Key.Key_Enter):
            self.confirm()
            return True
        if event.key() == Qt.Key.Key_Escape:
            self.cancel()
            return True
        return False
