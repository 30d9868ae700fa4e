"""The joints of a motion capture drawn as handles over the viewport, at key frames, and the
faint ghosts of the neighbouring frames while a key pose is dragged.

Painted with QPainter into each of the viewport's frames (:attr:`Viewport.painted_over`: the
viewport is a native GL window, which would cover a widget over it); mouse events are the
viewport's, which asks :class:`app.ui.capture_edit.JointDrag` whether a press is on a handle.
It projects the points with the viewport's camera, so it follows every orbit, pan and zoom.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
from PySide6.QtCore import QObject, QPointF
from PySide6.QtGui import QColor, QPainter, QPen

if TYPE_CHECKING:
    from app.ui.viewport import Viewport

HANDLE_PX = 4.5
HANDLE = QColor(255, 200, 60)
SELECTED = QColor(255, 90, 60)
GHOST = QColor(150, 220, 255, 70)


class JointHandles(QObject):
    """Handles for ``capture``'s joints over ``viewport``."""

    def __init__(self, capture, viewport: Viewport) -> None:  # capture: app.ui.capture_edit.CaptureEditor
        super().__init__(viewport)
        self.capture, self.viewport = capture, viewport
        viewport.painted_over.append(self)
        model = capture.model
        for signal in (model.frame_changed, model.display_changed, model.keys_changed, capture.changed):
            signal.connect(self.update)

    def update(self) -> None:
        """Paint the handles again (the viewport's overlays: the scene is not drawn again)."""
        self.viewport.update_overlays()

    def shown(self) -> bool:
        """Handles are drawn on a capture at a key frame."""
        return self.capture.attached and self.capture.at_key()

    def paint(self, painter: QPainter) -> None:
        """The handles (and the ghosts of a drag) in the viewport's pixels."""
        c = self.capture
        m = c.original
        parents = np.concatenate([m.parents, m.end_parents])
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
