"""A slider paired with a spin box, for parameters an artist drags and sometimes types; the
docks' scroll areas; and the wheel guard that keeps the docks' controls put while they scroll."""

from __future__ import annotations

import math

from PySide6.QtCore import QEvent, QObject, Qt, Signal
from PySide6.QtGui import QWheelEvent
from PySide6.QtWidgets import (
    QAbstractScrollArea,
    QAbstractSlider,
    QAbstractSpinBox,
    QApplication,
    QComboBox,
    QDoubleSpinBox,
    QFrame,
    QHBoxLayout,
    QScrollArea,
    QScrollBar,
    QSlider,
    QWidget,
)

from app.ui.qt_utils import signals_blocked

SLIDER_STEPS = 1000


class SliderSpin(QWidget):
    """A float in [lo, hi]: a slider (linear or logarithmic) and a spin box showing the same value.

    ``edited(value, drag)`` fires on user edits only; ``drag`` is an id shared by the edits of one
    slider drag (None for typed values), so the undo stack can merge a drag into one step.
    """

    edited = Signal(float, object)

    def __init__(
        self, lo: float, hi: float, decimals: int = 3, log: bool = False, parent: QWidget | None = None
    ) -> None:
        super().__init__(parent)
        self.lo, self.hi, self.log = float(lo), float(hi), bool(log)
        self.slider = QSlider(Qt.Orientation.Horizontal)
        self.slider.setRange(0, SLIDER_STEPS)
        self.spin = QDoubleSpinBox()
        self.spin.setDecimals(decimals)
        self.spin.setRange(lo, hi)
        self._set_step()
        self.spin.setKeyboardTracking(False)
        layout = QHBoxLayout(self)
        layout.setContentsMargins(0, 0, 0, 0)
        layout.addWidget(self.slider, 3)
        layout.addWidget(self.spin, 2)
        self._drag_counter = 0
        self._drag: int | None = None
        self.slider.sliderPressed.connect(self._begin_drag)
        self.slider.sliderReleased.connect(self._end_drag)
        self.slider.valueChanged.connect(self._from_slider)
        self.spin.valueChanged.connect(self._from_spin)

    def set_range(self, lo: float, hi: float) -> None:
        value = self.value()
        self.lo, self.hi = float(lo), float(hi)
        with signals_blocked(self.spin, self.slider):
            self.spin.setRange(lo, hi)
            self._set_step()
        self.set_value(min(max(value, self.lo), self.hi))

    def _set_step(self) -> None:
        if self.log:  # arrows step by about a tenth of the value shown
            self.spin.setStepType(QDoubleSpinBox.StepType.AdaptiveDecimalStepType)
        else:
            self.spin.setSingleStep((self.hi - self.lo) / 100.0)

    def _to_pos(self, value: float) -> int:
        if self.log:
            f = math.log(max(value, self.lo) / self.lo) / math.log(self.hi / self.lo)
        else:
            f = (value - self.lo) / (self.hi - self.lo)
        return round(min(max(f, 0.0), 1.0) * SLIDER_STEPS)

    def _from_pos(self, pos: int) -> float:
        f = pos / SLIDER_STEPS
        if self.log:
            return self.lo * (self.hi / self.lo) ** f
        return self.lo + f * (self.hi - self.lo)

    def value(self) -> float:
        return float(self.spin.value())

    def set_value(self, value: float) -> None:
        """Show a value from the model without emitting ``edited``."""
        with signals_blocked(self.spin, self.slider):
            self.spin.setValue(value)
            self.slider.setValue(self._to_pos(value))

    def _begin_drag(self) -> None:
        self._drag_counter += 1
        self._drag = id(self) * 1000 + self._drag_counter

    def _end_drag(self) -> None:
        self._drag = None

    def _from_slider(self, pos: int) -> None:
        value = self._from_pos(pos)
        with signals_blocked(self.spin):
            self.spin.setValue(value)
        self.edited.emit(self.value(), self._drag if self.slider.isSliderDown() else None)

    def _from_spin(self, value: float) -> None:
        with signals_blocked(self.slider):
            self.slider.setValue(self._to_pos(value))
        self.edited.emit(float(value), None)


def scrolling(body: QWidget) -> QScrollArea:
    """``body`` in a frameless vertical scroll area: a dock on a short screen scrolls its controls
    instead of making the window taller than the screen."""
    area = QScrollArea()
    area.setWidget(body)
    area.setWidgetResizable(True)
    area.setFrameShape(QFrame.Shape.NoFrame)
    area.setHorizontalScrollBarPolicy(Qt.ScrollBarPolicy.ScrollBarAlwaysOff)
    area.setMinimumWidth(body.minimumSizeHint().width() + area.verticalScrollBar().sizeHint().width())
    return area


#: Controls a passing wheel would change: they take the wheel only once they have the focus.
WHEEL_CONTROLS = (QAbstractSlider, QAbstractSpinBox, QComboBox)


class WheelGuard(QObject):
    """Event filter: a wheel over an unfocused slider, spin box or combo box is not theirs, so
    the scroll area round them scrolls instead (as in Blender and Maya); a click (or Tab) gives
    the control the focus, and then the wheel changes its value."""

    def eventFilter(self, obj: QObject, event: QEvent) -> bool:
        if event.type() != QEvent.Type.Wheel or not isinstance(obj, QWidget) or obj.hasFocus():
            return False
        area = obj.parentWidget()
        while area is not None and not isinstance(area, QAbstractScrollArea):
            area = area.parentWidget()
        if area is not None:
            scroll_by_wheel(area.verticalScrollBar(), event)
        return True  # never the control's


def scroll_by_wheel(bar: QScrollBar, event: QWheelEvent) -> None:
    """Scroll ``bar`` as a wheel over its area would: pixels from a touchpad, else the
    platform's lines per notch."""
    pixels = event.pixelDelta().y()
    if pixels == 0:
        notches = event.angleDelta().y() / 120.0
        pixels = round(notches * QApplication.wheelScrollLines() * bar.singleStep())
    bar.setValue(bar.value() - pixels)


def keep_controls_put(root: QWidget, guard: WheelGuard) -> None:
    """Guard every wheel control under ``root``: click or Tab focus only (StrongFocus, not the
    wheel focus spin boxes have by default), and the wheel only with the focus."""
    for w in root.findChildren(QWidget):
        if isinstance(w, WHEEL_CONTROLS):
            w.setFocusPolicy(Qt.FocusPolicy.StrongFocus)
            w.installEventFilter(guard)
