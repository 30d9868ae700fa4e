"""The falloff curve editor: how strongly a brush acts from its centre (left) to its rim (right).

A small painted widget over t = distance / radius in [0, 1] and weight in [0, 1]: drag a point,
double-click to add one, right-click to remove one. The end points stay at t = 0 and t = 1, and
the points keep their order in t, so the curve is always what the engine's ``falloff_lut``
accepts. A preset shows as its table; the first edit turns it into points.
"""

from __future__ import annotations

import numpy as np
from PySide6.QtCore import QPointF, QRectF, QSize, Qt, Signal
from PySide6.QtGui import QColor, QMouseEvent, QPainter, QPen
from PySide6.QtWidgets import QSizePolicy, QWidget

from app.ui.timeline_plots import polygon
from hairtool.frozen.brushes import falloff_lut

PICK_PX = 8.0  # a press this close to a point grabs it
MIN_GAP = 1e-3  # smallest step in t between neighbouring points
PRESET_POINTS = 5  # points a preset becomes when the artist starts editing it


def preset_points(name: str, n: int = PRESET_POINTS) -> list[list[float]]:
    """A preset as ``n`` editable points (its table sampled evenly in t)."""
    lut = falloff_lut(name)
    t = np.linspace(0.0, 1.0, n)
    w = np.interp(t, np.linspace(0.0, 1.0, len(lut)), lut)
    return [[float(a), float(b)] for a, b in zip(t, w, strict=True)]


class FalloffEditor(QWidget):
    """Emits ``curve_edited(points)`` (a list of [t, w]) on every user edit."""

    curve_edited = Signal(object)

    def __init__(self, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.setObjectName("FalloffEditor")
        self.setMinimumSize(120, 64)
        self.setSizePolicy(QSizePolicy.Policy.Expanding, QSizePolicy.Policy.Fixed)
        self.setToolTip(
            "Falloff: the brush's strength from its centre (left) to its rim (right). Drag a point; "
            "double-click to add one, right-click to remove one. (w(t), t = distance / radius)"
        )
        self._falloff: str | list[list[float]] = "smooth"
        self._grab: int | None = None

    def sizeHint(self) -> QSize:
        return QSize(200, 72)

    # -- state ---------------------------------------------------------------------------------
    def set_falloff(self, falloff) -> None:
        """Show a preset name or curve points (no signal)."""
        self._falloff = falloff if isinstance(falloff, str) else [[float(t), float(w)] for t, w in falloff]
        self.update()

    def points(self) -> list[list[float]]:
        """The curve as editable points (a preset sampled, see :func:`preset_points`)."""
        if isinstance(self._falloff, str):
            return preset_points(self._falloff)
        return [list(p) for p in self._falloff]

    # -- geometry ------------------------------------------------------------------------------
    def _plot(self) -> QRectF:
        return QRectF(self.rect()).adjusted(6.0, 6.0, -6.0, -6.0)

    def _to_px(self, t: float, w: float) -> QPointF:
        r = self._plot()
        return QPointF(r.left() + t * r.width(), r.bottom() - w * r.height())

    def _from_px(self, pos: QPointF) -> tuple[float, float]:
        r = self._plot()
        t = (pos.x() - r.left()) / max(r.width(), 1.0)
        w = (r.bottom() - pos.y()) / max(r.height(), 1.0)
        return float(np.clip(t, 0.0, 1.0)), float(np.clip(w, 0.0, 1.0))

    def point_at(self, pos: QPointF) -> int | None:
        """Index of the curve point within :data:`PICK_PX` of ``pos`` (None: none)."""
        best, best_d = None, PICK_PX
        for i, (t, w) in enumerate(self.points()):
            p = self._to_px(t, w)
            d = float(np.hypot(p.x() - pos.x(), p.y() - pos.y()))
            if d <= best_d:
                best, best_d = i, d
        return best

    def point_pos(self, i: int) -> QPointF:
        """Widget position of point ``i`` (tests press there)."""
        t, w = self.points()[i]
        return self._to_px(t, w)

    def _edited(self, points: list[list[float]]) -> None:
        self._falloff = points
        self.update()
        self.curve_edited.emit([list(p) for p in points])

    # -- input ---------------------------------------------------------------------------------
    def mousePressEvent(self, event: QMouseEvent) -> None:
        i = self.point_at(event.position())
        if event.button() == Qt.MouseButton.RightButton:
            pts = self.points()
            if i is not None and 0 < i < len(pts) - 1:
                del pts[i]
                self._edited(pts)
        elif event.button() == Qt.MouseButton.LeftButton:
            self._grab = i
        event.accept()

    def mouseMoveEvent(self, event: QMouseEvent) -> None:
        if self._grab is None:
            return
        pts = self.points()
        i = self._grab
        t, w = self._from_px(event.position())
        if i == 0:
            t = 0.0
        elif i == len(pts) - 1:
            t = 1.0
        else:
            t = float(np.clip(t, pts[i - 1][0] + MIN_GAP, pts[i + 1][0] - MIN_GAP))
        pts[i] = [t, w]
        self._edited(pts)
        event.accept()

    def mouseReleaseEvent(self, event: QMouseEvent) -> None:
        self._grab = None
        event.accept()

    def mouseDoubleClickEvent(self, event: QMouseEvent) -> None:
        if event.button() != Qt.MouseButton.LeftButton or self.point_at(event.position()) is not None:
            return
        t, w = self._from_px(event.position())
        pts = self.points()
        k = next((j for j, p in enumerate(pts) if p[0] > t), len(pts))
        if 0 < k < len(pts) and pts[k - 1][0] + MIN_GAP < t < pts[k][0] - MIN_GAP:
            pts.insert(k, [t, w])
            self._edited(pts)
        event.accept()

    # -- drawing -------------------------------------------------------------------------------
    def paintEvent(self, event) -> None:
        p = QPainter(self)
        p.setRenderHint(QPainter.RenderHint.Antialiasing)
        r = self._plot()
        p.fillRect(self.rect(), self.palette().base())
        p.setPen(QPen(QColor(128, 128, 128, 90), 1.0))
        for f in (0.25, 0.5, 0.75):
            p.drawLine(self._to_px(f, 0.0), self._to_px(f, 1.0))
            p.drawLine(self._to_px(0.0, f), self._to_px(1.0, f))
        p.drawRect(r)
        lut = falloff_lut(self._falloff)
        t = np.linspace(0.0, 1.0, len(lut))
        xs, ys = r.left() + t * r.width(), r.bottom() - np.asarray(lut, dtype=np.float64) * r.height()
        enabled = self.isEnabled()
        p.setPen(QPen(QColor(255, 140, 26) if enabled else QColor(120, 120, 120), 2.0))
        p.setBrush(Qt.BrushStyle.NoBrush)
        p.drawPolyline(polygon(xs, ys))  # one call: QPainterPath.lineTo leaks in PySide6 6.12
        if enabled:  # a preset's handles are where its points will be once edited
            p.setBrush(QColor(255, 255, 255))
            p.setPen(QPen(QColor(40, 40, 40), 1.0))
            for a, b in self.points():
                p.drawEllipse(self._to_px(a, b), 3.5, 3.5)
