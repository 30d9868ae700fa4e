"""Colours for distances (displacement from rest, error against the keys) and their legend.

The ramp starts at a light slate grey, not black, so strands that did not move stay visible on
the viewport's dark background; it runs through yellow and orange to red at the top of the scale.
The legend sits in the status bar and says what the colours mean, in the groom's units.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray
from PySide6.QtCore import QRectF, QSize, Qt
from PySide6.QtGui import QColor, QLinearGradient, QPainter
from PySide6.QtWidgets import QHBoxLayout, QLabel, QWidget

#: The distance ramp's stops, evenly spaced over [0, 1] (RGB in [0, 1]).
MAGNITUDE_STOPS = np.array(
    [[0.55, 0.59, 0.66], [1.0, 0.84, 0.0], [1.0, 0.45, 0.0], [0.85, 0.05, 0.05]], dtype=np.float64
)


def magnitude_colors(values: ArrayLike) -> NDArray[np.float32]:
    """``(n,)`` values in [0, 1] (clipped; NaN counts as 0) → ``(n, 3)`` float32 ramp colours."""
    v = np.nan_to_num(np.clip(np.asarray(values, dtype=np.float64).reshape(-1), 0.0, 1.0))
    x = np.linspace(0.0, 1.0, len(MAGNITUDE_STOPS))
    return np.column_stack([np.interp(v, x, MAGNITUDE_STOPS[:, c]) for c in range(3)]).astype(np.float32)


def readable_length(value: float, meters_per_unit: float) -> tuple[float, str]:
    """``value`` groom units as an artist reads a length: ``(number, "mm" | "cm" | "m")``, the
    unit chosen for the size (a 5 mm error, a 20 cm strand), whatever unit the scene is in."""
    metres = float(value) * float(meters_per_unit)
    if abs(metres) < 0.01:
        return metres * 1e3, "mm"
    if abs(metres) < 1.0:
        return metres * 1e2, "cm"
    return metres, "m"


class RampBar(QWidget):
    """The distance ramp as a horizontal gradient."""

    def sizeHint(self) -> QSize:
        return QSize(90, 12)

    def paintEvent(self, event) -> None:
        p = QPainter(self)
        rect = QRectF(self.rect()).adjusted(0.5, 2.5, -0.5, -2.5)
        gradient = QLinearGradient(rect.topLeft(), rect.topRight())
        for i, rgb in enumerate(MAGNITUDE_STOPS):
            gradient.setColorAt(i / (len(MAGNITUDE_STOPS) - 1), QColor.fromRgbF(*rgb))
        p.fillRect(rect, gradient)
        p.setPen(QColor(20, 20, 20))
        p.drawRect(rect)


class RampLegend(QWidget):
    """``title  0 [ramp] top unit`` for the status bar; hidden while no distance colouring shows."""

    def __init__(self, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.setObjectName("RampLegend")
        row = QHBoxLayout(self)
        row.setContentsMargins(4, 0, 4, 0)
        row.setSpacing(4)
        self.title = QLabel()
        self.low = QLabel("0")
        self.bar = RampBar()
        self.high = QLabel()
        for w in (self.title, self.low, self.bar, self.high):
            row.addWidget(w, 0, Qt.AlignmentFlag.AlignVCenter)
        self.hide()

    def show_scale(self, title: str, top: float, unit: str, tip: str = "") -> None:
        """Show the ramp from 0 to ``top`` (in ``unit``) under ``title``."""
        self.title.setText(title)
        self.high.setText(f"{top:.3g} {unit}")
        self.setToolTip(tip)
        self.show()

    def text(self) -> str:
        """What the legend says, as one line (for tests and screen readers)."""
        return f"{self.title.text()} {self.low.text()} – {self.high.text()}"
