"""The joints of a motion capture drawn as handles over the viewport, at key frames, and the
faint ghosts of the neighbouring frames while a key pose is dragged.

A transparent child widget painted with QPainter on top of the GL view (mouse events pass
through to the viewport, which asks :class:`app.ui.capture_edit.JointDrag` whether a press is
on a handle); it projects the points with the viewport's camera, so it follows every orbit,
pan and zoom.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
from PySide6.QtCore import QEvent, QObject, QPointF, Qt
from PySide6.QtGui import QColor, QPainter, QPen
from PySide6.QtWidgets import QWidget

if TYPE_CHECKING:
    from app.ui.viewport import Viewport

HANDLE_PX = 4.5
HANDLE = QColor(255, 200, 60)
SELECTED = QColor(255, 90, 60)
GHOST = QColor(150, 220, 255, 70)


class JointHandles(QWidget):
    """Handles for ``capture``'s joints over ``viewport``."""

    def __init__(self, capture, viewport: Viewport) -> None:  # capture: app.ui.capture_edit.CaptureEditor
        super().__init__(viewport)
        self.capture, self.viewport = capture, viewport
        self.setAttribute(Qt.WidgetAttribute.WA_TransparentForMouseEvents)
        self.setAttribute(Qt.WidgetAttribute.WA_NoSystemBackground)
        self.setAttribute(Qt.WidgetAttribute.WA_TranslucentBackground)
        self.setGeometry(viewport.rect())
        viewport.installEventFilter(self)
        viewport.frame_drawn.connect(self.update)
        model = capture.model
        for signal in (model.frame_changed, model.display_changed, model.keys_changed, capture.changed):
            signal.connect(self.update)
        self.show()

    def eventFilter(self, watched: QObject, event: QEvent) -> bool:
        if watched is self.viewport and event.type() == QEvent.Type.Resize:
            self.setGeometry(self.viewport.rect())
        return False

    def shown(self) -> bool:
        """Handles are drawn on a capture at a key frame."""
        return self.capture.attached and self.capture.at_key()

    def paintEvent(self, event) -> None:
        c = self.capture
        if not self.shown():
            return
        m = c.original
        parents = np.concatenate([m.parents, m.end_parents])
        painter = QPainter(self)
        painter.setRenderHint(QPainter.RenderHint.Antialiasing)
        if c.ghosts:
            painter.setPen(QPen(GHOST, 1.5))
            for pose in c.ghosts:
                xy = self.viewport.project(pose)
                for b in np.flatnonzero(parents >= 0):
                    a = parents[b]
                    painter.drawLine(QPointF(*xy[a]), QPointF(*xy[b]))
        xy = self.viewport.project(c.pose_positions()[: m.n_joints])
        depth = m.depths()
        for j in range(m.n_joints):
            if depth[j] == 0:
                continue
            on = m.joint_names[j] == c.joint
            painter.setPen(QPen(QColor(20, 20, 20), 1.0))
            painter.setBrush(SELECTED if on else HANDLE)
            r = HANDLE_PX * (1.4 if on else 1.0)
            painter.drawEllipse(QPointF(*xy[j]), r, r)
        painter.end()
