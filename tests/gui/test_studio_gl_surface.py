"""The viewport's native GL window (app.ui.gl_surface): the window's widgets compose as a plain
raster, never through GL, and a picture of the window still shows the hair in the viewport."""

from __future__ import annotations

import numpy as np
import pytest
from PySide6.QtCore import QEvent, QPointF, Qt
from PySide6.QtGui import QImage, QMouseEvent, QSurface
from PySide6.QtWidgets import QApplication, QWidget

from app.ui.gl_surface import grab_with_view
from hairtool import samples

pytestmark = pytest.mark.gui


def _rgb(image: QImage) -> np.ndarray:
    image = image.convertToFormat(QImage.Format.Format_RGB888)
    w, h = image.width(), image.height()
    data = np.frombuffer(image.constBits(), dtype=np.uint8, count=image.bytesPerLine() * h)
    return data.reshape(h, image.bytesPerLine())[:, : w * 3].reshape(h, w, 3).copy()


def test_the_window_composes_its_widgets_without_gl(make_window):
    # A GL widget anywhere in it would make Qt compose the whole window through GL on every
    # update of any widget (a status label: 40-70 ms under a software GL).
    w = make_window(groom=samples.portrait(strands=30, vertices=20))
    assert w.windowHandle().surfaceType() == QSurface.SurfaceType.RasterSurface
    assert w.viewport.surface.surfaceType() == QSurface.SurfaceType.OpenGLSurface
    assert w.viewport.renderer is not None


def test_a_picture_of_the_window_shows_the_viewport_as_drawn(ui, make_window):
    w = make_window(groom=samples.portrait(strands=30, vertices=20))
    v = w.viewport
    drawn = ui.grab(v)
    assert (np.abs(drawn.astype(int) - drawn[0, 0].astype(int)).max(axis=2) > 40).mean() > 0.001  # hair
    picture = _rgb(grab_with_view(w, v))
    at = v.mapTo(w, v.rect().topLeft())
    h, wd, _ = drawn.shape
    assert np.array_equal(picture[at.y() : at.y() + h, at.x() : at.x() + wd], drawn)


def test_input_that_reaches_the_gl_window_is_the_viewports(make_window):
    # (X makes the surface transparent to input; a platform that cannot passes it on)
    w = make_window(groom=samples.portrait(strands=30, vertices=20))
    v = w.viewport
    other = next(
        x
        for x in w.findChildren(QWidget)
        if x.isVisible() and x is not v and x.focusPolicy() == Qt.FocusPolicy.StrongFocus
    )
    other.setFocus()
    QApplication.processEvents()
    assert w.focusWidget() is not v and v.hover_pos() != QPointF(v.width() * 0.4, v.height() * 0.3)
    pos = QPointF(v.width() * 0.4, v.height() * 0.3)
    for kind, button in (
        (QEvent.Type.MouseMove, Qt.MouseButton.NoButton),
        (QEvent.Type.MouseButtonPress, Qt.MouseButton.RightButton),
    ):
        event = QMouseEvent(
            kind, pos, v.surface.mapToGlobal(pos), button, button, Qt.KeyboardModifier.NoModifier
        )
        QApplication.sendEvent(v.surface, event)
    assert v.hover_pos() == pos and w.focusWidget() is v  # (the window's focus, active or not)
