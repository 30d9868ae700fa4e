"""The viewport's native GL window (app.ui.gl_surface): the window's widgets compose as a plain
raster, never through GL, and a picture of the window still shows the hair in the viewport."""

from __future__ import annotations

import numpy as np
import pytest
from PySide6.QtGui import QImage, QSurface

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
